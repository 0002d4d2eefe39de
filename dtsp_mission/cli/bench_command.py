"""``dtsp-mission bench``: benchmarks that print what they measured."""

from __future__ import annotations

import click

from .options import LIMITS, FiniteFloatRange, UserError, reports_errors, seed_option


bench_radius_option = click.option("--radius", "rho_m", type=LIMITS["radius"], default=100.0,
                                   show_default=True, help="Turn radius in metres.")


@click.group()
def bench() -> None:
    """Measure speed and memory; results are printed as tables.

    Example: dtsp-mission bench planners --sizes 100,400 --seeds 2
    """


@bench.command("dubins")
@click.option("--pairs", type=click.IntRange(1), default=1_000_000, show_default=True,
              help="Random pose pairs for the batch kernel.")
@click.option("--ompl-pairs", type=click.IntRange(1), default=200_000, show_default=True,
              help="How many of them OMPL computes, one Python call each.")
@bench_radius_option
@click.option("--half-width", "half_width_m", type=LIMITS["extent"], default=1000.0, show_default=True,
              help="Positions are uniform in a square of side twice this, in metres.")
@click.option("--repeats", type=click.IntRange(1), default=5, show_default=True)
@seed_option
@reports_errors
def dubins_bench(pairs: int, ompl_pairs: int, rho_m: float, half_width_m: float, repeats: int,
                 seed: int) -> None:
    """Batch Dubins lengths per second, beside OMPL called per pair from Python.

    Example: dtsp-mission bench dubins --pairs 1000000
    """
    from ..bench import dubins_throughput
    rows, difference = dubins_throughput.run(pairs, ompl_pairs, rho_m, half_width_m, repeats, seed)
    click.echo(dubins_throughput.report(rows, difference))


def _sizes(ctx, param, value: str) -> list[int]:
    try:
        sizes = [int(part) for part in value.split(",") if part.strip()]
    except ValueError:
        raise click.BadParameter(f"{value!r} is not a comma-separated list of integers") from None
    if not sizes or min(sizes) < 1:
        raise click.BadParameter("sizes must be positive integers")
    return sizes


@bench.command("planners")
@click.option("--sizes", default="50,200,1000,5000,20000,100000", show_default=True,
              callback=_sizes, help="Numbers of targets, comma separated.")
@click.option("--seeds", type=click.IntRange(1), default=3, show_default=True,
              help="Instances (seeds 0..N-1) per size.")
@bench_radius_option
@click.option("--side", "side_m", type=LIMITS["extent"], default=5000.0, show_default=True,
              help="Side of the square the targets are uniform in, metres.")
@click.option("--planners", "names", default=None,
              help="Planners to compare, comma separated (default: every installed one).")
@click.option("--families", default="uniform", show_default=True,
              help="Instance families, comma separated: uniform, dense (1.5 km square), "
                   "clustered (Gaussian clusters among sparse targets), site (the bundled "
                   "inspection site, at rho 80 m).")
@click.option("--anchor", is_flag=True,
              help="Add the LKH-3 GTSP anchor (K = 8, 16, 32 headings, Noon-Bean, elkai) as a "
                   "peer and give every length over it; needs pip install -e \".[bench]\".")
@click.option("--time-limit", "time_limit_s", type=FiniteFloatRange(min=0.0, max=86400.0), default=None,
              help="auto's improvement budget in reference seconds (default: auto's own).")
@click.option("--merge", "merge_files", multiple=True, type=click.Path(exists=True, dir_okay=False),
              help="Measure nothing: tabulate the runs of earlier --json outputs (repeatable; "
                   "e.g. families measured on separate cores; a later file's run of a planner on "
                   "an instance replaces an earlier one, so the slow anchor need not be rerun).")
@click.option("--csv", "csv_file", type=click.Path(dir_okay=False), help="Write every run as CSV.")
@click.option("--json", "json_file", type=click.Path(dir_okay=False), help="Write every run as JSON.")
@click.option("--markdown", "markdown_file", type=click.Path(dir_okay=False),
              help="Write the summary table as Markdown (for docs/benchmarks.md).")
@click.option("--plot", "plot_file", type=click.Path(dir_okay=False),
              help="Log-log PNG of length against n, with the lower bound.")
@reports_errors
def planners_bench(sizes, seeds, rho_m, side_m, names, families, anchor, time_limit_s, merge_files,
                   csv_file, json_file, markdown_file, plot_file) -> None:
    """Every planner on seeded instances of each family: length, ratio to the lower bound, to
    the best of the run and (--anchor) to the LKH-3 anchor, time, peak memory, checker
    verdict (medians over seeds).

    Example: dtsp-mission bench planners --sizes 50,200 --families uniform,dense --seeds 2
    """
    import sys

    from ..bench import planners as planner_bench
    from ..files import write_atomic
    from ..planning import planners
    from ..plugins import working
    from ..plot import require_matplotlib
    if plot_file:
        require_matplotlib()
    installed = list(working(planners()))
    chosen = installed if names is None else [n.strip() for n in names.split(",") if n.strip()]
    unknown = sorted(set(chosen) - set(installed))
    if unknown:
        raise UserError(f"unknown planner(s) {', '.join(unknown)} (installed: {', '.join(installed)})")
    from ..bench.instances import FAMILIES
    family_list = [f.strip() for f in families.split(",") if f.strip()]
    if not family_list or set(family_list) - set(FAMILIES):
        raise UserError(f"--families takes a comma-separated list of {', '.join(FAMILIES)}")
    if anchor:
        from ..bench.anchor import AnchorPlanner, require_elkai
        require_elkai()
        chosen.append(AnchorPlanner.name)
    steps = sum(1 if f == "site" else len(sizes) * seeds for f in family_list) * len(chosen)
    if merge_files:
        runs = planner_bench.recombine(
            [run for path in merge_files for run in planner_bench.from_json(path)])
        family_list = list(dict.fromkeys(r.family for r in runs))
        seeds = len({r.seed for r in runs})
    else:
        if sys.stderr.isatty():
            with click.progressbar(length=steps, label="planning", file=sys.stderr,
                                   item_show_func=lambda step: step) as bar:
                runs = planner_bench.run(sizes, seeds, rho_m, side_m, chosen,
                                         lambda step: bar.update(1, step), family_list, time_limit_s)
        else:       # no bar fragments in a log file
            runs = planner_bench.run(sizes, seeds, rho_m, side_m, chosen, lambda step: None,
                                     family_list, time_limit_s)
    click.echo(f"families {', '.join(family_list)} (uniform and clustered in a {side_m:g} m "
               f"square), rho {rho_m:g} m, {seeds} seeds; medians over seeds")
    click.echo(planner_bench.table(runs))
    for r in runs:
        if not r.valid:
            verdict = "not applicable" if r.not_applicable else "FAILED"
            click.echo(f"{verdict}: {r.family} n={r.n} seed={r.seed} {r.planner}: "
                       f"{r.error or 'checker'}")
    command = "dtsp-mission bench planners " + " ".join(sys.argv[3:]) if len(sys.argv) > 3 else \
        "dtsp-mission bench planners"
    for path, content in ((csv_file, lambda: planner_bench.as_csv(runs)),
                          (json_file, lambda: planner_bench.as_json(runs)),
                          (markdown_file, lambda: planner_bench.markdown(runs, command, side_m, rho_m,
                                                                        bool(merge_files))),
                          (plot_file, lambda: planner_bench.plot_png(runs, side_m, rho_m))):
        if path:
            write_atomic(path, content())
            click.echo(f"wrote {path}")
