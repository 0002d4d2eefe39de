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
from .mission.discretise import candidate_s
from .tour import Tour


def require_matplotlib() -> None:
    """Raise :class:`InputError` now, before any work, if matplotlib is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise InputError("--plot needs matplotlib: pip install 'dtsp-mission[plot]'") from None


#: Picture formats by file extension (matplotlib's writers).
PLOT_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf", ".jpg": "jpg", ".jpeg": "jpg"}


def plot_format(path) -> str:
    """The picture format of ``path`` from its extension, or :class:`InputError`."""
    suffix = Path(path).suffix.lower()
    if suffix not in PLOT_FORMATS:
        raise InputError(f"{path}: a plot is written as {', '.join(PLOT_FORMATS)}; "
                         f"{suffix or 'no extension'} is none of them")
    return PLOT_FORMATS[suffix]


def draw_plan(product: Mission | Tour, path: str | os.PathLike,
              area_m: np.ndarray | None = None, title: str = "") -> Path:
    """Write a PNG of ``product`` to ``path`` (atomically)."""
    require_matplotlib()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
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
              label=f"flight: {mission.summary['flight_length_m'] / 1e3:,.2f} km from take-off "
                    f"to the return (tour {tour.length_m:,.1f} m)" if mission
              else f"tour {tour.length_m:,.1f} m", zorder=2)
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
        axes.plot(*home, marker="^", color="black", markersize=10, linestyle="none",
                  label="home", zorder=5)
    axes.plot(tour.targets_m[:, 0], tour.targets_m[:, 1], "o", markerfacecolor="none",
              markeredgecolor="#c0392b", markersize=5, label=f"targets ({len(tour.targets_m)})",
              zorder=4)
    axes.set_aspect("equal")
    axes.set_xlabel("east (m)")
    axes.set_ylabel("north (m)")
    axes.set_title(title or f"{tour.planner}: {len(tour.targets_m)} targets, rho {tour.rho_m:g} m")
    axes.grid(True, linewidth=0.3)
    axes.legend(loc="upper right", fontsize=8)
    buffer = io.BytesIO()
    figure.savefig(buffer, format=plot_format(path), bbox_inches="tight")
    plt.close(figure)
    return write_atomic(path, buffer.getvalue())
