"""Planner benchmark: every planner on the same seeded uniform instances, what each achieved.

For every size and seed the targets are uniform in a square; every planner plans them once
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
from ..planning.lower_bounds import lower_bound
from ..tour import check_tour
from .measure import format_table

STANDARD_SIZES = (50, 200, 1000, 5000, 20000, 100000)


@dataclass(frozen=True)
class PlannerRun:
    """One planner on one instance."""

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


def _one(name: str, targets: np.ndarray, rho_m: float) -> tuple[float, float, float, bool, str]:
    tracemalloc.start()
    started = time.perf_counter()
    try:
        tour = get_planner(name).plan(targets, rho_m)
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
        progress: Callable[[str], None] = lambda step: None) -> list[PlannerRun]:
    """Every planner in ``names`` on ``seeds`` instances of each size."""
    warm = np.random.default_rng(0).uniform(0, side_m, (200, 2))
    for name in names:
        _one(name, warm, rho_m)
    runs: list[PlannerRun] = []
    for n in sizes:
        for seed in range(seeds):
            targets = np.random.default_rng(seed).uniform(0, side_m, (n, 2))
            bound = lower_bound(targets, rho_m, side_m * side_m).value_m
            measured = []
            for name in names:
                progress(f"n={n} seed={seed} {name}")
                measured.append((name, *_one(name, targets, rho_m)))
            lengths = [m[1] for m in measured if m[4]]
            best = min(lengths) if lengths else float("nan")
            runs += [PlannerRun(n, seed, name, length, bound, best, elapsed, peak, valid, error)
                     for name, length, elapsed, peak, valid, error in measured]
    return runs


def summary_rows(runs: list[PlannerRun]) -> list[list[str]]:
    """Median over seeds per (n, planner): the table the command prints."""
    rows = []
    keys = sorted({(r.n, r.planner) for r in runs}, key=lambda k: (k[0], k[1]))
    for n, planner in keys:
        group = [r for r in runs if r.n == n and r.planner == planner]
        valid = [r for r in group if r.valid]
        median = statistics.median
        rows.append([
            str(n), planner,
            f"{median(r.length_m for r in valid):,.0f}" if valid else
            ("not applicable" if all(r.not_applicable for r in group) else "failed"),
            f"{median(r.over_bound for r in valid):.3f}" if valid else "-",
            f"{median(r.over_best for r in valid):.3f}" if valid else "-",
            f"{statistics.median(r.time_s for r in group):.3f}",
            f"{max(r.peak_mib for r in group):.1f}",
            f"{len(valid)}/{len(group)}",
        ])
    return rows


HEADER = ["n", "planner", "length m (median)", "/ lower bound", "/ best of run", "time s",
          "peak MiB", "checked ok"]


def table(runs: list[PlannerRun]) -> str:
    return format_table(HEADER, summary_rows(runs))


def markdown(runs: list[PlannerRun], command: str, side_m: float, rho_m: float) -> str:
    """The summary as a Markdown table, with the command that produced it."""
    lines = ["| " + " | ".join(HEADER) + " |", "|" + " --- |" * len(HEADER)]
    lines += ["| " + " | ".join(row) + " |" for row in summary_rows(runs)]
    notes = [f"- n={r.n} seed={r.seed} {r.planner}: "
             f"{'not applicable' if r.not_applicable else 'FAILED'}: {r.error or 'checker'}"
             for r in runs if not r.valid]
    sizes = sorted({r.n for r in runs})
    seeds = len({r.seed for r in runs})
    return (f"# Planner benchmark\n\nProduced by `{command}` (targets uniform in a "
            f"{side_m:g} m square, rho {rho_m:g} m, sizes "
            f"{', '.join(map(str, sizes))}, {seeds} seeds; medians over seeds; time is one "
            "planning run on one core, peak memory as traced by tracemalloc). Not typed: rerun "
            "the command to refresh it.\n\n" + "\n".join(lines) + "\n"
            + ("\nRuns without a tour:\n\n" + "\n".join(notes) + "\n" if notes else ""))


def as_csv(runs: list[PlannerRun]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(list(asdict(runs[0]).keys()) + ["over_bound", "over_best"])
    for r in runs:
        writer.writerow(list(asdict(r).values()) + [r.over_bound, r.over_best])
    return buffer.getvalue()


def as_json(runs: list[PlannerRun]) -> str:
    return json.dumps([dict(asdict(r), over_bound=r.over_bound, over_best=r.over_best)
                       for r in runs], indent=1) + "\n"


def plot_png(runs: list[PlannerRun], side_m: float, rho_m: float) -> bytes:
    """Log-log plot of the median length against n per planner, with the lower bound."""
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
    axes.set_title(f"uniform targets, {side_m / 1000:g} km square, rho {rho_m:g} m")
    axes.grid(True, which="both", linewidth=0.3)
    axes.legend()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", bbox_inches="tight")
    plt.close(figure)
    return buffer.getvalue()
