"""OMPL's DubinsStateSpace called once per pose pair from Python, in a clean process.

Run as ``python -m dtsp_mission.bench.ompl_reference PAIRS.npz OUT.npz RHO REPEATS``.  It lives
in its own process because loading numba (our kernel) into the same interpreter was measured to
slow OMPL's per-call path by 25-60 %; a clean process measures OMPL at its best.  This module
imports only numpy and ompl.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np


def ompl_lengths(starts: np.ndarray, goals: np.ndarray, rho_m: float) -> np.ndarray:
    """Reference lengths from OMPL's DubinsStateSpace, one Python call per pair."""
    from ompl import base as ob
    space = ob.DubinsStateSpace(rho_m)
    a, b = space.allocState(), space.allocState()
    # The leanest loop we know (bound methods, list output), so OMPL is not charged for ours.
    set_a_xy, set_a_yaw, set_b_xy, set_b_yaw = a.setXY, a.setYaw, b.setXY, b.setYaw
    distance = space.distance
    lengths = []
    append = lengths.append
    for (x0, y0, h0), (x1, y1, h1) in zip(starts.tolist(), goals.tolist()):
        set_a_xy(x0, y0)
        set_a_yaw(h0)
        set_b_xy(x1, y1)
        set_b_yaw(h1)
        append(distance(a, b))
    return np.array(lengths)


def main(arguments: list[str]) -> None:
    pairs_file, out_file, rho, repeats = arguments[0], arguments[1], float(arguments[2]), int(arguments[3])
    pairs = np.load(pairs_file)
    starts, goals = pairs["starts"], pairs["goals"]
    lengths = ompl_lengths(starts, goals, rho)  # warm-up, and the reference values
    runs = []
    for _ in range(repeats):
        start = time.perf_counter()
        ompl_lengths(starts, goals, rho)
        runs.append(time.perf_counter() - start)
    np.savez(out_file, lengths=lengths, runs=np.array(runs), median=statistics.median(runs))


if __name__ == "__main__":
    main(sys.argv[1:])
