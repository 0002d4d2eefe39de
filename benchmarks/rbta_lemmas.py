"""Evidence that the RBTA behaves as its lemmas say, on uniform targets in a square.

Lemma 2.2: the targets left after the last phase number O(log n) w.h.p. (the proof's bound is
24 log2 n).  Lemma 2.3 / Theorem 2.4: the tour length grows like n^(2/3).  Also: per-phase
lengths, the ratio to the lower bound, planning time and peak memory at 1e5 and 1e6 targets.

Usage: python benchmarks/rbta_lemmas.py [--quick]   (writes docs/rbta-evidence.md and
docs/rbta-scaling.png; --quick uses fewer seeds, for a smoke run)
"""

from __future__ import annotations

import argparse
import math
import resource
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from dtsp_mission.bench.measure import format_table
from dtsp_mission.files import write_atomic
from dtsp_mission.planning import get_planner
from dtsp_mission.planning.lower_bounds import lower_bound

SIDE_M, RHO_M = 5000.0, 100.0
AREA_M2 = SIDE_M * SIDE_M
DOCS = Path(__file__).resolve().parents[1] / "docs"


def instance(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(0.0, SIDE_M, (n, 2))


def unit(n: int) -> float:
    """(rho A)^(1/3) n^(2/3): the natural unit of Dubins tour length."""
    return (RHO_M * AREA_M2) ** (1 / 3) * n ** (2 / 3)


def i_star(n: int) -> int:
    """The proof's last 'controlled' phase, floor(log2 n - log2 log2 n - log2 6)."""
    return math.floor(math.log2(n) - math.log2(math.log2(n)) - math.log2(6))


def _spread(values: list[int]) -> str:
    return f"{min(values)} / {statistics.median(values):g} / {statistics.mean(values):.1f} / {max(values)}"


def run(n: int, seed: int):
    targets = instance(n, seed)
    started = time.perf_counter()
    tour = get_planner("rbta").plan(targets, RHO_M)
    return tour, time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true")
    quick = parser.parse_args().quick
    get_planner("rbta").plan(instance(2000, 0), RHO_M)   # compile once, outside the timings
    lines = ["# RBTA: evidence for the lemmas", "",
             f"Uniform targets in a {SIDE_M / 1000:g} km square, rho = {RHO_M:g} m, seeds 1, 2, ...; "
             "every tour passed the checker (the planner refuses to return one that does not). "
             "Produced by `python benchmarks/rbta_lemmas.py`; numbers are measured, not typed.", ""]

    # Lemma 2.2: leftovers.
    seeds = {1000: 40, 10000: 20, 100000: 8} if not quick else {1000: 5, 10000: 3, 100000: 1}
    rows = []
    for n, count in seeds.items():
        tours = [run(n, seed)[0] for seed in range(1, count + 1)]
        leftovers = [tour.report["leftovers"] for tour in tours]
        star = i_star(n)
        after_star = [n - sum(p["serviced"] for p in tour.report["phases"][:star]) for tour in tours]
        phases = [len(tour.report["phases"]) for tour in tours]
        bound = 24 * math.log2(n)
        rows.append([f"{n:,}", str(count), str(star), _spread(after_star), _spread(leftovers),
                     f"{min(phases)}-{max(phases)} of {math.floor(math.log2(n)) + 1}", f"{bound:.0f}",
                     "yes" if max(after_star) < bound else "NO"])
        print(f"n={n}: after phase i*: {after_star}; leftovers {leftovers}", flush=True)
    lines += ["## Lemma 2.2: targets left unvisited", "",
              "The proof bounds the targets still unvisited after phase "
              "i*(n) = floor(log2 n - log2 log2 n - log2 6) by 24 log2 n w.h.p.; phases then go on "
              "(at most floor(log2 n) + 1) and whatever remains goes to the Alternating Algorithm. "
              "Cells give min / median / mean / max over the seeds.", "",
              "```", format_table(["n", "seeds", "i*", "unvisited after i*", "left for Alternating",
                                   "phases run", "24 log2 n", "max below"], rows), "```", ""]

    # Lemma 2.3: length against n.
    sizes = [1000, 2000, 5000, 10000, 20000, 50000, 100000]
    per_size = 3 if not quick else 1
    rows, medians, phase_rows = [], [], []
    for n in sizes:
        results = [run(n, seed) for seed in range(1, per_size + 1)]
        lengths = [tour.length_m for tour, _ in results]
        median_length = statistics.median(lengths)
        medians.append(median_length)
        tour = results[0][0]
        bound = lower_bound(tour.targets_m, RHO_M, AREA_M2)
        rows.append([f"{n:,}", f"{median_length / 1000:,.1f}", f"{median_length / unit(n):.2f}",
                     f"{median_length / bound.value_m:.2f}", bound.kind.split(" ")[0],
                     f"{statistics.median(t for _, t in results):.2f}",
                     str(len(tour.report["phases"])), str(tour.report["leftovers"])])
        phase_rows.append([f"{n:,}"] + [f"{p['length_m'] / 1000:,.0f}" for p in tour.report["phases"]])
        print(f"n={n}: median {median_length:.0f} m", flush=True)
    slope, intercept = np.polyfit(np.log(sizes), np.log(medians), 1)
    large = np.array(sizes) >= 10000
    slope_large = np.polyfit(np.log(np.array(sizes)[large]), np.log(np.array(medians)[large]), 1)[0]
    lines += ["## Lemma 2.3 / Theorem 2.4: tour length against n", "",
              f"Median over {per_size} seeds. Unit = (rho A)^(1/3) n^(2/3); lower bound = the larger of "
              "the stochastic bound (3/4)(3 rho A)^(1/3) n^(2/3) (asymptotic, uniform targets) and the "
              "certified 1-tree bound.", "",
              "```", format_table(["n", "length km", "units", "/ lower bound", "bound", "plan s",
                                   "phases", "leftovers"], rows), "```", "",
              f"Least-squares exponent of length against n over all sizes: **{slope:.3f}** "
              f"(2/3 = 0.667; difference {slope - 2 / 3:+.3f}); over n >= 10,000: {slope_large:.3f}.", "",
              "Per-phase lengths (km) of the first seed, phase 1 first:", "", "```"]
    lines += [" ".join(row) for row in phase_rows] + ["```", ""]
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        figure, axes = plt.subplots(figsize=(6, 4.2))
        axes.loglog(sizes, np.array(medians) / 1000, "o-", label="RBTA tour (median)")
        axes.loglog(sizes, [0.75 * (3 * RHO_M * AREA_M2) ** (1 / 3) * n ** (2 / 3) / 1000 for n in sizes],
                    "--", label="stochastic lower bound")
        axes.loglog(sizes, np.exp(intercept) * np.array(sizes) ** slope / 1000, ":",
                    label=f"fit: n^{slope:.3f}")
        axes.set_xlabel("targets n")
        axes.set_ylabel("length (km)")
        axes.set_title(f"RBTA, {SIDE_M / 1000:g} km square, rho = {RHO_M:g} m")
        axes.legend()
        axes.grid(True, which="both", alpha=0.3)
        figure.tight_layout()
        figure.savefig(DOCS / "rbta-scaling.png", dpi=110)
        lines += ["![tour length against n](rbta-scaling.png)", ""]
    except ImportError:
        lines += ["(matplotlib is not installed: no plot)", ""]

    # Speed and memory.
    rows = []
    for n in ([100000, 1000000] if not quick else [100000]):
        targets = instance(n, 1)
        times = []
        for _ in range(3 if n <= 100000 else 1):
            started = time.perf_counter()
            get_planner("rbta").plan(targets, RHO_M)
            times.append(time.perf_counter() - started)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20
        rows.append([f"{n:,}", str(len(times)), f"{statistics.median(times):.2f}", f"{peak:.2f}"])
        print(f"speed n={n}: {times}", flush=True)
    lines += ["## Speed (one core) and memory", "",
              "Wall time of `plan` (tiling, phases, leftovers and the checker), median of the runs; "
              "peak resident memory of the whole benchmark process so far.", "",
              "```", format_table(["n", "runs", "median s", "peak RSS GiB"], rows), "```", ""]
    write_atomic(DOCS / "rbta-evidence.md", "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    sys.exit(main())
