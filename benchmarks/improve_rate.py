"""Dubins evaluations per second of the improvement stage, on this machine.

``--time-limit`` is a work budget: ``limit * EVALUATIONS_PER_SECOND`` Dubins evaluations
(``dtsp_mission/planning/improve.py``), so that the same input, limit and seed give the same
tour on every machine.  This script measures the rate the constant stands for: the improver
runs a fixed budget on seeded uniform instances (density of a 5 km square at n = 1,000) from
the ``headings`` tour, stall stop disabled; median of repeated runs, one core.

    python benchmarks/improve_rate.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from dtsp_mission.bench.measure import format_table
from dtsp_mission.planning import get_planner
from dtsp_mission.planning import improve

SIZES = (30, 100, 1000, 10_000)
BUDGET_S = 2.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    improve.MIN_STALL_KICKS = 10**12           # measure the search, not its stopping rule
    rows = []
    for n in SIZES:
        side = 5000.0 * np.sqrt(n / 1000)
        points = np.random.default_rng(0).uniform(0, side, (n, 2))
        start = get_planner("headings").plan(points, 100.0)
        order = start.visit_order
        headings = start.visit_poses()[order, 2]
        improve.improve_tour(points, order, headings, 100.0, 0.01)      # compiled, cached
        rates, times = [], []
        for _ in range(args.repeats):
            started = time.perf_counter()
            result = improve.improve_tour(points, order, headings, 100.0, BUDGET_S)
            elapsed = time.perf_counter() - started
            rates.append(result.evaluations / elapsed)
            times.append(elapsed)
        rows.append([str(n), f"{statistics.median(rates) / 1e6:.2f}",
                     f"{statistics.median(times):.2f}", f"{BUDGET_S:g}"])
    print(f"improvement stage, budget {BUDGET_S:g} reference s "
          f"({improve.EVALUATIONS_PER_SECOND / 1e6:.1f} M evaluations per reference second); "
          f"median of {args.repeats} runs")
    print(format_table(["n", "M evaluations / s", "wall s", "reference s"], rows))


if __name__ == "__main__":
    main()
