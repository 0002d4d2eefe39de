"""Throughput of the batch Dubins kernel, side by side with OMPL called per pair from Python."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..dubins import shortest_length
from .measure import format_table, measure


@dataclass(frozen=True)
class ThroughputRow:
    implementation: str
    pairs: int
    median_s: float
    pairs_per_s: float
    peak_mib: float


def random_pose_pairs(count: int, half_width_m: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Uniform positions in a square of side 2 * half_width_m, uniform headings."""
    rng = np.random.default_rng(seed)
    def poses() -> np.ndarray:
        return np.column_stack([rng.uniform(-half_width_m, half_width_m, (count, 2)),
                                rng.uniform(0.0, 2.0 * np.pi, count)])
    return poses(), poses()


def ompl_in_clean_process(starts: np.ndarray, goals: np.ndarray, rho_m: float,
                          repeats: int) -> tuple[np.ndarray, float] | None:
    """OMPL's lengths and median time for the pairs, measured in a child interpreter that
    never loads numba; ``None`` when OMPL is not installed."""
    if importlib.util.find_spec("ompl") is None:
        return None
    with tempfile.TemporaryDirectory() as directory:
        pairs_file, out_file = Path(directory, "pairs.npz"), Path(directory, "out.npz")
        np.savez(pairs_file, starts=starts, goals=goals)
        subprocess.run([sys.executable, "-m", "dtsp_mission.bench.ompl_reference", str(pairs_file),
                        str(out_file), repr(rho_m), str(repeats)], check=True)
        with np.load(out_file) as result:
            return result["lengths"], float(result["median"])


def run(pairs: int, ompl_pairs: int, rho_m: float, half_width_m: float, repeats: int,
        seed: int) -> tuple[list[ThroughputRow], float]:
    """Measure both implementations; returns the rows and the largest relative difference
    between them on the pairs OMPL computed."""
    starts, goals = random_pose_pairs(pairs, half_width_m, seed)
    rows = []
    ours = measure(lambda: shortest_length(starts, goals, rho_m), repeats)
    rows.append(ThroughputRow("dtsp_mission.dubins.shortest_length (batch, 1 core)", pairs,
                              ours.median_s, pairs / ours.median_s, ours.peak_bytes / 2**20))
    count = min(ompl_pairs, pairs)
    reference = ompl_in_clean_process(starts[:count], goals[:count], rho_m, max(1, repeats // 2))
    if reference is None:
        return rows, float("nan")
    lengths, median_s = reference
    rows.append(ThroughputRow("OMPL DubinsStateSpace.distance, per pair from Python", count,
                              median_s, count / median_s, float("nan")))
    difference = np.abs(shortest_length(starts[:count], goals[:count], rho_m) - lengths)
    return rows, float(np.max(difference / np.maximum(lengths, 1e-300)))


def _mib(value: float) -> str:
    return "n/a" if np.isnan(value) else f"{value:.1f}"


def report(rows: list[ThroughputRow], max_relative_difference: float) -> str:
    table = format_table(["implementation", "pairs", "median s", "lengths/s", "peak MiB"],
                         [[r.implementation, f"{r.pairs:,}", f"{r.median_s:.4f}",
                           f"{r.pairs_per_s:,.0f}", _mib(r.peak_mib)] for r in rows])
    lines = [table, "(OMPL runs in a separate clean interpreter; its peak memory is not traced.)"]
    if len(rows) > 1:
        lines.append(f"speed-up over OMPL-from-Python: {rows[0].pairs_per_s / rows[1].pairs_per_s:.1f}x; "
                     f"largest relative difference from OMPL: {max_relative_difference:.2e}")
    else:
        lines.append("OMPL is not installed (pip install 'dtsp-mission[bench]'): no reference row.")
    return "\n".join(lines)
