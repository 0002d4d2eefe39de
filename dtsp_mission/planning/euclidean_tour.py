"""A strong Euclidean TSP tour for up to millions of points, in seconds.

Construction: Hilbert space-filling-curve order.  Improvement: 2-opt and Or-opt (segments of 1
to 3 points, both orientations) with K-nearest-neighbour candidate lists and a queue of
"don't-look bits" (Bentley 1992), until no improving move remains.  Every move is a composition
of 2-opt exchanges applied to the cyclic tour, reversing the shorter side.  Typical quality is
about 5 % above optimal on uniform points (measured against the certified 1-tree bound in the
benchmarks).  The result is deterministic: no randomness is used.
"""

from __future__ import annotations

import logging

import numba
import numpy as np
from scipy.spatial import cKDTree

_JIT = dict(cache=True, error_model="numpy")
log = logging.getLogger(__name__)


def hilbert_order(points_m: np.ndarray, bits: int = 16) -> np.ndarray:
    """Indices of the points sorted along a Hilbert curve over their bounding box."""
    points = np.asarray(points_m, dtype=float)
    low = points.min(axis=0)
    span = max(float(np.ptp(points, axis=0).max()), 1e-300)
    side = 2 ** bits
    x = np.minimum(((points[:, 0] - low[0]) / span * side).astype(np.int64), side - 1)
    y = np.minimum(((points[:, 1] - low[1]) / span * side).astype(np.int64), side - 1)
    index = np.zeros(len(points), dtype=np.int64)
    s = side // 2
    while s > 0:
        rx = (x & s) > 0
        ry = (y & s) > 0
        index += s * s * ((3 * rx) ^ ry)
        flip = ~ry
        swap_x = np.where(flip & rx, side - 1 - x, x)
        swap_y = np.where(flip & rx, side - 1 - y, y)
        x, y = np.where(flip, swap_y, swap_x), np.where(flip, swap_x, swap_y)
        s //= 2
    return np.argsort(index, kind="stable")


@numba.njit(inline="always", **_JIT)
def _d(points, a, b):
    dx = points[a, 0] - points[b, 0]
    dy = points[a, 1] - points[b, 1]
    return np.sqrt(dx * dx + dy * dy)


