"""``dtsp-mission check``: run the tour checker on a tour file."""

from __future__ import annotations

import click

from ..tour import check_tour, read_tour
from .options import reports_errors


@click.command()
@click.argument("tour_file", type=click.Path(dir_okay=False))
@reports_errors
def check(tour_file: str) -> None:
    """Check that TOUR_FILE (tour JSON) is a feasible closed Dubins tour through its targets:
    C1-continuous, curvature at most 1/rho, closed, every target on the path within 1e-6 rho.
    Exit code 1 if it is not.

    Example: dtsp-mission check examples/square-tour.json
    """
    report = check_tour(read_tour(tour_file))
    click.echo(report.summary())
    for problem in report.problems:
        click.echo(f"  - {problem}")
    if not report.ok:
        raise SystemExit(1)
