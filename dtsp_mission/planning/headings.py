"""Headings for a fixed visiting order: dynamic programming over discretised headings, then
continuous refinement.

For a closed visiting order ``p_0 ... p_{n-1}`` the tour length is the sum of shortest Dubins
lengths ``D((p_i, th_i), (p_{i+1}, th_{i+1}))``; only the headings are free.  Each target gets
``K`` candidate headings: the directions of its incoming and outgoing edges (so the
Alternating Algorithm's headings are among the candidates), the direction of the chord from its
predecessor to its successor (the heading of a vehicle flying straight through), and ``K - 3``
more evenly spaced around the circle from that one.  The cycle is solved exactly over those candidates by dynamic programming (every
start heading tried, ``n K^3`` additions on ``n K^2`` Dubins lengths from the kernel), then each
heading is refined on its own by golden-section search between its neighbours' fixed headings,
keeping a change only when it shortens the tour.  Deterministic; the result is never longer
than the best discrete solution, hence never longer than the Alternating Algorithm on the same
order.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..dubins import shortest_length
from ..dubins.kernel import solve_pair
from ..tour import Tour, tour_through_poses
from .alternating import alternating_headings
from .base import Planner
from .euclidean_tour import euclidean_tour
from .region import Region

_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@numba.njit(cache=True)
def _edge_costs(points: np.ndarray, candidates: np.ndarray, rho: float) -> np.ndarray:
    """costs[i, a, b]: Dubins length from point i with candidate heading a to point i+1
    (cyclically) with candidate heading b."""
    n, k = candidates.shape
    inv_rho = 1.0 / rho
    costs = np.empty((n, k, k))
    for i in range(n):
        j = (i + 1) % n
        for a in range(k):
            for b in range(k):
                _, t, p, q = solve_pair(points[i, 0], points[i, 1], candidates[i, a],
                                        points[j, 0], points[j, 1], candidates[j, b], inv_rho)
                costs[i, a, b] = (t + p + q) * rho
    return costs


@numba.njit(cache=True)
def _cycle(costs: np.ndarray, start: int, back: np.ndarray, keep: bool) -> float:
    """Length of the best cycle whose first heading is ``start``; fills ``back`` if ``keep``."""
    n, k, _ = costs.shape
    value = costs[0, start].copy()
    following = np.empty(k)
    for i in range(1, n - 1):
        for c in range(k):
            best, arg = np.inf, 0
            for b in range(k):
                v = value[b] + costs[i, b, c]
                if v < best:
                    best, arg = v, b
            following[c] = best
            if keep:
                back[i, c] = arg
        value[:] = following
    best, arg = np.inf, 0
    for b in range(k):
        v = value[b] + costs[n - 1, b, start]
        if v < best:
            best, arg = v, b
    if keep:
        back[n - 1, 0] = arg
    return best


@numba.njit(cache=True)
def _best_cycle(costs: np.ndarray) -> np.ndarray:
    """Candidate index per point of the shortest cycle over the candidate headings."""
    n, k, _ = costs.shape
    back = np.zeros((n, k), dtype=np.int64)
    best, start = np.inf, 0
    for a in range(k):
        v = _cycle(costs, a, back, False)
        if v < best:
            best, start = v, a
    _cycle(costs, start, back, True)
    choice = np.empty(n, dtype=np.int64)
    choice[0] = start
    if n > 1:
        choice[n - 1] = back[n - 1, 0]
        for i in range(n - 2, 0, -1):
            choice[i] = back[i, choice[i + 1]]
    return choice


@numba.njit(cache=True)
def _local_cost(points, headings, i, heading, inv_rho, rho):
    n = len(points)
    h, j = (i - 1) % n, (i + 1) % n
    _, t1, p1, q1 = solve_pair(points[h, 0], points[h, 1], headings[h],
                               points[i, 0], points[i, 1], heading, inv_rho)
    _, t2, p2, q2 = solve_pair(points[i, 0], points[i, 1], heading,
                               points[j, 0], points[j, 1], headings[j], inv_rho)
    return (t1 + p1 + q1 + t2 + p2 + q2) * rho


@numba.njit(cache=True)
def _refine(points: np.ndarray, headings: np.ndarray, rho: float, half_width: float,
            sweeps: int, iterations: int) -> None:
    """Golden-section search of each heading within +-half_width, in place, improving only."""
    n = len(points)
    inv_rho = 1.0 / rho
    for _ in range(sweeps):
        for i in range(n):
            current = _local_cost(points, headings, i, headings[i], inv_rho, rho)
            low, high = headings[i] - half_width, headings[i] + half_width
            x1 = high - _GOLDEN * (high - low)
            x2 = low + _GOLDEN * (high - low)
            f1 = _local_cost(points, headings, i, x1, inv_rho, rho)
            f2 = _local_cost(points, headings, i, x2, inv_rho, rho)
            for _ in range(iterations):
                if f1 < f2:
                    high, x2, f2 = x2, x1, f1
                    x1 = high - _GOLDEN * (high - low)
                    f1 = _local_cost(points, headings, i, x1, inv_rho, rho)
                else:
                    low, x1, f1 = x1, x2, f2
                    x2 = low + _GOLDEN * (high - low)
                    f2 = _local_cost(points, headings, i, x2, inv_rho, rho)
            best, value = (x1, f1) if f1 < f2 else (x2, f2)
            if value < current:
                headings[i] = best


def straight_through_headings(points_m: np.ndarray) -> np.ndarray:
    """Direction of the chord from each point's predecessor to its successor (closed order);
    the edge direction where that chord is empty."""
    chord = np.roll(points_m, -1, axis=0) - np.roll(points_m, 1, axis=0)
    edge = np.roll(points_m, -1, axis=0) - points_m
    use_edge = np.hypot(*chord.T) == 0
    chord[use_edge] = edge[use_edge]
    return np.arctan2(chord[:, 1], chord[:, 0])


def headings_over_candidates(points_m: np.ndarray, candidates_rad: np.ndarray, rho_m: float,
                             refine_half_width_rad: float, sweeps: int = 3) -> np.ndarray:
    """Headings at the points of a closed visiting order: the shortest cycle over the given
    candidates (row ``i`` of ``candidates_rad`` for point ``i``), exactly, then each heading
    refined within +-``refine_half_width_rad`` while that shortens the tour.  The result is
    never longer than the best choice among the candidates."""
    points = np.ascontiguousarray(points_m, dtype=float)
    candidates = np.ascontiguousarray(candidates_rad, dtype=float)
    choice = _best_cycle(_edge_costs(points, candidates, float(rho_m)))
    headings = candidates[np.arange(len(points)), choice].copy()
    _refine(points, headings, float(rho_m), float(refine_half_width_rad), sweeps, 24)
    return headings


def edge_directions(points_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Direction of the edge into and out of each point of a closed order (radians)."""
    outgoing = np.roll(points_m, -1, axis=0) - points_m
    outgoing = np.arctan2(outgoing[:, 1], outgoing[:, 0])
    return np.roll(outgoing, 1), outgoing


