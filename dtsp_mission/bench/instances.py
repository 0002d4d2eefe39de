"""Seeded benchmark instances: the kinds of site planners are compared on.

Every family maps (n, seed) to targets in metres, the same on every machine:

* ``uniform``: uniform in a square of the given side (the paper's setting);
* ``dense``: uniform in a 1.5 km square, targets a few turn radii apart or closer;
* ``clustered``: three quarters of the targets in Gaussian clusters (sigma 150 m, one cluster
  per 40 targets) among uniform sparse ones, in the same square as ``uniform``;
* ``site``: the bundled inspection site (``examples/site-local.csv``: power lines, a fence,
  tank rims; its own n, the seed is ignored).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

FAMILIES = ("uniform", "dense", "clustered", "site")
DENSE_SIDE_M = 1500.0
CLUSTER_SIGMA_M = 150.0
TARGETS_PER_CLUSTER = 40
SITE_FILE = Path(__file__).resolve().parents[2] / "examples" / "site-local.csv"


def site_targets() -> np.ndarray:
    """The bundled inspection site in local metres (n = 420)."""
    if not SITE_FILE.exists():
        raise FileNotFoundError(f"the bundled site {SITE_FILE} is not here (a source checkout has it)")
    with open(SITE_FILE, newline="") as handle:
        return np.array([[float(row["x"]), float(row["y"])] for row in csv.DictReader(handle)])


def instance(family: str, n: int, seed: int, side_m: float = 5000.0) -> np.ndarray:
    """Targets (n, 2) in metres of ``family`` (see the module docstring)."""
    rng = np.random.default_rng(seed)
    if family == "uniform":
        return rng.uniform(0.0, side_m, (n, 2))
    if family == "dense":
        return rng.uniform(0.0, DENSE_SIDE_M, (n, 2))
    if family == "clustered":
        centres = rng.uniform(0.0, side_m, (max(2, n // TARGETS_PER_CLUSTER), 2))
        clustered = n * 3 // 4
        members = centres[rng.integers(0, len(centres), clustered)]
        members = members + rng.normal(0.0, CLUSTER_SIGMA_M, (clustered, 2))
        return np.vstack([members, rng.uniform(0.0, side_m, (n - clustered, 2))])
    if family == "site":
        return site_targets()
    raise ValueError(f"unknown instance family {family!r} (known: {', '.join(FAMILIES)})")


def area_m2(family: str, targets_m: np.ndarray, side_m: float = 5000.0) -> float:
    """The area the family's targets are drawn in (for the lower bound's estimate)."""
    if family == "uniform" or family == "clustered":
        return side_m * side_m
    if family == "dense":
        return DENSE_SIDE_M * DENSE_SIDE_M
    extent = np.ptp(targets_m, axis=0)
    return float(max(extent[0] * extent[1], 1.0))
