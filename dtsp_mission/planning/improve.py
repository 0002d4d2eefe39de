"""Dubins-aware improvement of a closed tour: order and headings optimised together on exact
Dubins lengths.

The tour is a cyclic order of the targets with one heading per visit; its length is the sum of
the shortest Dubins lengths between consecutive visit poses.  Starting from any such tour the
improver returns one that is never longer, by an iterated local search:

* **moves** (on neighbour lists of the :func:`neighbour_count` nearest targets, with don't-look
  bits; a move whose new legs, as straight lines, already cost more than it could gain is not
  evaluated):
  a new heading for one visit (``HEADING_CANDIDATES`` around the circle, then golden-section
  refinement); 2-opt with heading flips (a section flown backwards with every heading turned
  by pi keeps the lengths of its inner legs, so only the two new legs are computed); Or-opt of
  sections of 1 to 3 visits, forwards or flipped, a single visit taking the best of the
  candidate headings at its new place;
* **heading re-optimisation** of the whole order between rounds: the exact shortest cycle over
  discrete candidate headings (the current ones among them) and continuous refinement
  (:func:`~dtsp_mission.planning.headings.headings_over_candidates`);
* **perturbation** at a random place, then local search from the visits it touched: a local
  double bridge (two short neighbouring sections swapped, the first perhaps flipped) or a short
  section moved next to a spatial neighbour with a random heading (``KICK_KIND`` 2, the
  default, takes either; a ruin-and-recreate kick, a visit and its neighbours removed and put
  back one by one at their cheapest places, is kind 3, and 4 mixes all three: measured no
  better within the seed-to-seed spread on dense and clustered sites).  The result is kept
  when the tour grows by less than ``ACCEPT_WORSE`` of a mean leg, undone otherwise; each
  round restarts from the best tour seen.

The work is counted in Dubins evaluations, not seconds: a limit of ``s`` seconds is a budget of
``s * EVALUATIONS_PER_SECOND`` evaluations (the rate of this code on one core of the reference
machine, ``benchmarks/improve_rate.py``) and the random choices come from ``seed``, so the same
input, limit and seed give the same tour on every machine; a slower machine takes longer for
it.  The search also ends when ``max(MIN_STALL_KICKS, STALL_KICKS_PER_TARGET * n)``
perturbations in a row shorten the best tour by less than ``PROGRESS``.

Measured (``docs/benchmarks.md``): on dense and clustered sites the peers loop at almost every
target and the improver removes most loops (the bundled 272-target site: 34.9 -> 24.2 km).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numba
import numpy as np

from ..dubins.kernel import solve_pair
from .euclidean_tour import _d as _eu          # straight distance: no Dubins path is shorter
from .euclidean_tour import neighbour_lists, reverse_section
from .headings import edge_directions, headings_over_candidates, straight_through_headings

_JIT = dict(cache=True, error_model="numpy")

#: Nearest targets whose tour edges are tried in 2-opt and Or-opt moves: ``NEIGHBOURS`` up to
#: ``NEIGHBOURS_FROM`` targets, ``NEIGHBOURS_PER_DECADE`` more per tenfold above, at most
#: ``MAX_NEIGHBOURS`` (see :func:`neighbour_count`).
NEIGHBOURS = 8
NEIGHBOURS_FROM = 1000
NEIGHBOURS_PER_DECADE = 40
MAX_NEIGHBOURS = 64
#: Headings tried for a visit before golden-section refinement.
HEADING_CANDIDATES = 12
#: Headings tried for a single visit at a new place (no refinement: heading moves follow).
INSERTION_CANDIDATES = 8
#: Dubins evaluations per second of the search on one core of the reference machine (measured
#: by ``benchmarks/improve_rate.py``); converts a time limit into a work budget.
EVALUATIONS_PER_SECOND = 6_500_000
#: Perturbations in a row that bring no progress before the search ends early (per target,
#: and at least).
STALL_KICKS_PER_TARGET = 50
MIN_STALL_KICKS = 2000
#: A new best shorter by less than this fraction is kept but does not count as progress.
PROGRESS = 1e-5
#: A perturbation is kept when the tour grows by less than this fraction of a mean leg.
ACCEPT_WORSE = 0.05
#: Perturbation: 0 swaps two neighbouring sections, 1 moves a short section next to a spatial
#: neighbour with a random heading, 2 either at random, 3 ruin and recreate, 4 any of 1-3.
KICK_KIND = 2
#: Longest section a perturbation moves.
KICK_SECTION = 30
#: The final heading pass over the best tour: candidates around the circle (30: the set of the
#: headings planner's K = 32), refinement sweeps, and up to how many targets the fine grid is
#: used.
POLISH_GRID = 30
POLISH_SWEEPS = 8
POLISH_UP_TO = 5000
#: A heading move must gain this much (radii); finer tuning is left to the whole-order pass.
HEADING_MIN_GAIN = 1e-2
_EPS = 1e-9          # improvements smaller than this (in radii) are not moves
_PI = math.pi
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@numba.njit(inline="always", **_JIT)
def _wrap(angle):
    """Angle in [-pi, pi)."""
    return angle - 2.0 * _PI * math.floor((angle + _PI) / (2.0 * _PI))


@numba.njit(**_JIT)                 # not inlined: the solver is large and called from many places
def _dist(pts, a, ha, b, hb, count):
    """Shortest Dubins length (radii) from target a with heading ha to target b with hb."""
    count[0] += 1
    _, t, p, q = solve_pair(pts[a, 0], pts[a, 1], ha, pts[b, 0], pts[b, 1], hb, 1.0)
    return t + p + q


@numba.njit(inline="always", **_JIT)
def _succ(tour, pos, a):
    return tour[(pos[a] + 1) % tour.shape[0]]


@numba.njit(inline="always", **_JIT)
def _pred(tour, pos, a):
    return tour[(pos[a] - 1) % tour.shape[0]]


@numba.njit(**_JIT)
def _leg(pts, tour, pos, hd, a, count):
    b = _succ(tour, pos, a)
    return _dist(pts, a, hd[a], b, hd[b], count)


@numba.njit(**_JIT)
def tour_length_rho(pts, tour, hd, count):
    """Closed length (radii) of the tour through the poses."""
    n = tour.shape[0]
    total = 0.0
    for i in range(n):
        a, b = tour[i], tour[(i + 1) % n]
        total += _dist(pts, a, hd[a], b, hd[b], count)
    return total


@numba.njit(**_JIT)
def _reverse(tour, pos, hd, i, j):
    """Reverse positions i..j (forward, cyclic) with every heading there turned by pi, or the
    rest of the tour likewise if it is shorter: both give tours of the same legs."""
    n = tour.shape[0]
    start, length = reverse_section(tour, pos, i, j)
    for k in range(length):
        c = tour[(start + k) % n]
        hd[c] = _wrap(hd[c] + _PI)


@numba.njit(**_JIT)
def _move_section(tour, pos, hd, i, length, c, flip):
    """Move the section at positions i..i+length-1 between c and its successor (c outside the
    section), flipped (reversed, headings turned by pi) if ``flip``; the travel direction of
    the rest of the tour is kept."""
    n = tour.shape[0]
    section = np.empty(length, dtype=np.int64)
    for k in range(length):
        section[k] = tour[(i + k) % n]
    if flip:
        section = section[::-1].copy()
        for k in range(length):
            hd[section[k]] = _wrap(hd[section[k]] + _PI)
    after = (pos[c] - (i + length - 1)) % n           # visits from the section's end to c
    before = (i - 1 - pos[c]) % n                     # visits from c's successor to the section
    if after <= before:
        for k in range(after):
            src = (i + length + k) % n
            dst = (i + k) % n
            tour[dst] = tour[src]
            pos[tour[dst]] = dst
        start = (i + after) % n
    else:
        first = (pos[c] + 1) % n
        for k in range(before - 1, -1, -1):
            src = (first + k) % n
            dst = (first + k + length) % n
            tour[dst] = tour[src]
            pos[tour[dst]] = dst
        start = first
    for k in range(length):
        p = (start + k) % n
        tour[p] = section[k]
        pos[section[k]] = p


@numba.njit(**_JIT)
def _best_heading(pts, hd, p, a, s, count, candidates, refine):
    """The heading of a between fixed neighbours p and s that minimises the two legs, over
    ``candidates`` directions and golden-section refinement; (heading, cost)."""
    hp, hs = hd[p], hd[s]
    dx, dy = pts[s, 0] - pts[p, 0], pts[s, 1] - pts[p, 1]
    base = math.atan2(dy, dx) if dx * dx + dy * dy > 0.0 else hd[a]
    best_h = hd[a]
    best = _dist(pts, p, hp, a, best_h, count) + _dist(pts, a, best_h, s, hs, count)
    step = 2.0 * _PI / candidates
    for k in range(candidates):
        h = _wrap(base + k * step)
        v = _dist(pts, p, hp, a, h, count) + _dist(pts, a, h, s, hs, count)
        if v < best:
            best, best_h = v, h
    if not refine:
        return best_h, best
    low, high = best_h - 0.5 * step, best_h + 0.5 * step
    x1 = high - _GOLDEN * (high - low)
    x2 = low + _GOLDEN * (high - low)
    f1 = _dist(pts, p, hp, a, x1, count) + _dist(pts, a, x1, s, hs, count)
    f2 = _dist(pts, p, hp, a, x2, count) + _dist(pts, a, x2, s, hs, count)
    for _ in range(16):
        if f1 < f2:
            high, x2, f2 = x2, x1, f1
            x1 = high - _GOLDEN * (high - low)
            f1 = _dist(pts, p, hp, a, x1, count) + _dist(pts, a, x1, s, hs, count)
        else:
            low, x1, f1 = x1, x2, f2
            x2 = low + _GOLDEN * (high - low)
            f2 = _dist(pts, p, hp, a, x2, count) + _dist(pts, a, x2, s, hs, count)
    if f1 < best:
        best, best_h = f1, _wrap(x1)
    if f2 < best:
        best, best_h = f2, _wrap(x2)
    return best_h, best


@numba.njit(**_JIT)
def _try_heading(pts, tour, pos, hd, a, count, touched, min_gain):
    """A better heading for a between its neighbours; the gain (radii), 0 if none."""
    p, s = _pred(tour, pos, a), _succ(tour, pos, a)
    current = _dist(pts, p, hd[p], a, hd[a], count) + _dist(pts, a, hd[a], s, hd[s], count)
    if current - _eu(pts, p, a) - _eu(pts, a, s) < min_gain:
        return 0.0, 0                     # already within min_gain of the straight lines
    h, value = _best_heading(pts, hd, p, a, s, count, HEADING_CANDIDATES, True)
    if value < current - min_gain:
        hd[a] = h
        touched[0], touched[1], touched[2] = p, a, s
        return current - value, 3
    return 0.0, 0


@numba.njit(**_JIT)
def _try_two_opt(pts, tour, pos, hd, nbr, a, count, touched):
    """The best improving 2-opt move that makes a and one of its neighbours adjacent."""
    best, best_c, best_dir = _EPS, -1, 0
    for direction in range(2):
        b = _succ(tour, pos, a) if direction == 0 else _pred(tour, pos, a)
        d_ab = _dist(pts, a, hd[a], b, hd[b], count) if direction == 0 else \
            _dist(pts, b, hd[b], a, hd[a], count)
        for k in range(nbr.shape[1]):
            c = nbr[a, k]
            if c == a or c == b:
                continue
            e = _succ(tour, pos, c) if direction == 0 else _pred(tour, pos, c)
            if e == a or e == b:
                continue
            # The new legs are no shorter than straight lines: skip moves that cannot gain.
            if direction == 0:      # a b ... c e  ->  a c' ... b' e
                d_ce = _dist(pts, c, hd[c], e, hd[e], count)
                if d_ab + d_ce - _eu(pts, a, c) - _eu(pts, b, e) <= best:
                    continue
                delta = (_dist(pts, a, hd[a], c, hd[c] + _PI, count)
                         + _dist(pts, b, hd[b] + _PI, e, hd[e], count) - d_ab - d_ce)
            else:                   # e c ... b a  ->  e b' ... c' a
                d_ec = _dist(pts, e, hd[e], c, hd[c], count)
                if d_ab + d_ec - _eu(pts, e, b) - _eu(pts, c, a) <= best:
                    continue
                delta = (_dist(pts, e, hd[e], b, hd[b] + _PI, count)
                         + _dist(pts, c, hd[c] + _PI, a, hd[a], count) - d_ab - d_ec)
            if -delta > best:
                best, best_c, best_dir = -delta, c, direction
    if best_c < 0:
        return 0.0, 0
    c = best_c
    if best_dir == 0:
        b, e = _succ(tour, pos, a), _succ(tour, pos, c)
        _reverse(tour, pos, hd, pos[b], pos[c])
    else:
        b, e = _pred(tour, pos, a), _pred(tour, pos, c)
        _reverse(tour, pos, hd, pos[c], pos[b])
    touched[0], touched[1], touched[2], touched[3] = a, b, c, e
    return best, 4


@numba.njit(**_JIT)
def _try_or_opt(pts, tour, pos, hd, nbr, a, count, touched):
    """The best improving move of the section of 1..3 visits starting at a to an edge next to
    one of its ends' neighbours, forwards or flipped (a single visit: with its best heading)."""
    n = tour.shape[0]
    best, best_len, best_c, best_flip, best_h = _EPS, 0, -1, False, 0.0
    for length in range(1, 4):
        if n < length + 3:
            break
        i = pos[a]
        first, last = a, tour[(i + length - 1) % n]
        p, nx = _pred(tour, pos, first), _succ(tour, pos, last)
        gain = (_dist(pts, p, hd[p], first, hd[first], count)
                + _dist(pts, last, hd[last], nx, hd[nx], count)
                - _dist(pts, p, hd[p], nx, hd[nx], count))
        if gain <= best:
            continue
        for end in range(1 if length == 1 else 2):
            near = first if end == 0 else last
            for k in range(nbr.shape[1]):
                for side in range(2):
                    c = nbr[near, k]
                    if side == 1:
                        c = _pred(tour, pos, c)
                    if (pos[c] - i) % n < length or c == p:
                        continue                 # inside the section, or its own place
                    d = _succ(tour, pos, c)
                    d_cd = _dist(pts, c, hd[c], d, hd[d], count)
                    room = d_cd + gain - best          # a move must add less than this
                    if length == 1:
                        if _eu(pts, c, a) + _eu(pts, a, d) >= room:
                            continue
                        h, value = _best_heading(pts, hd, c, a, d, count, INSERTION_CANDIDATES, False)
                        delta = value - d_cd - gain
                        if -delta > best:
                            best, best_len, best_c, best_flip, best_h = -delta, 1, c, False, h
                        continue
                    if _eu(pts, c, first) + _eu(pts, last, d) < room:
                        forward = (_dist(pts, c, hd[c], first, hd[first], count)
                                   + _dist(pts, last, hd[last], d, hd[d], count) - d_cd - gain)
                        if -forward > best:
                            best, best_len, best_c, best_flip = -forward, length, c, False
                            room = d_cd + gain - best
                    if _eu(pts, c, last) + _eu(pts, first, d) < room:
                        flipped = (_dist(pts, c, hd[c], last, hd[last] + _PI, count)
                                   + _dist(pts, first, hd[first] + _PI, d, hd[d], count) - d_cd - gain)
                        if -flipped > best:
                            best, best_len, best_c, best_flip = -flipped, length, c, True
    if best_c < 0:
        return 0.0, 0
    i = pos[a]
    first, last = a, tour[(i + best_len - 1) % n]
    p, nx = _pred(tour, pos, first), _succ(tour, pos, last)
    d = _succ(tour, pos, best_c)
    if best_len == 1:
        hd[a] = best_h
    _move_section(tour, pos, hd, i, best_len, best_c, best_flip)
    touched[0], touched[1], touched[2], touched[3] = p, nx, first, last
    touched[4], touched[5] = best_c, d
    return best, 6


