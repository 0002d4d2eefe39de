"""A picture of the plan (PNG): targets, the exact path, the waypoints, home and the area.

Drawn in the local frame (metres east and north of the mission centre) so that distances and
turn radii look true.  matplotlib is an optional dependency (``pip install dtsp-mission[plot]``)
and is imported only here.
"""

from __future__ import annotations

import io
import math
import os
from pathlib import Path

import numpy as np

from .errors import InputError
from .files import write_atomic
from .mission import Command, Mission
from .export.base import lengths_text
from .mission.discretise import candidate_s
from .tour import Tour


def require_matplotlib() -> None:
    """Raise :class:`InputError` now, before any work, if matplotlib is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise InputError("drawing a plot needs matplotlib: pip install 'dtsp-mission[plot]'") from None


#: Picture formats by file extension (matplotlib's writers).
PLOT_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf", ".jpg": "jpg", ".jpeg": "jpg"}


def plot_format(path) -> str:
    """The picture format of ``path`` from its extension, or :class:`InputError`."""
    suffix = Path(path).suffix.lower()
    if suffix not in PLOT_FORMATS:
        raise InputError(f"{path}: a plot is written as {', '.join(PLOT_FORMATS)}; "
                         f"{suffix or 'no extension'} is none of them")
    return PLOT_FORMATS[suffix]


#: Targets labelled with their visit number: all of them up to this many, else every k-th.
LABELLED_VISITS = 80


def _nice_length(span_m: float) -> float:
    """A round length (1, 2 or 5 x 10^k metres) near a fifth of ``span_m``, for the scale bar."""
    target = max(span_m / 5.0, 1e-3)
    power = 10.0 ** math.floor(math.log10(target))
    return max(step * power for step in (1.0, 2.0, 5.0) if step * power <= target)


def draw_plan(product: Mission | Tour, path: str | os.PathLike,
              area_m: np.ndarray | None = None, title: str = "") -> Path:
    """Write :func:`render_plan`'s picture to ``path`` (atomically; PNG, SVG, PDF or JPEG by
    the extension)."""
    return write_atomic(path, render_plan(product, plot_format(path), area_m, title))


def render_plan(product: Mission | Tour, image_format: str,
                area_m: np.ndarray | None = None, title: str = "") -> bytes:
    """A picture of ``product`` in ``image_format`` (png, svg, pdf, jpg): the flight path with arrows in the direction of flight, the targets with their
    visit numbers, take-off and the return to home for a mission, a scale bar and north, the
    legend below the map.  SVG text stays text (searchable, editable)."""
    require_matplotlib()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar
    matplotlib.rcParams["svg.fonttype"] = "none"
    mission = product if isinstance(product, Mission) else None
    tour = mission.tour if mission else product
    chain = mission.path.chain if mission else tour.chain
    s, _ = candidate_s(chain, math.radians(2.0), np.zeros(0), 0.0)
    line = chain.pose_at(s)[:, :2]
    figure, axes = plt.subplots(figsize=(10, 10), dpi=120)
    if area_m is not None:
        ring = np.vstack([area_m, area_m[:1]])
        axes.fill(ring[:, 0], ring[:, 1], color="#e8f0e0", zorder=0, label="survey area")
    axes.plot(line[:, 0], line[:, 1], color="#1f5fa8", linewidth=0.8,
              # the two lengths plan reports, named and rounded as it prints them
              label=lengths_text(mission) if mission else f"tour {tour.length_m:,.1f} m", zorder=2)
    # the direction of flight: an arrow every twelfth of the path
    arrows = chain.pose_at(np.linspace(0.0, chain.length_m, 13)[1:-1] if chain.length_m > 0
                           else np.zeros(0))
    span = float(np.ptp(line, axis=0).max()) if len(line) else 1.0
    for x, y, heading in arrows:
        axes.annotate("", xy=(x + 1e-3 * span * math.cos(heading), y + 1e-3 * span * math.sin(heading)),
                      xytext=(x, y), arrowprops={"arrowstyle": "-|>", "color": "#1f5fa8",
                                                  "mutation_scale": 14}, zorder=3)
    if mission:
        frame = mission.frame
        positioned = [item for item in mission.items
                      if item.has_position and item.command == Command.NAV_WAYPOINT
                      and item.role != "target"]
        if positioned:
            points = frame.to_local([i.latitude_deg for i in positioned],
                                    [i.longitude_deg for i in positioned])
            axes.plot(points[:, 0], points[:, 1], ".", color="#f28e2b", markersize=1.5,
                      label=f"path waypoints ({len(positioned)})", zorder=3)
        home = frame.to_local(mission.home.latitude_deg, mission.home.longitude_deg)[0]
        start, end = chain.starts[0, :2], chain.ends()[-1, :2]
        axes.plot([home[0], start[0]], [home[1], start[1]], color="#555555", linewidth=1.0,
                  linestyle=":", label="take-off and climb", zorder=2)
        axes.plot([end[0], home[0]], [end[1], home[1]], color="#555555", linewidth=1.0,
                  linestyle="--", label="return to home", zorder=2)
        axes.plot(*home, marker="^", color="black", markersize=10, linestyle="none",
                  label="home", zorder=5)
        axes.annotate("take-off", xy=tuple(start), xytext=(6, 6), textcoords="offset points",
                      fontsize=8, zorder=6)
    axes.plot(tour.targets_m[:, 0], tour.targets_m[:, 1], "o", markerfacecolor="none",
              markeredgecolor="#c0392b", markersize=5, label=f"targets ({len(tour.targets_m)}), "
              "numbered in visiting order", zorder=4)
    order = tour.visit_order
    every = max(1, math.ceil(len(order) / LABELLED_VISITS))
    for visit, target in enumerate(order, start=1):
        if visit == 1 or visit % every == 0:
            axes.annotate(str(visit), xy=tuple(tour.targets_m[target]), xytext=(3, -9),
                          textcoords="offset points", fontsize=6, color="#c0392b", zorder=6)
    axes.set_aspect("equal")
    axes.set_xlabel("east of the frame's centre (m)")
    axes.set_ylabel("north of the frame's centre (m)")
    axes.set_title(title or f"{tour.planner}: {len(tour.targets_m)} targets, rho {tour.rho_m:g} m")
    axes.grid(True, linewidth=0.3)
    bar = _nice_length(span)
    axes.add_artist(AnchoredSizeBar(axes.transData, bar, f"{bar:g} m" if bar < 1000 else
                                    f"{bar / 1000:g} km", "lower left", pad=0.5, frameon=False,
                                    size_vertical=span / 300))
    axes.annotate("N", xy=(0.97, 0.97), xytext=(0.97, 0.90), xycoords="axes fraction",
                  ha="center", fontsize=10, arrowprops={"arrowstyle": "-|>", "color": "black"})
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=2, fontsize=8,
                frameon=False)
    buffer = io.BytesIO()
    figure.savefig(buffer, format=image_format, bbox_inches="tight")
    plt.close(figure)
    return buffer.getvalue()
