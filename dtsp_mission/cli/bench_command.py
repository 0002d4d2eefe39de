"""``dtsp-mission bench``: benchmarks that print what they measured."""

from __future__ import annotations

import click

from .options import reports_errors, seed_option


@click.group()
def bench() -> None:
    """Measure speed and memory; results are printed as tables."""


@bench.command("dubins")
@click.option("--pairs", type=click.IntRange(1), default=1_000_000, show_default=True,
              help="Random pose pairs for the batch kernel.")
@click.option("--ompl-pairs", type=click.IntRange(1), default=200_000, show_default=True,
              help="How many of them OMPL computes, one Python call each.")
@click.option("--radius", "rho_m", type=float, default=100.0, show_default=True,
              help="Turn radius in metres.")
@click.option("--half-width", "half_width_m", type=float, default=1000.0, show_default=True,
              help="Positions are uniform in a square of side twice this, in metres.")
@click.option("--repeats", type=click.IntRange(1), default=5, show_default=True)
@seed_option
@reports_errors
def dubins_bench(pairs: int, ompl_pairs: int, rho_m: float, half_width_m: float, repeats: int,
                 seed: int) -> None:
    """Batch Dubins lengths per second, beside OMPL called per pair from Python."""
    from ..bench import dubins_throughput
    rows, difference = dubins_throughput.run(pairs, ompl_pairs, rho_m, half_width_m, repeats, seed)
    click.echo(dubins_throughput.report(rows, difference))
