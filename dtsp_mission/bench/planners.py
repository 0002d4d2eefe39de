"""Planner benchmark: every planner on the same seeded instances, what each achieved.

For every family (:mod:`~dtsp_mission.bench.instances`: uniform, dense, clustered, the bundled
site), size and seed every planner plans the targets once; with ``anchor`` the LKH-3 GTSP
anchor (:mod:`~dtsp_mission.bench.anchor`) is a peer too and every length is also given as a
ratio to it.  Each planner plans once
(after one warm-up run per planner on a small instance, so compile time is not counted), with
tracemalloc tracing the run for its peak memory (numpy allocations included; the traced run is
the timed run, so times include tracemalloc's small overhead).  Each returned tour is checked
again here; a planner error is recorded, not hidden.
"""

from __future__ import annotations

import csv
import io
import json
import statistics
import time
import tracemalloc
from dataclasses import asdict, dataclass
from typing import Callable, Iterable

import numpy as np

from ..planning import get_planner
from ..planning.base import Planner
from ..planning.lower_bounds import lower_bound
from ..tour import check_tour
from .anchor import AnchorPlanner
from .instances import area_m2, instance
from .measure import format_table

ANCHOR = AnchorPlanner.name
#: Families whose targets are uniform: the stochastic lower bound applies to them.
UNIFORM_FAMILIES = ("uniform", "dense")
#: The bundled site is planned at the turn radius its missions are flown with.
SITE_RHO_M = 80.0

STANDARD_SIZES = (50, 200, 1000, 5000, 20000, 100000)


@dataclass(frozen=True)
class PlannerRun:
    """One planner on one instance."""

    family: str
    n: int
    seed: int
    planner: str
    length_m: float           # NaN if the planner failed
    lower_bound_m: float
    best_m: float             # shortest valid tour of this instance over all planners
    time_s: float
    peak_mib: float
    valid: bool
    error: str = ""
    anchor_m: float = float("nan")   # the anchor's length on this instance, if it ran

    @property
    def not_applicable(self) -> bool:
        """The planner declined the instance by design (the RBTA with too few targets)."""
        return self.error.startswith("TilingUnavailable")

    @property
    def over_bound(self) -> float:
        return self.length_m / self.lower_bound_m

    @property
    def over_best(self) -> float:
        return self.length_m / self.best_m

    @property
    def over_anchor(self) -> float:
        return self.length_m / self.anchor_m


def make_planner(name: str, time_limit_s: float | None = None) -> Planner:
    """The planner ``name`` (the anchor included), ``auto`` with the given improvement budget."""
    if name == ANCHOR:
        return AnchorPlanner()
    if name == "auto" and time_limit_s is not None:
        return get_planner(name, time_limit_s=time_limit_s)
    return get_planner(name)


def _one(name: str, targets: np.ndarray, rho_m: float,
         time_limit_s: float | None) -> tuple[float, float, float, bool, str]:
    tracemalloc.start()
    started = time.perf_counter()
    try:
        tour = make_planner(name, time_limit_s).plan(targets, rho_m)
        elapsed = time.perf_counter() - started
        _, peak = tracemalloc.get_traced_memory()
        return tour.length_m, elapsed, peak / 2**20, check_tour(tour).ok, ""
    except Exception as error:   # measured and reported, never hidden
        elapsed = time.perf_counter() - started
        _, peak = tracemalloc.get_traced_memory()
        return float("nan"), elapsed, peak / 2**20, False, f"{type(error).__name__}: {error}"
    finally:
        tracemalloc.stop()


