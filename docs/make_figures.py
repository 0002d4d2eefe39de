"""Draw the algorithm figures of docs/algorithms.md from the planning code itself.

* ``fig-bead.png``: one bead B_rho(l) (its exact boundary from ``planning.bead``) with the
  S-curves the RBTA flies through three targets inside it;
* ``fig-tiling.png``: the staggered bead tiling of a small region (``planning.tiling``), every
  target coloured by the bead that holds it;
* ``fig-phases.png``: a faithful RBTA tour, each phase in its own colour (lengths from the tour's
  own report), the leftovers' Alternating tour in black;
* ``fig-lanes.png``: the ``lanes`` planner (the default's winner at large n) on the same targets.

Run: python docs/make_figures.py [--out docs]      (needs matplotlib)
"""

from __future__ import annotations

import argparse
import io
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from dtsp_mission.files import write_atomic  # noqa: E402
from dtsp_mission.planning import bead, bounding_region, get_planner  # noqa: E402
from dtsp_mission.planning.tiling import BeadTiling  # noqa: E402

RHO_M = 100.0


def _save(figure, path: Path) -> None:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
    plt.close(figure)
    write_atomic(path, buffer.getvalue())
    print("wrote", path)


def _draw_chain(axes, chain, start_m: float, end_m: float, **style) -> None:
    s = np.linspace(start_m, end_m, max(2, int((end_m - start_m) / 2.0)))
    xy = chain.pose_at(s)[:, :2]
    axes.plot(xy[:, 0], xy[:, 1], **style)


def bead_figure(path: Path) -> None:
    l_m = 1.2 * RHO_M
    figure, axes = plt.subplots(figsize=(7, 3))
    outline = bead.boundary(l_m, RHO_M)
    _draw_chain(axes, outline, 0.0, outline.length_m, color="tab:blue", lw=2, label="B_rho(l) boundary")
    points = np.array([[-40.0, 12.0], [25.0, -20.0], [70.0, 5.0]])
    radii = bead.radius_through(points, l_m, RHO_M)
    for point, radius in zip(points, radii):
        x = np.linspace(-l_m, l_m, 300)
        sign = 1.0 if point[1] >= 0 else -1.0
        y = sign * bead.curve_height(x, l_m, radius)
        axes.plot(x, y, color="tab:orange", lw=1)
    axes.plot(*points.T, "o", color="crimson", label="targets")
    axes.plot([-l_m, l_m], [0, 0], "k.", ms=8)
    axes.annotate("p-", (-l_m, 0), textcoords="offset points", xytext=(-14, -3))
    axes.annotate("p+", (l_m, 0), textcoords="offset points", xytext=(5, -3))
    axes.set_aspect("equal")
    axes.set_title(f"a bead, l = {l_m / RHO_M:g} rho: S-curves of radius >= rho through each target")
    axes.legend(loc="upper left", fontsize=8)
    _save(figure, path)


def tiling_figure(path: Path, targets: np.ndarray) -> None:
    region = bounding_region(targets)
    tiling = BeadTiling.for_region(region, len(targets), RHO_M)
    local = region.to_local(targets)
    rows, columns = tiling.bead_of(local)
    figure, axes = plt.subplots(figsize=(8, 6))
    outline = bead.boundary(tiling.l_m, RHO_M).pose_at(
        np.linspace(0, bead.boundary(tiling.l_m, RHO_M).length_m, 120))[:, :2]
    for k in range(tiling.row_count):
        for m in range(-1, int(region.width_m / (2 * tiling.l_m)) + 2):
            centre = np.array([(2 * m + k % 2) * tiling.l_m, k * tiling.row_spacing_m])
            axes.plot(*(outline + centre).T, color="0.75", lw=0.6)
    colour = (rows * 7919 + columns * 104729) % 20
    axes.scatter(*local.T, c=colour, cmap="tab20", s=12, zorder=3)
    axes.set_xlim(-tiling.l_m, region.width_m + tiling.l_m)
    axes.set_ylim(-tiling.row_spacing_m, region.height_m + tiling.row_spacing_m)
    axes.set_aspect("equal")
    axes.set_title(f"bead tiling: {len(targets)} targets, Area[bead] = A / 2n, "
                   f"l = {tiling.l_m:.0f} m, rho = {RHO_M:g} m")
    _save(figure, path)


def phases_figure(path: Path, targets: np.ndarray) -> None:
    tour = get_planner("rbta").plan(targets, RHO_M)
    figure, axes = plt.subplots(figsize=(8, 7))
    colours = plt.get_cmap("viridis")
    phases = tour.report["phases"]
    start = 0.0
    for k, phase in enumerate(phases):
        end = start + phase["length_m"]
        _draw_chain(axes, tour.chain, start, end, color=colours(k / max(1, len(phases) - 1)),
                    lw=0.9, label=f"phase {phase['phase']}: {phase['serviced']} targets, "
                                  f"{phase['length_m'] / 1000:.1f} km")
        start = end
    if tour.report["leftovers"]:
        _draw_chain(axes, tour.chain, start, tour.chain.length_m, color="k", lw=0.9,
                    label=f"leftovers ({tour.report['leftovers']}): Alternating Algorithm")
    axes.plot(*targets.T, ".", color="crimson", ms=3, zorder=3)
    axes.set_aspect("equal")
    axes.set_title(f"faithful RBTA, {len(targets)} targets: {tour.length_m / 1000:.1f} km")
    axes.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8)
    _save(figure, path)


def lanes_figure(path: Path, targets: np.ndarray) -> None:
    tour = get_planner("lanes").plan(targets, RHO_M)
    figure, axes = plt.subplots(figsize=(8, 7))
    _draw_chain(axes, tour.chain, 0.0, tour.chain.length_m, color="tab:blue", lw=0.8)
    axes.plot(*targets.T, ".", color="crimson", ms=3, zorder=3)
    axes.set_aspect("equal")
    widths = ", ".join(f"{w} m: {v / 1000:.1f} km" for w, v in tour.report["lane_width_m"].items())
    axes.set_title(f"lanes, {len(targets)} targets: {tour.length_m / 1000:.1f} km (widths tried {widths})",
                   fontsize=9)
    _save(figure, path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent)
    args = parser.parse_args()
    targets = np.random.default_rng(3).uniform(0.0, 2000.0, (300, 2))
    bead_figure(args.out / "fig-bead.png")
    tiling_figure(args.out / "fig-tiling.png", targets)
    phases_figure(args.out / "fig-phases.png", targets)
    lanes_figure(args.out / "fig-lanes.png", targets)


if __name__ == "__main__":
    main()
