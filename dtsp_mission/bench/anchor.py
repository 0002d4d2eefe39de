"""The anchor the default planner is measured against: the literature's standard strong method.

K headings per target (evenly spaced) make the Dubins TSP a generalised TSP: visit one
(target, heading) node of every target.  The Noon-Bean transformation turns it into an
asymmetric TSP (the nodes of a target on a zero-cost cycle, every arc leaving a target moved to
the predecessor of its tail on that cycle, plus a constant that makes leaving a target before
all its nodes are visited never pay), which LKH-3 solves (PyPI ``elkai``, installed by the
``bench`` extra).  A second start: the Euclidean LKH tour with headings by dynamic programming
over the same K.  The anchor is the shortest of all runs; every run's tour is rebuilt from its
poses with exact Dubins paths and passed through the tour checker.

Sizes: the ATSP has n K nodes and a full matrix goes to LKH, so K is skipped (and the skip
reported) where n K exceeds ``max_nodes``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..dubins import shortest_length
from ..errors import DtspError
from ..planning.base import Planner
from ..planning.headings import optimise_headings
from ..planning.region import Region
from ..tour import Tour, tour_through_poses

DEFAULT_HEADINGS = (8, 16, 32)
DEFAULT_MAX_NODES = 3500
_RESOLUTION_M = 0.1        # LKH takes integer weights: lengths in units of 10 cm at best


def require_elkai():
    """The elkai module, or a DtspError saying how to install it."""
    try:
        import elkai
    except ImportError:
        raise DtspError("the LKH anchor needs the package elkai: pip install -e \".[bench]\"") \
            from None
    return elkai


def _gtsp_matrix(points_m: np.ndarray, headings_rad: np.ndarray, rho_m: float) -> np.ndarray:
    """Noon-Bean ATSP matrix (integers) of the GTSP over ``headings_rad`` at every point."""
    n, k = len(points_m), len(headings_rad)
    nodes = np.column_stack([np.repeat(points_m, k, axis=0), np.tile(headings_rad, n)])
    m = n * k
    start = np.repeat(nodes, m, axis=0)
    goal = np.tile(nodes, (m, 1))
    lengths = shortest_length(start, goal, rho_m).reshape(m, m)
    # LKH scales weights by its PRECISION (100) in 32-bit integers: the largest weight, about
    # 2 n max(length), must stay below 2**31 / 100.
    resolution = max(_RESOLUTION_M, 2.0 * n * float(lengths.max()) * 100.0 / 2**31 * 1.25)
    costs = np.rint(lengths / resolution)
    cluster = np.arange(m) // k
    successor = cluster * k + (np.arange(m) % k + 1) % k        # next node on the target's cycle
    big = float(costs.max()) * n + 1.0                           # more than any whole tour
    weights = costs[successor] + big                             # leave from the cycle successor
    same = cluster[:, None] == cluster[None, :]
    weights[same] = 2.0 * big                                    # never inside a target ...
    weights[np.arange(m), successor] = 0.0                       # ... but along its cycle
    return weights.astype(np.int64)


def _decode(tour_nodes: list[int], k: int) -> tuple[np.ndarray, np.ndarray]:
    """Visiting order and the heading index of each visit from an ATSP tour: a target is
    visited at the node its cycle is entered by."""
    nodes = np.asarray(tour_nodes[:-1] if tour_nodes[0] == tour_nodes[-1] else tour_nodes)
    clusters = nodes // k
    entered = np.flatnonzero(clusters != np.roll(clusters, 1))
    if len(entered) == 0:
        entered = np.array([0])
    return clusters[entered], nodes[entered] % k


@dataclass
class AnchorResult:
    """The shortest anchor tour and every run's length (metres) or the reason it was skipped."""

    tour: Tour
    runs: dict[str, float | str] = field(default_factory=dict)
    time_s: float = 0.0


def anchor_tour(points_m: np.ndarray, rho_m: float, headings: tuple[int, ...] = DEFAULT_HEADINGS,
                max_nodes: int = DEFAULT_MAX_NODES, lkh_runs: int = 1) -> AnchorResult:
    """The best of the GTSP runs (one per K in ``headings``, cold) and the Euclidean-start runs
    (LKH's Euclidean order, headings by DP over each K); every tour checked."""
    elkai = require_elkai()
    points = np.asarray(points_m, dtype=float)
    n = len(points)
    started = time.perf_counter()
    runs: dict[str, float | str] = {}
    best: Tour | None = None

    def keep(name: str, order: np.ndarray, visit_headings: np.ndarray) -> None:
        nonlocal best
        tour = tour_through_poses(points, order, visit_headings, rho_m, "lkh-anchor",
                                  {"run": name})
        runs[name] = tour.length_m
        if best is None or tour.length_m < best.length_m:
            best = tour

    if n >= 3:
        euclid = np.rint(np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
                         / _RESOLUTION_M).astype(np.int64)
        order = np.asarray(elkai.DistanceMatrix(euclid.tolist()).solve_tsp(runs=lkh_runs)[:-1])
    else:
        order = np.arange(n)
    for k in headings:
        visit_headings = optimise_headings(points[order], rho_m, k)
        keep(f"euclidean+dp K={k}", order, visit_headings)
        if n * k > max_nodes:
            runs[f"gtsp K={k}"] = f"skipped: {n * k} nodes > {max_nodes}"
            continue
        if n < 2:
            continue
        grid = 2.0 * np.pi * np.arange(k) / k
        matrix = _gtsp_matrix(points, grid, rho_m)
        solution = elkai.DistanceMatrix(matrix.tolist()).solve_tsp(runs=lkh_runs)
        gtsp_order, choice = _decode(solution, k)
        if len(gtsp_order) != n or len(set(gtsp_order.tolist())) != n:
            runs[f"gtsp K={k}"] = "failed: LKH's tour left a target's cycle early"
            continue
        keep(f"gtsp K={k}", gtsp_order, grid[choice])
    assert best is not None
    return AnchorResult(best, runs, time.perf_counter() - started)


class AnchorPlanner(Planner):
    """The LKH-3 GTSP anchor as a planner peer (bench only: not registered for ``plan``).

    Parameters: ``headings`` (tuple of K), ``max_nodes``, ``lkh_runs``."""

    name = "lkh-anchor"
    description = "K-heading GTSP by Noon-Bean + LKH-3 (elkai), best of K = 8, 16, 32"

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        result = anchor_tour(targets_m, rho_m,
                             tuple(self.parameters.get("headings", DEFAULT_HEADINGS)),
                             int(self.parameters.get("max_nodes", DEFAULT_MAX_NODES)),
                             int(self.parameters.get("lkh_runs", 1)))
        tour = result.tour
        return Tour(tour.chain, tour.rho_m, tour.targets_m, tour.visit_s_m, self.name,
                    dict(self.parameters), {"runs": result.runs})


__all__ = ["AnchorPlanner", "AnchorResult", "anchor_tour"]