@numba.njit(**_JIT)
def _descend(pts, tour, pos, hd, nbr, queue, queued, count, budget):
    """Local search from the visits in the queue (and those its moves touch) until no move
    improves or the budget is spent; the total gain (radii)."""
    n = tour.shape[0]
    touched = np.empty(8, dtype=np.int64)
    head, size, total = 0, 0, 0.0
    for i in range(n):
        if queued[i]:
            queue[size] = i
            size += 1
    while size > 0 and count[0] < budget:
        a = queue[head]
        head = (head + 1) % n
        size -= 1
        queued[a] = False
        count[1] += 1
        gain, m = _try_two_opt(pts, tour, pos, hd, nbr, a, count, touched)
        if m == 0:
            gain, m = _try_or_opt(pts, tour, pos, hd, nbr, a, count, touched)
        if m == 0:
            gain, m = _try_heading(pts, tour, pos, hd, a, count, touched, HEADING_MIN_GAIN)
        total += gain
        count[2] += m > 0
        for t in range(m):
            city = touched[t]
            if not queued[city]:
                queued[city] = True
                queue[(head + size) % n] = city
                size += 1
    for i in range(n):
        queued[i] = False
    return total


@numba.njit(**_JIT)
def _ruin_recreate(pts, tour, pos, hd, nbr, a, m, count, queued):
    """Remove a and its m - 1 nearest neighbours from the tour and put each back, in random
    order, at its cheapest place next to one of its neighbours with its best heading (any edge
    where none is in the tour); marks the visits touched in ``queued``.  Returns the exact
    change of length (radii)."""
    n = tour.shape[0]
    removed = np.zeros(n, dtype=np.bool_)
    members = np.empty(m, dtype=np.int64)
    members[0] = a
    for k in range(m - 1):
        members[k + 1] = nbr[a, k]
    for k in range(m):
        removed[members[k]] = True
    # Legs that disappear: out of every removed visit and out of each kept visit before one.
    delta = 0.0
    for i in range(n):
        v, w = tour[i], tour[(i + 1) % n]
        if removed[v] or removed[w]:
            delta -= _dist(pts, v, hd[v], w, hd[w], count)
    rest = np.empty(n, dtype=np.int64)
    size = 0
    for i in range(n):
        if not removed[tour[i]]:
            rest[size] = tour[i]
            size += 1
    for i in range(size):
        v = rest[i]
        if removed[tour[(pos[v] + 1) % n]]:
            w = rest[(i + 1) % size]
            delta += _dist(pts, v, hd[v], w, hd[w], count)
            queued[v] = True
    where = np.full(n, -1, dtype=np.int64)
    for i in range(size):
        where[rest[i]] = i
    order = np.random.permutation(m)
    for k in range(m):
        v = members[order[k]]
        best, best_i, best_h = np.inf, -1, 0.0
        for t in range(nbr.shape[1] + size):
            if t < nbr.shape[1]:
                c = nbr[v, t]
                if where[c] < 0:
                    continue
                sites = 2
            else:
                if best_i >= 0:
                    break                       # a neighbour's edge was found
                c = rest[t - nbr.shape[1]]      # no neighbour in the tour: every edge
                sites = 1
            for side in range(sites):
                i = where[c] if side == 0 else (where[c] - 1) % size
                u, w = rest[i], rest[(i + 1) % size]
                h, value = _best_heading(pts, hd, u, v, w, count, INSERTION_CANDIDATES, False)
                value -= _dist(pts, u, hd[u], w, hd[w], count)
                if value < best:
                    best, best_i, best_h = value, i, h
        hd[v] = best_h
        delta += best
        for j in range(size, best_i + 1, -1):   # insert after position best_i
            rest[j] = rest[j - 1]
            where[rest[j]] = j
        rest[best_i + 1] = v
        where[v] = best_i + 1
        size += 1
        queued[v] = True
        queued[rest[best_i]] = True
        queued[rest[(best_i + 2) % size]] = True
    for i in range(n):
        tour[i] = rest[i]
        pos[rest[i]] = i
    return delta


