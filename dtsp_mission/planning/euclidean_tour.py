"""A strong Euclidean TSP tour for up to millions of points, in seconds.

Construction: greedy edge matching over K-nearest-neighbour candidate edges, fragments chained
nearest end first.  Improvement: 2-opt and Or-opt (segments of 1 to 3 points, both orientations)
with the same candidate lists and a queue of "don't-look bits" (Bentley 1992), until no
improving move remains.  Every move is a composition of 2-opt exchanges applied to the cyclic
tour, reversing the shorter side.  Measured on uniform points: 4.5-4.9 % above the
Beardwood-Halton-Hammersley estimate 0.7124 sqrt(n A) at n = 1e4..1e5 (1e5 points in 0.7 s).
Deterministic: no randomness is used.
"""

from __future__ import annotations

import logging

import numba
import numpy as np
from scipy.spatial import cKDTree

_JIT = dict(cache=True, error_model="numpy")
log = logging.getLogger(__name__)


@numba.njit(inline="always", **_JIT)
def _d(points, a, b):
    dx = points[a, 0] - points[b, 0]
    dy = points[a, 1] - points[b, 1]
    return np.sqrt(dx * dx + dy * dy)


@numba.njit(**_JIT)
def reverse_section(tour, pos, i, j):
    """Reverse tour positions i..j (forward, cyclic), or the complement if it is shorter;
    either gives the same cyclic tour.  Returns the first position and the length of the
    section actually reversed."""
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
    return i, length


@numba.njit(**_JIT)
def _exchange(tour, pos, a, b, c, d):
    """Replace edges {a, b} and {c, d} by {a, c} and {b, d}, where the cycle runs a, b, ..., c, d
    in one of its two orientations."""
    n = tour.shape[0]
    if tour[(pos[a] + 1) % n] == b:
        reverse_section(tour, pos, pos[b], pos[c])
    else:
        reverse_section(tour, pos, pos[c], pos[b])


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


@numba.njit(**_JIT)
def _find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@numba.njit(**_JIT)
def _greedy(points, neighbours):
    """Greedy-edge tour: candidate edges (to K nearest neighbours) shortest first, kept when
    both ends have degree < 2 and no cycle closes; the fragments are then chained, each joined
    to the nearest free fragment end (a linear scan over the fragment ends)."""
    n, k = neighbours.shape
    count = n * k
    a = np.empty(count, dtype=np.int64)
    b = np.empty(count, dtype=np.int64)
    w = np.empty(count)
    for i in range(n):
        for j in range(k):
            a[i * k + j] = i
            b[i * k + j] = neighbours[i, j]
            w[i * k + j] = _d(points, i, neighbours[i, j])
    order = np.argsort(w, kind="mergesort")
    parent = np.arange(n)
    degree = np.zeros(n, dtype=np.int64)
    link = -np.ones((n, 2), dtype=np.int64)
    for e in order:
        u, v = a[e], b[e]
        if u == v or degree[u] >= 2 or degree[v] >= 2:
            continue
        ru, rv = _find(parent, u), _find(parent, v)
        if ru == rv:
            continue
        parent[ru] = rv
        link[u, degree[u]] = v
        link[v, degree[v]] = u
        degree[u] += 1
        degree[v] += 1
    # Chain the fragments: walk one to its end, then jump to the nearest unused fragment end.
    used = np.zeros(n, dtype=np.bool_)
    tour = np.empty(n, dtype=np.int64)
    ends = np.empty(n, dtype=np.int64)
    end_count = 0
    for i in range(n):
        if degree[i] < 2:
            ends[end_count] = i
            end_count += 1
    position = 0
    current = ends[0] if end_count > 0 else 0
    while True:
        previous = -1
        node = current
        while True:                       # walk the fragment
            used[node] = True
            tour[position] = node
            position += 1
            following = -1
            for t in range(degree[node]):
                if link[node, t] != previous and not used[link[node, t]]:
                    following = link[node, t]
            if following < 0:
                break
            previous, node = node, following
        if position >= n:
            break
        best, best_d = -1, np.inf
        for t in range(end_count):
            candidate = ends[t]
            if not used[candidate]:
                dist = _d(points, node, candidate)
                if dist < best_d:
                    best, best_d = candidate, dist
        current = best
    return tour


def tour_length(points_m: np.ndarray, order: np.ndarray) -> float:
    """Length of the closed polygon through the points in ``order``."""
    closed = points_m[np.append(order, order[0])]
    return float(np.hypot(*np.diff(closed, axis=0).T).sum())


def _construct_and_improve(points: np.ndarray, neighbour_count: int) -> tuple[np.ndarray, int]:
    """Greedy tour improved to a local optimum, and the move budget left."""
    neighbours = neighbour_lists(points, min(neighbour_count, len(points) - 1))
    return _improve(points, _greedy(points, neighbours), neighbours)


def euclidean_tour(points_m: np.ndarray, neighbour_count: int = 10) -> np.ndarray:
    """A closed Euclidean tour through all points, as an order of their indices."""
    points = np.ascontiguousarray(points_m, dtype=float).reshape(-1, 2)
    n = len(points)
    if n <= 3:
        return np.arange(n)
    tour, moves_left = _construct_and_improve(points, neighbour_count)
    if moves_left <= 0:
        log.warning("Euclidean tour: improvement stopped by its move budget (%d points)", n)
    return tour


def improvement_moves_left(points_m: np.ndarray, neighbour_count: int = 10) -> int:
    """How much of the improver's move budget is left after improving the greedy tour: a
    positive number means it stopped because no improving move remained (tests use this)."""
    points = np.ascontiguousarray(points_m, dtype=float).reshape(-1, 2)
    return int(_construct_and_improve(points, neighbour_count)[1])