@numba.njit(**_JIT)
def _reverse(tour, pos, i, j):
    """Reverse tour positions i..j (forward, cyclic), or the complement if it is shorter;
    either gives the same cyclic tour."""
    n = tour.shape[0]
    length = (j - i) % n + 1
    if 2 * length > n:
        i, j = (j + 1) % n, (i - 1) % n
        length = n - length
    for k in range(length // 2):
        p = (i + k) % n
        q = (j - k) % n
        a, b = tour[p], tour[q]
        tour[p], tour[q] = b, a
        pos[b], pos[a] = p, q


@numba.njit(**_JIT)
def _exchange(tour, pos, a, b, c, d):
    """Replace edges {a, b} and {c, d} by {a, c} and {b, d}, where the cycle runs a, b, ..., c, d
    in one of its two orientations."""
    n = tour.shape[0]
    if tour[(pos[a] + 1) % n] == b:
        _reverse(tour, pos, pos[b], pos[c])
    else:
        _reverse(tour, pos, pos[c], pos[b])


@numba.njit(**_JIT)
def _improve(points, tour, neighbours):
    n = tour.shape[0]
    pos = np.empty(n, dtype=np.int64)
    for i in range(n):
        pos[tour[i]] = i
    queue = np.empty(n, dtype=np.int64)
    queued = np.ones(n, dtype=np.bool_)
    for i in range(n):
        queue[i] = tour[i]
    head = 0
    count = n
    eps = 1e-10
    budget = 100 * n + 1000      # improving moves: a guarantee of termination (tests check
                                 # that it is never reached)
    while count > 0 and budget > 0:
        a = queue[head]
        head = (head + 1) % n
        count -= 1
        queued[a] = False
        touched = np.empty(8, dtype=np.int64)
        touched_count = 0
        # 2-opt, both directions around a.
        for direction in range(2):
            if touched_count:
                break
            b = tour[(pos[a] + 1) % n] if direction == 0 else tour[(pos[a] - 1) % n]
            d_ab = _d(points, a, b)
            for k in range(neighbours.shape[1]):
                c = neighbours[a, k]
                d_ac = _d(points, a, c)
                if d_ac >= d_ab:
                    break
                e = tour[(pos[c] + 1) % n] if direction == 0 else tour[(pos[c] - 1) % n]
                if c == a or c == b or e == a:
                    continue
                delta = d_ac + _d(points, b, e) - d_ab - _d(points, c, e)
                if delta < -eps:
                    _exchange(tour, pos, a, b, c, e)
                    touched[0], touched[1], touched[2], touched[3] = a, b, c, e
                    touched_count = 4
                    break
        # Or-opt: move the segment of 1..3 points starting at a elsewhere.
        if touched_count == 0 and n >= 8:
            for seg in range(1, 4):
                if touched_count:
                    break
                first = a
                last = tour[(pos[a] + seg - 1) % n]
                p = tour[(pos[first] - 1) % n]
                nx = tour[(pos[last] + 1) % n]
                gain = _d(points, p, first) + _d(points, last, nx) - _d(points, p, nx)
                if gain <= eps:
                    continue
                for end in range(2):
                    if touched_count:
                        break
                    near = first if end == 0 else last
                    for k in range(neighbours.shape[1]):
                        c = neighbours[near, k]
                        if _d(points, near, c) >= gain:
                            break
                        offset = (pos[c] - pos[first]) % n
                        if offset < seg or c == p:
                            continue               # c inside the segment, or no move
                        f = tour[(pos[c] + 1) % n]
                        if f == first or f == p:
                            continue               # inserting next to p: not this move
                        d_cf = _d(points, c, f)
                        reversed_cost = _d(points, c, last) + _d(points, first, f) - d_cf
                        forward_cost = _d(points, c, first) + _d(points, last, f) - d_cf
                        if min(reversed_cost, forward_cost) < gain - eps:
                            _exchange(tour, pos, p, first, c, f)        # p c ... nx last..first f
                            if c != nx:
                                _exchange(tour, pos, p, c, nx, last)    # p nx ... c last..first f
                            if forward_cost < reversed_cost:
                                _exchange(tour, pos, c, last, first, f)  # c first..last f
                            touched[0], touched[1], touched[2], touched[3] = p, first, last, nx
                            touched[4], touched[5] = c, f
                            touched_count = 6
                            break
        budget -= touched_count > 0
        for t in range(touched_count):
            city = touched[t]
            if not queued[city]:
                queued[city] = True
                queue[(head + count) % n] = city
                count += 1
    return tour, budget


def neighbour_lists(points_m: np.ndarray, k: int) -> np.ndarray:
    """The k nearest other points of every point, (n, k).  A point is removed from its own
    list explicitly: among duplicates the KD-tree need not list it first."""
    n = len(points_m)
    _, found = cKDTree(points_m).query(points_m, k=k + 1)
    not_self = found != np.arange(n)[:, None]
    first_others = np.argsort(~not_self, axis=1, kind="stable")
    return np.ascontiguousarray(np.take_along_axis(found, first_others, axis=1)[:, :k],
                                dtype=np.int64)


def tour_length(points_m: np.ndarray, order: np.ndarray) -> float:
    """Length of the closed polygon through the points in ``order``."""
    closed = points_m[np.append(order, order[0])]
    return float(np.hypot(*np.diff(closed, axis=0).T).sum())


def euclidean_tour(points_m: np.ndarray, neighbour_count: int = 10) -> np.ndarray:
    """A closed Euclidean tour through all points, as an order of their indices."""
    points = np.ascontiguousarray(points_m, dtype=float).reshape(-1, 2)
    n = len(points)
    if n <= 3:
        return np.arange(n)
    order = hilbert_order(points)
    k = min(neighbour_count, n - 1)
    neighbours = neighbour_lists(points, k)
    tour, moves_left = _improve(points, order.astype(np.int64), neighbours)
    if moves_left <= 0:
        log.warning("Euclidean tour: improvement stopped by its move budget (%d points)", n)
    return tour


def improvement_moves_left(points_m: np.ndarray, neighbour_count: int = 10) -> int:
    """How much of the improver's move budget is left after improving a Hilbert tour: a
    positive number means it stopped because no improving move remained (tests use this)."""
    points = np.ascontiguousarray(points_m, dtype=float).reshape(-1, 2)
    n = len(points)
    neighbours = neighbour_lists(points, min(neighbour_count, n - 1))
    return int(_improve(points, hilbert_order(points).astype(np.int64), neighbours)[1])
