"""``dtsp-mission dubins``: the shortest Dubins path between two poses."""

from __future__ import annotations

import math

import click
import numpy as np

from ..dubins import shortest_path
from .options import radius_option, reports_errors


def _pose(text: str) -> np.ndarray:
    try:
        x, y, heading_deg = (float(v) for v in text.split(","))
    except ValueError:
        raise click.BadParameter(f"{text!r} is not X_M,Y_M,HEADING_DEG") from None
    if not all(map(math.isfinite, (x, y, heading_deg))):
        raise click.BadParameter(f"{text!r}: every number must be finite")
    if max(abs(x), abs(y)) > MAX_COORDINATE_M:
        raise click.BadParameter(f"{text!r}: x and y must be within +-{MAX_COORDINATE_M:,.0f} m "
                                 "(a local frame in metres)")
    return np.array([x, y, math.radians(math.fmod(heading_deg, 360.0))])   # fmod is exact


#: Poses farther out than this are not in any local frame a mission is planned in (and their
#: lengths would lose every digit below a metre).
MAX_COORDINATE_M = 1e7


@click.command(context_settings={"ignore_unknown_options": True})   # -5,0,0 is a pose
@click.argument("start", metavar="X_M,Y_M,HEADING_DEG")
@click.argument("goal", metavar="X_M,Y_M,HEADING_DEG")
@radius_option
@reports_errors
def dubins(start: str, goal: str, rho_m: float) -> None:
    """Print the shortest Dubins path from START to GOAL.

    Poses are in a local frame in metres (x east, y north) with the heading in degrees
    counter-clockwise from east.  Example: dtsp-mission dubins 0,0,0 0,0,180 --radius 80
    """
    path = shortest_path(_pose(start), _pose(goal), rho_m)
    t, p, q = path.segment_lengths_m
    end = path.end()
    click.echo(f"word {path.word}: segments {t:.3f} m, {p:.3f} m, {q:.3f} m; "
               f"length {path.length_m:.3f} m ({path.length_m / rho_m:.6f} rho)")
    click.echo(f"end pose by integration: x {end[0]:.6f} m, y {end[1]:.6f} m, "
               f"heading {math.degrees(end[2]) % 360:.6f} deg")