def run(sizes: Iterable[int], seeds: int, rho_m: float, side_m: float, names: list[str],
        progress: Callable[[str], None] = lambda step: None,
        families: Iterable[str] = ("uniform",), time_limit_s: float | None = None) -> list[PlannerRun]:
    """Every planner in ``names`` on ``seeds`` instances of each family and size (the site
    family: one instance, its own size, at :data:`SITE_RHO_M`)."""
    warm = np.random.default_rng(0).uniform(0, side_m, (200, 2))
    for name in names:
        if name != ANCHOR:
            _one(name, warm, rho_m, 0.05)
    runs: list[PlannerRun] = []
    for family in families:
        cases = [(0, 0)] if family == "site" else [(n, seed) for n in sizes for seed in range(seeds)]
        for n, seed in cases:
            targets = instance(family, n, seed, side_m)
            n = len(targets)
            rho = SITE_RHO_M if family == "site" else rho_m
            bounds = lower_bound(targets, rho, area_m2(family, targets, side_m))
            # The stochastic bound holds for uniform targets only; elsewhere the certified one.
            bound = bounds.value_m if family in UNIFORM_FAMILIES else bounds.one_tree_m
            measured = []
            for name in names:
                progress(f"{family} n={n} seed={seed} {name}")
                measured.append((name, *_one(name, targets, rho, time_limit_s)))
            lengths = [m[1] for m in measured if m[4]]
            best = min(lengths) if lengths else float("nan")
            anchor = next((m[1] for m in measured if m[0] == ANCHOR and m[4]), float("nan"))
            runs += [PlannerRun(family, n, seed, name, length, bound, best, elapsed, peak, valid,
                                error, anchor)
                     for name, length, elapsed, peak, valid, error in measured]
    return runs


def _groups(runs: list[PlannerRun]) -> list[tuple[str, int, str]]:
    families = list(dict.fromkeys(r.family for r in runs))
    return sorted({(r.family, r.n, r.planner) for r in runs},
                  key=lambda k: (families.index(k[0]), k[1], k[2]))


def summary_rows(runs: list[PlannerRun]) -> list[list[str]]:
    """Median over seeds per (family, n, planner): the table the command prints."""
    rows = []
    median = statistics.median
    with_anchor = any(r.planner == ANCHOR for r in runs)
    for family, n, planner in _groups(runs):
        group = [r for r in runs if (r.family, r.n, r.planner) == (family, n, planner)]
        valid = [r for r in group if r.valid]
        row = [family, str(n), planner,
               f"{median(r.length_m for r in valid):,.0f}" if valid else
               ("not applicable" if all(r.not_applicable for r in group) else "failed"),
               f"{median(r.over_bound for r in valid):.3f}" if valid else "-",
               f"{median(r.over_best for r in valid):.3f}" if valid else "-"]
        if with_anchor:
            ratios = [r.over_anchor for r in valid if np.isfinite(r.anchor_m)]
            row.append(f"{median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f})"
                       if ratios else "-")
        row += [f"{statistics.median(r.time_s for r in group):.3f}",
                f"{max(r.peak_mib for r in group):.1f}", f"{len(valid)}/{len(group)}"]
        rows.append(row)
    return rows


def header(runs: list[PlannerRun]) -> list[str]:
    columns = ["family", "n", "planner", "length m (median)", "/ lower bound", "/ best of run"]
    if any(r.planner == ANCHOR for r in runs):
        columns.append("/ anchor (median, range)")
    return columns + ["time s", "peak MiB", "checked ok"]


def table(runs: list[PlannerRun]) -> str:
    return format_table(header(runs), summary_rows(runs))


def markdown(runs: list[PlannerRun], command: str, side_m: float, rho_m: float,
             merged: bool = False) -> str:
    """The summary as a Markdown table, with the command that produced it."""
    columns = header(runs)
    lines = ["| " + " | ".join(columns) + " |", "|" + " --- |" * len(columns)]
    lines += ["| " + " | ".join(row) + " |" for row in summary_rows(runs)]
    notes = [f"- {r.family} n={r.n} seed={r.seed} {r.planner}: "
             f"{'not applicable' if r.not_applicable else 'FAILED'}: {r.error or 'checker'}"
             for r in runs if not r.valid]
    sizes = sorted({r.n for r in runs if r.family != "site"})
    seeds = len({r.seed for r in runs})
    families = ", ".join(dict.fromkeys(r.family for r in runs))
    return (f"# Planner benchmark\n\nProduced by `{command}` (families {families}: uniform "
            f"and clustered in a {side_m:g} m square, dense in a 1.5 km square, the bundled "
            f"site at rho {SITE_RHO_M:g} m; rho {rho_m:g} m otherwise; sizes "
            f"{', '.join(map(str, sizes))}, {seeds} seeds; medians over seeds; time is one "
            "planning run on one core, peak memory as traced by tracemalloc). Not typed: rerun "
            "the command to refresh it."
            + (" The runs are merged from the files named, each written by `bench planners "
               "--json` (how each was measured: `benchmarks/README.md`; the anchor's runs shared "
               "the machine with a second benchmark process, one per core)." if merged else "")
            + "\n\n" + "\n".join(lines) + "\n"
            + ("\nRuns without a tour:\n\n" + "\n".join(notes) + "\n" if notes else ""))