@numba.njit(**_JIT)
def _search(pts, tour, hd, nbr, seed, kicks, stall_limit, count, budget, current, best_tour,
            best_hd, best, state, section, threshold, kind):
    """Up to ``kicks`` perturbations, each followed by local search and kept when the tour
    grows by less than ``threshold`` (radii), undone otherwise; the shortest tour seen is kept
    in ``best_tour``, ``best_hd`` (length ``best[0]``).  ``state[0]`` counts the kicks since
    the best last improved, across calls.  Returns the current tour's length."""
    n = tour.shape[0]
    np.random.seed(seed)
    pos = np.empty(n, dtype=np.int64)
    for i in range(n):
        pos[tour[i]] = i
    queue = np.empty(n, dtype=np.int64)
    queued = np.zeros(n, dtype=np.bool_)
    saved_tour = tour.copy()
    saved_hd = hd.copy()
    longest = max(1, min(section, n // 4))
    for _ in range(kicks):
        if count[0] >= budget or state[0] >= stall_limit:
            break
        choice = kind if kind < 4 else np.random.randint(3) + 1
        if choice == 3 and n > 6:
            m = 2 + np.random.randint(min(nbr.shape[1], n - 4))
            candidate = current + _ruin_recreate(pts, tour, pos, hd, nbr, np.random.randint(n), m,
                                                 count, queued)
            candidate -= _descend(pts, tour, pos, hd, nbr, queue, queued, count, budget)
        else:
            if choice == 0 or (choice == 2 and np.random.randint(2) == 0):
                l1 = 1 + np.random.randint(longest)
                l2 = 1 + np.random.randint(longest)
                if l1 + l2 + 2 > n:
                    continue
                i = np.random.randint(n)
                x = tour[i]
                s1 = tour[(i + 1) % n]
                e1 = tour[(i + l1) % n]
                s2 = tour[(i + l1 + 1) % n]
                e2 = tour[(i + l1 + l2) % n]
                y = tour[(i + l1 + l2 + 1) % n]
                before = (_dist(pts, x, hd[x], s1, hd[s1], count)
                          + _dist(pts, e1, hd[e1], s2, hd[s2], count)
                          + _dist(pts, e2, hd[e2], y, hd[y], count))
                # x S1 S2 y -> x S2 S1 y, S1 flipped half of the time.
                flip = np.random.randint(2) == 1
                _move_section(tour, pos, hd, (i + 1) % n, l1, e2, flip)
                # The three new joints: out of x, out of S2's last visit, into y.
                z = _pred(tour, pos, y)
                joint = (_leg(pts, tour, pos, hd, x, count) + _leg(pts, tour, pos, hd, e2, count)
                         + _leg(pts, tour, pos, hd, z, count))
            else:
                # A short section moved next to a spatial neighbour, maybe flipped, its first
                # visit given a random heading.
                length = 1 + np.random.randint(3)
                a = np.random.randint(n)
                i = pos[a]
                c = nbr[a, np.random.randint(nbr.shape[1])]
                if (pos[c] - i) % n < length or n < length + 3:
                    continue
                x = _pred(tour, pos, a)
                s1 = a
                e1 = tour[(i + length - 1) % n]
                y = _succ(tour, pos, e1)
                s2 = c
                e2 = _succ(tour, pos, c)
                if x == c:
                    continue
                before = (_dist(pts, x, hd[x], s1, hd[s1], count)
                          + _dist(pts, e1, hd[e1], y, hd[y], count)
                          + _dist(pts, s2, hd[s2], e2, hd[e2], count))
                _move_section(tour, pos, hd, i, length, c, np.random.randint(2) == 1)
                joint = (_leg(pts, tour, pos, hd, x, count) + _leg(pts, tour, pos, hd, c, count)
                         + _leg(pts, tour, pos, hd, _pred(tour, pos, e2), count))
                # Then the random heading: its two legs before and after.
                p = _pred(tour, pos, a)
                before += _leg(pts, tour, pos, hd, p, count) + _leg(pts, tour, pos, hd, a, count)
                hd[a] = _wrap(2.0 * _PI * np.random.random())
                joint += _leg(pts, tour, pos, hd, p, count) + _leg(pts, tour, pos, hd, a, count)
            candidate = current - before + joint
            for z in (x, s1, e1, s2, e2, y):
                queued[z] = True
            candidate -= _descend(pts, tour, pos, hd, nbr, queue, queued, count, budget)
        state[0] += 1
        state[1] += 1
        if candidate < current + threshold:
            current = candidate
            saved_tour[:] = tour
            saved_hd[:] = hd
            if current < best[0] - _EPS:
                if current < best[0] * (1.0 - PROGRESS):
                    state[0] = 0
                best[0] = current
                best_tour[:] = tour
                best_hd[:] = hd
        else:
            tour[:] = saved_tour
            hd[:] = saved_hd
            for k in range(n):
                pos[tour[k]] = k
    return current


@dataclass(frozen=True)
class Improvement:
    """What the improver did: lengths before and after (metres), the work it spent."""

    order: np.ndarray
    headings_rad: np.ndarray
    start_m: float
    length_m: float
    evaluations: int
    budget: int
    stopped: str          # "converged" (stalled), "budget" or "too few targets"
    kicks: int = 0
    examined: int = 0
    moves: int = 0


def neighbour_count(n: int) -> int:
    """Neighbours per target the moves try for a tour of ``n`` targets.

    Measured (uniform 5 km square, rho 100 m, default budget): 8 is the best or level with the
    best up to 1,000 targets and on the dense, clustered and bundled sites of 100-420; above,
    the lanes the tours start from are narrow and the place a looping target fits is beyond
    the nearest eight (n = 1e4: 1.99 x the lower bound with 8, 1.59 with 48; n = 1e5, 30 s:
    2.41 with 32, 2.25 with 48, 2.18 with 64).
    """
    if n <= NEIGHBOURS_FROM:
        return NEIGHBOURS
    extra = NEIGHBOURS_PER_DECADE * math.log10(n / NEIGHBOURS_FROM)
    return int(min(MAX_NEIGHBOURS, round(NEIGHBOURS + extra)))


def _optimise_headings(pts: np.ndarray, tour: np.ndarray, hd: np.ndarray, grid: int = 12,
                       sweeps: int = 3, keep_current: bool = True) -> np.ndarray:
    """Headings (by target) over the visiting order ``tour``: exact over ``grid`` + 2 discrete
    candidates (and the current ones if ``keep_current``: then never longer than them), then
    refined in ``sweeps``."""
    points = pts[tour]
    incoming, outgoing = edge_directions(points)
    natural = straight_through_headings(points)
    offsets = 2.0 * np.pi * np.arange(grid) / grid
    candidates = np.column_stack([incoming, outgoing, natural[:, None] + offsets[None, :]])
    if keep_current:
        candidates = np.column_stack([hd[tour], candidates])
    headings = headings_over_candidates(points, candidates, 1.0, np.pi / grid, sweeps)
    result = hd.copy()
    result[tour] = np.array([_wrap(h) for h in headings])
    return result


def improve_tour(points_m: np.ndarray, order: np.ndarray, headings_rad: np.ndarray,
                 rho_m: float, time_limit_s: float = 10.0, seed: int = 0,
                 progress: Callable[[float], None] | None = None) -> Improvement:
    """A tour through the same points never longer than the given one (visit ``order[k]``
    with heading ``headings_rad[k]``), found within a work budget of ``time_limit_s`` seconds
    at the reference rate (see the module docstring); deterministic for given ``seed``.
    ``progress`` is called with the fraction of the budget spent."""
    points = np.ascontiguousarray(points_m, dtype=float) / rho_m
    n = len(points)
    tour = np.ascontiguousarray(order, dtype=np.int64).copy()
    hd = np.empty(n)
    hd[tour] = np.asarray(headings_rad, dtype=float)
    hd = np.array([_wrap(h) for h in hd])
    count = np.zeros(3, dtype=np.int64)      # Dubins evaluations, visits examined, moves made
    start = tour_length_rho(points, tour, hd, count)
    budget = int(max(time_limit_s, 0.0) * EVALUATIONS_PER_SECOND)
    if n < 4 or budget <= 0:
        return Improvement(tour, hd[tour], start * rho_m, start * rho_m, int(count[0]), budget,
                           "too few targets" if n < 4 else "budget")
    nbr = neighbour_lists(points, min(neighbour_count(n), n - 1))
    best_tour, best_hd = tour.copy(), hd.copy()
    best = np.array([start])
    state = np.zeros(2, dtype=np.int64)       # kicks since the best improved, kicks in all
    stall_limit = max(MIN_STALL_KICKS, STALL_KICKS_PER_TARGET * n)
    round_index = 0
    while count[0] < budget and state[0] < stall_limit:
        # Local search to a local optimum, then the headings of the whole order re-optimised.
        pos = np.empty(n, dtype=np.int64)
        pos[tour] = np.arange(n)
        _descend(points, tour, pos, hd, nbr, np.empty(n, dtype=np.int64), np.ones(n, dtype=np.bool_),
                 count, budget)
        hd = _optimise_headings(points, tour, hd)
        count[0] += n * 17 * 17
        current = tour_length_rho(points, tour, hd, count)
        if current < best[0] - _EPS:
            if current < best[0] * (1.0 - PROGRESS):
                state[0] = 0
            best_tour[:], best_hd[:], best[0] = tour, hd, current
        # Perturbations: a round is a few hundred kicks.
        threshold = ACCEPT_WORSE * current / n
        _search(points, tour, hd, nbr, seed * 1_000_003 + round_index, 200 + n, stall_limit,
                count, budget, current, best_tour, best_hd, best, state, KICK_SECTION, threshold, KICK_KIND)
        round_index += 1
        if progress is not None:
            progress(min(1.0, count[0] / budget))
        tour, hd = best_tour.copy(), best_hd.copy()      # the next round starts from the best
    # A last, finer pass over the headings of the best order (its cost is not budgeted: about
    # 4 n 33**2 evaluations, a few percent of a budget; one pass on the coarse grid above
    # POLISH_UP_TO targets).  The current headings are a local optimum of the refinement: a
    # fresh start from the grid alone (the headings planner's candidates) sometimes lands in a
    # better one, and so does the same tour flown the other way (every heading turned by pi).
    fine = n <= POLISH_UP_TO
    grid = POLISH_GRID if fine else 12
    for keep_current in (True, False) if fine else (True,):
        for backwards in (False, True) if fine else (False,):
            order_used = best_tour[::-1].copy() if backwards else best_tour
            turned = np.array([_wrap(h + np.pi) for h in best_hd]) if backwards else best_hd
            polished = _optimise_headings(points, order_used, turned, grid, POLISH_SWEEPS,
                                          keep_current)
            if backwards:
                polished = np.array([_wrap(h + np.pi) for h in polished])
            length = tour_length_rho(points, best_tour, polished, count)
            if length < best[0]:
                best_hd, best[0] = polished, length
    stopped = "budget" if count[0] >= budget else "converged"
    return Improvement(best_tour, best_hd[best_tour], start * rho_m, float(best[0]) * rho_m,
                       int(count[0]), budget, stopped, int(state[1]),
                       int(count[1]), int(count[2]))
