"""From the faithful RBTA to the ``lanes`` planner, one step at a time, on the same instances.

Each row removes one kind of waste from the bead tiling and reports the median tour length over
the seeds as a ratio to the stochastic lower bound (and to the faithful RBTA):

1. ``rbta``: the paper's algorithm, unchanged;
2. rows of beads (lane width = the tiling's row spacing), only rows that hold targets, every
   sweep trimmed to its first and last target, every target of a row in that one pass, rows
   flown in plain order (U-turns to the adjacent row), Alternating Algorithm headings;
3. + rows flown interleaved, so turns go to rows at least ``2 rho`` apart;
4. + headings by dynamic programming over the visiting order;
5. + loop repair (a target whose neighbour forces a loop moves to the next lane);
6. + lane width from ``(A^2 / (n^2 rho))^(1/3)`` instead of the bead's: the ``lanes`` planner.

Usage: python benchmarks/bead_steps.py [--sizes 1000,5000,20000] [--seeds 3]
       [--markdown docs/bead-steps.md]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from dtsp_mission.bench.measure import format_table
from dtsp_mission.files import write_atomic
from dtsp_mission.planning import bounding_region, get_planner
from dtsp_mission.planning.lower_bounds import stochastic_lower_bound
from dtsp_mission.planning.tiling import BeadTiling

SIDE_M, RHO_M = 5000.0, 100.0


def bead_row_spacing_m(targets_m: np.ndarray) -> float:
    """Distance between the axes of the RBTA's bead rows for these targets."""
    return BeadTiling.for_region(bounding_region(targets_m), len(targets_m), RHO_M).row_spacing_m


def steps(targets_m: np.ndarray) -> list[tuple[str, str, dict]]:
    """(label, planner, parameters) of every step."""
    rows = dict(width_m=bead_row_spacing_m(targets_m))
    plain = dict(rows, interleave=False, dp_headings=False, repair_rounds=0)
    return [
        ("1 faithful RBTA", "rbta", {}),
        ("2 bead rows, trimmed, all targets per pass", "lanes", plain),
        ("3 + rows >= 2 rho apart", "lanes", dict(plain, interleave=True)),
        ("4 + headings by DP", "lanes", dict(rows, repair_rounds=0)),
        ("5 + loop repair", "lanes", rows),
        ("6 + lane width from n, A, rho (lanes)", "lanes", {}),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1000,5000,20000")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    rows: list[list[str]] = []
    for n in sizes:
        bound = stochastic_lower_bound(n, RHO_M, SIDE_M * SIDE_M)
        results: dict[str, list[tuple[float, float]]] = {}
        for seed in range(args.seeds):
            targets = np.random.default_rng(seed).uniform(0.0, SIDE_M, (n, 2))
            for label, name, parameters in steps(targets):
                start = time.perf_counter()
                tour = get_planner(name, **parameters).plan(targets, RHO_M)   # checked
                results.setdefault(label, []).append((tour.length_m, time.perf_counter() - start))
        rbta = statistics.median(length for length, _ in results["1 faithful RBTA"])
        for label, runs in results.items():
            length = statistics.median(length for length, _ in runs)
            rows.append([str(n), label, f"{length:,.0f}", f"{length / bound:.3f}",
                         f"{length / rbta:.3f}", f"{statistics.median(t for _, t in runs):.2f}"])
        print(f"n={n} done", flush=True)
    header = ["n", "step", "length m (median)", "/ lower bound", "/ faithful RBTA", "time s"]
    print(format_table(header, rows))
    if args.markdown:
        lines = ["# From the bead tiling to the lanes planner", "",
                 f"Produced by `python benchmarks/bead_steps.py --sizes {args.sizes} --seeds "
                 f"{args.seeds} --markdown {args.markdown}`: targets uniform in a {SIDE_M:g} m "
                 f"square, rho {RHO_M:g} m, medians over seeds; every tour passed the checker. "
                 "Steps are cumulative (see the script's docstring).", "",
                 "| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
        lines += ["| " + " | ".join(row) + " |" for row in rows]
        write_atomic(args.markdown, ("\n".join(lines) + "\n").encode())


if __name__ == "__main__":
    main()