def as_csv(runs: list[PlannerRun]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(list(asdict(runs[0]).keys()) + ["over_bound", "over_best", "over_anchor"])
    for r in runs:
        writer.writerow(list(asdict(r).values()) + [r.over_bound, r.over_best, r.over_anchor])
    return buffer.getvalue()


def as_json(runs: list[PlannerRun]) -> str:
    return json.dumps([dict(asdict(r), over_bound=r.over_bound, over_best=r.over_best,
                            over_anchor=r.over_anchor) for r in runs], indent=1) + "\n"


def recombine(runs: list[PlannerRun]) -> list[PlannerRun]:
    """Runs gathered from several measurements as one: a later run of the same planner on the
    same instance replaces an earlier one, and each instance's best of run and anchor length
    are taken anew over what is there."""
    from dataclasses import replace
    latest = {(r.family, r.n, r.seed, r.planner): r for r in runs}
    merged = list(latest.values())
    instances: dict[tuple, list[PlannerRun]] = {}
    for r in merged:
        instances.setdefault((r.family, r.n, r.seed), []).append(r)
    result = []
    for group in instances.values():
        lengths = [r.length_m for r in group if r.valid]
        best = min(lengths) if lengths else float("nan")
        anchor = next((r.length_m for r in group if r.planner == ANCHOR and r.valid), float("nan"))
        bound = min(r.lower_bound_m for r in group)      # the bound is the instance's, not a run's
        result += [replace(r, best_m=best, anchor_m=anchor, lower_bound_m=bound) for r in group]
    return result


def from_json(path) -> list[PlannerRun]:
    """The runs an earlier :func:`as_json` wrote (derived ratios recomputed, not read)."""
    from dataclasses import fields
    from ..errors import FileFormatError
    names = [f.name for f in fields(PlannerRun)]
    try:
        with open(path) as handle:
            return [PlannerRun(**{k: (float("nan") if v is None else v) for k, v in row.items()
                                  if k in names}) for row in json.load(handle)]
    except (OSError, ValueError, TypeError) as error:
        raise FileFormatError(f"{path}: not a planner benchmark JSON file ({error})") from None


def plot_png(runs: list[PlannerRun], side_m: float, rho_m: float) -> bytes:
    """Log-log plot of the median length against n per planner, with the lower bound, for the
    first family measured (uniform if it was)."""
    families = [r.family for r in runs]
    family = "uniform" if "uniform" in families else families[0]
    runs = [r for r in runs if r.family == family]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, axes = plt.subplots(figsize=(8, 6), dpi=120)
    sizes = sorted({r.n for r in runs})
    for planner in sorted({r.planner for r in runs}):
        points = [(n, statistics.median([r.length_m for r in runs if r.n == n and r.planner == planner
                                         and r.valid] or [float("nan")])) for n in sizes]
        axes.loglog(*zip(*points), marker="o", label=planner)
    bounds = [statistics.median([r.lower_bound_m for r in runs if r.n == n]) for n in sizes]
    axes.loglog(sizes, bounds, "k--", label="lower bound")
    axes.set_xlabel("targets n")
    axes.set_ylabel("tour length (m)")
    axes.set_title(f"{family} targets, rho {rho_m:g} m" if family != "uniform" else
                   f"uniform targets, {side_m / 1000:g} km square, rho {rho_m:g} m")
    axes.grid(True, which="both", linewidth=0.3)
    axes.legend()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", bbox_inches="tight")
    plt.close(figure)
    return buffer.getvalue()