def optimise_headings(points_m: np.ndarray, rho_m: float, candidate_count: int = 16,
                      sweeps: int = 3) -> np.ndarray:
    """Headings (radians) at the points of a closed visiting order that make the tour of
    shortest Dubins paths short: exact over ``candidate_count`` candidates per point, then
    refined continuously (see the module docstring)."""
    points = np.ascontiguousarray(points_m, dtype=float)
    natural = straight_through_headings(points)
    if len(points) == 1:
        return natural
    incoming, outgoing = edge_directions(points)
    spread = candidate_count - 2
    offsets = 2.0 * np.pi * np.arange(spread) / spread
    candidates = np.column_stack([incoming, outgoing, natural[:, None] + offsets[None, :]])
    return headings_over_candidates(points, candidates, rho_m, np.pi / candidate_count, sweeps)


def leg_lengths_m(points_m: np.ndarray, headings_rad: np.ndarray, rho_m: float) -> np.ndarray:
    """Shortest Dubins length of each leg ``i -> i + 1`` of the closed tour through the poses."""
    poses = np.column_stack([points_m, headings_rad])
    return shortest_length(poses, np.roll(poses, -1, axis=0), rho_m)


def closed_length_m(points_m: np.ndarray, headings_rad: np.ndarray, rho_m: float) -> float:
    """Length of the closed tour of shortest Dubins paths through the given poses."""
    return float(leg_lengths_m(points_m, headings_rad, rho_m).sum())


class HeadingsPlanner(Planner):
    """A strong Euclidean tour, then the headings optimised for it (never longer than the
    Alternating Algorithm's headings on the same order, which are kept as a candidate).

    Parameters: ``candidates`` (K, default 16) headings per target in the exact stage.
    """

    name = "headings"
    description = "Euclidean order + heading optimisation (DP over K headings, then refined)"

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        order = euclidean_tour(targets_m)
        points = targets_m[order]
        optimised = optimise_headings(points, rho_m, int(self.parameters.get("candidates", 16)))
        alternating = alternating_headings(points)
        lengths = {"optimised": closed_length_m(points, optimised, rho_m),
                   "alternating": closed_length_m(points, alternating, rho_m)}
        headings = optimised if lengths["optimised"] <= lengths["alternating"] else alternating
        tour = tour_through_poses(targets_m, order, headings, rho_m, self.name, self.parameters)
        return Tour(tour.chain, tour.rho_m, tour.targets_m, tour.visit_s_m, tour.planner,
                    tour.parameters, {"heading_candidates_m": lengths})
