"""``dtsp-mission plan``: plan a tour through targets and write it."""

from __future__ import annotations

import time

import click
import numpy as np

from ..planning import TilingUnavailable, get_planner, planners
from ..planning.lower_bounds import lower_bound
from ..targets import read_local_csv
from ..tour import write_tour
from .options import radius_option, reports_errors


@click.command()
@click.argument("targets_file", type=click.Path(dir_okay=False))
@radius_option
@click.option("--algorithm", default="auto", show_default=True,
              help="Planner: " + ", ".join(sorted(planners())) + ".")
@click.option("--region", default="bounding", show_default=True,
              help="Rectangle the bead tiling covers: 'bounding', 'min-area', or a sweep "
                   "heading in degrees counter-clockwise from east.")
@click.option("--fallback/--no-fallback", default=True, show_default=True,
              help="If the RBTA cannot tile (too few targets), plan with the Alternating "
                   "Algorithm instead of failing.")
@click.option("-o", "--output", "outputs", multiple=True, type=click.Path(dir_okay=False),
              help="Write the tour here (tour JSON). Repeatable.")
@reports_errors
def plan(targets_file: str, rho_m: float, algorithm: str, region: str, fallback: bool,
         outputs: tuple[str, ...]) -> None:
    """Plan a closed Dubins tour through the targets in TARGETS_FILE.

    TARGETS_FILE is a CSV with columns x and y in metres (a local frame: x east, y north).
    Example: dtsp-mission plan examples/site-local.csv --radius 80 -o tour.json
    """
    targets = read_local_csv(targets_file)
    if targets.merged_duplicates:
        click.echo(f"note: {targets.merged_duplicates} duplicate targets merged "
                   f"({len(targets.positions_m)} remain)", err=True)
    parameters = {"region": region} if algorithm in ("rbta", "auto") else {}
    started = time.perf_counter()
    try:
        tour = get_planner(algorithm, **parameters).plan(targets.positions_m, rho_m)
    except TilingUnavailable as error:
        if not fallback:
            raise
        click.echo(f"note: {error}; planning with the Alternating Algorithm instead", err=True)
        tour = get_planner("alternating").plan(targets.positions_m, rho_m)
    elapsed = time.perf_counter() - started
    positions = targets.positions_m
    area = max(float(np.ptp(positions[:, 0]) * np.ptp(positions[:, 1])), 1.0)
    bound = lower_bound(positions, rho_m, area)
    click.echo(f"planner {tour.planner}: {len(positions)} targets, tour {tour.length_m:,.1f} m "
               f"({elapsed:.2f} s)")
    click.echo(f"lower bound {bound.value_m:,.1f} m [{bound.kind}]: ratio "
               f"{tour.length_m / bound.value_m:.3f}")
    for phase in tour.report.get("phases", []):
        click.echo(f"  phase {phase['phase']}: meta-beads of {phase['meta_bead_beads'][0]}x"
                   f"{phase['meta_bead_beads'][1]} beads, {phase['serviced']} targets, "
                   f"{phase['length_m']:,.1f} m")
    for name, result in tour.report.get("candidates", {}).items():
        shown = f"{result:,.1f} m" if isinstance(result, float) else result
        click.echo(f"  candidate {name}: {shown}")
    if "leftovers" in tour.report:
        click.echo(f"  leftovers (Alternating Algorithm): {tour.report['leftovers']} targets, "
                   f"{tour.report['leftover_length_m']:,.1f} m")
    for output in outputs:
        write_tour(tour, output)
        click.echo(f"wrote {output}")
