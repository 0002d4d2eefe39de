"""Tours for a steady wind: Dubins paths in the air mass, timed over the ground.

In a steady wind ``w`` an aircraft at airspeed ``V`` with turn radius ``rho`` flies Dubins paths
*in the air mass*; over the ground its path is that air path carried along by the wind
(trochoids where it turns).  A leg from target ``p`` (air heading ``a``) to target ``q`` (air
heading ``b``) that takes ``T`` seconds is the shortest Dubins path in the air mass from ``p`` to
where ``q`` is in the air mass after ``T`` seconds, ``q - w T``, and it must take exactly ``T``:
``L(T) = V T`` with ``L(T)`` the Dubins length to ``(q - w T, b)``.  That depends only on the
displacement ``q - p`` and the two headings -- not on when the leg starts -- so a tour in wind
is a tour over a time cost, asymmetric (upwind is slower than downwind), on the same targets
and orders as in calm air (McGee and Hedrick's virtual target, Techy and Woolsey's trochoids).

A leg's time is the *earliest* ``T`` with ``L(T) = V T``, but for arrivals possible only within
a window shorter than ``_MAX_STEP_RHO * rho / V`` behind a downward jump of the Dubins length
(the wind carrying the target across the heading line, say); see ``_leg_time``.  Where the
length jumps at the time found, the shortest path would arrive early; such a pair of headings is
not used (its cost is infinite), so every leg kept arrives over its target to within a
micrometre-scale tolerance, which :meth:`WindTour.check` verifies with the tours' own checker on
the chain in the air mass.

:func:`plan_wind_tour` starts from a given order (the calm planner's, or its reverse when that
is faster), chooses the air headings at the targets for the least flight time (exact dynamic
programming over candidate headings, as :mod:`.headings` does for length in calm air, then each
refined continuously), and improves the order on flight time (Or-opt moves; 2-opt's reversals
would turn every heading of a run round in an asymmetric cost).  In calm air its times are the
Dubins lengths over the airspeed, and with the calm tour's headings given, at most the calm tour's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from ..dubins import shortest_path
from ..dubins.kernel import solve_pair
from ..errors import InputError
from ..segments import SegmentChain, wrap_angle
from ..tour.check import TOLERANCE_RHO, CheckReport, check_path
from .headings import _best_cycle, edge_directions, straight_through_headings


#: A leg whose shortest path would pass its target more than this (times rho) off is not used.
_LEG_TOLERANCE_RHO = 1e-9
#: The search for a leg's time steps at most this many rho of flight: an arrival possible only
#: for a shorter time (behind a jump of the Dubins length) may be passed over.
_MAX_STEP_RHO = 0.25
#: An arrival where the Dubins length falls by more than this (times rho) at once is refused.
_JUMP_RHO = 1e-6


@numba.njit(cache=True)
def _air_length(x0: float, y0: float, th0: float, x1: float, y1: float, th1: float,
                rho: float) -> float:
    _, t, p, q = solve_pair(x0, y0, th0, x1, y1, th1, 1.0 / rho)
    return (t + p + q) * rho


@numba.njit(cache=True)
def _leg_time(x0: float, y0: float, th0: float, x1: float, y1: float, th1: float, rho: float,
              v: float, wx: float, wy: float, tolerance_m: float) -> float:
    """Earliest arrival time (s) of the leg in the wind: the shortest path in the air mass to
    where the target is after that time takes that time, to within ``tolerance_m`` over the
    ground; inf if no such time is found (a jump of the Dubins length makes it early)."""
    if wx == 0.0 and wy == 0.0:
        return _air_length(x0, y0, th0, x1, y1, th1, rho) / v
    w = math.sqrt(wx * wx + wy * wy)
    dx, dy = x1 - x0, y1 - y0
    # No arrival before the straight-line time (|d - w T| = v T), and the slack
    # g(T) = L(T) - v T falls at most at v + w where the length is continuous: steps of
    # g / (v + w) from there pass no arrival but one behind a downward jump of the length, and
    # steps of at most _MAX_STEP_RHO rho / v none of those that stays open that long.
    along, a = dx * wx + dy * wy, v * v - w * w
    t = (-along + math.sqrt(along * along + a * (dx * dx + dy * dy))) / a
    previous, g_previous = t, 0.0       # nothing is shorter than the straight line
    for _ in range(100000):
        length = _air_length(x0, y0, th0, x1 - wx * t, y1 - wy * t, th1, rho)
        g = length - v * t
        if g >= 0.0 and w * g / v <= tolerance_m:
            return length / v           # a hair late: over the target within the tolerance
        if g < 0.0:
            break
        previous, g_previous = t, g
        t += min(g / (v + w), _MAX_STEP_RHO * rho / v)
    else:
        return np.inf
    # Behind a jump: the first time in (previous, t] the path is not late, if it is on time
    # and the length is continuous there (an arrival only at the instant of a jump exists
    # only to the last bits of the goal: the word found there depends on rounding).
    lo, hi, g_lo, g_hi = previous, t, g_previous, g
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        g_mid = _air_length(x0, y0, th0, x1 - wx * mid, y1 - wy * mid, th1, rho) - v * mid
        if g_mid <= 0.0:
            hi, g_hi = mid, g_mid
        else:
            lo, g_lo = mid, g_mid
    if w * (-g_hi) / v > tolerance_m or g_lo - g_hi > _JUMP_RHO * rho:
        return np.inf
    return hi


@numba.njit(cache=True)
def _time_costs(points: np.ndarray, candidates: np.ndarray, rho: float, v: float, wx: float,
                wy: float, tolerance_m: float) -> np.ndarray:
    """costs[i, a, b]: time from point i with candidate heading a to point i+1 (cyclically)
    with candidate heading b."""
    n, k = candidates.shape
    costs = np.empty((n, k, k))
    for i in range(n):
        j = (i + 1) % n
        for a in range(k):
            for b in range(k):
                costs[i, a, b] = _leg_time(points[i, 0], points[i, 1], candidates[i, a],
                                           points[j, 0], points[j, 1], candidates[j, b], rho,
                                           v, wx, wy, tolerance_m)
    return costs


def leg_times_s(points_m: np.ndarray, headings_rad: np.ndarray, rho_m: float,
                airspeed_m_s: float, wind_m_s: tuple[float, float]) -> np.ndarray:
    """Time of each leg ``i -> i + 1`` of the closed order through ``points_m`` with air headings
    ``headings_rad``; inf for a leg whose shortest path cannot arrive on time (see the module
    docstring)."""
    points = np.ascontiguousarray(points_m, dtype=float)
    headings = np.asarray(headings_rad, dtype=float)
    n = len(points)
    tolerance = _LEG_TOLERANCE_RHO * rho_m
    return np.array([_leg_time(*points[i], headings[i], *points[(i + 1) % n],
                               headings[(i + 1) % n], rho_m, airspeed_m_s, wind_m_s[0],
                               wind_m_s[1], tolerance) for i in range(n)])


@dataclass(frozen=True)
class WindTour:
    """A closed tour flown in a steady wind: the targets in ``order``, the air heading at each
    visit (``air_headings_rad[k]`` at ``targets_m[order[k]]``) and each leg's time
    (``leg_time_s[k]``: ``order[k] -> order[k + 1]``, the last back to the first)."""

    targets_m: np.ndarray
    order: np.ndarray
    air_headings_rad: np.ndarray
    leg_time_s: np.ndarray
    rho_m: float
    airspeed_m_s: float
    wind_m_s: tuple[float, float]       # (east, north) velocity of the air mass

    @property
    def time_s(self) -> float:
        return float(self.leg_time_s.sum())

    @property
    def air_length_m(self) -> float:
        """Length of the path in the air mass (the airspeed times the time)."""
        return self.airspeed_m_s * self.time_s

    def _air_legs(self) -> list[SegmentChain]:
        points = self.targets_m[self.order]
        w = np.asarray(self.wind_m_s, dtype=float)
        starts = np.concatenate([[0.0], np.cumsum(self.leg_time_s)[:-1]])
        legs = []
        for k in range(len(points)):
            j = (k + 1) % len(points)
            # Solved from the target as the leg's time was (where the Dubins length jumps, the
            # last bits of the goal decide the word), then carried to where the air mass is.
            there = points[j] - w * self.leg_time_s[k]
            leg = shortest_path(np.append(points[k], self.air_headings_rad[k]),
                                np.append(there, self.air_headings_rad[j]), self.rho_m).chain()
            shifted = leg.starts.copy()
            shifted[:, :2] -= w * starts[k]
            legs.append(SegmentChain(shifted, leg.lengths_m, leg.curvatures_1_m))
        return legs

    def air_chain(self) -> SegmentChain:
        """The whole path in the air mass (lines and arcs of radius ``rho_m``), from the first
        target; the air mass is taken where it is at the first visit."""
        return SegmentChain.concatenate(self._air_legs())

    def ground_xy_m(self, s_m: np.ndarray) -> np.ndarray:
        """Positions over the ground at air arc lengths ``s_m`` from the first target."""
        s = np.asarray(s_m, dtype=float)
        return (self.air_chain().pose_at(s)[..., :2]
                + np.multiply.outer(s / self.airspeed_m_s, np.asarray(self.wind_m_s)))

    def check(self, tolerance_rho: float = TOLERANCE_RHO) -> CheckReport:
        """The tours' checker on the path in the air mass (C1, curvature at most ``1 / rho``,
        each target where the air mass has carried it at its visit time, on the path within
        ``tolerance_rho * rho``), and the tour closed over the ground: back over the first
        target at its heading."""
        legs = self._air_legs()
        chain = SegmentChain.concatenate(legs)
        points = self.targets_m[self.order]
        w = np.asarray(self.wind_m_s, dtype=float)
        # Where the path in the air mass is when the aircraft flying it at the airspeed is
        # over each target: the air mass has moved on for the time actually flown.
        visits = np.concatenate([[0.0], np.cumsum([leg.length_m for leg in legs])[:-1]])
        report = check_path(chain, self.rho_m, points - np.outer(visits / self.airspeed_m_s, w),
                            visits, closed=False, tolerance_rho=tolerance_rho)
        problems = list(report.problems)
        end = chain.ends()[-1]
        ground_end = end[:2] + w * chain.length_m / self.airspeed_m_s
        gap = float(np.hypot(*(ground_end - points[0])))
        turn = abs(float(wrap_angle(end[2] - self.air_headings_rad[0])))
        if gap > tolerance_rho * self.rho_m or turn > 1e-6:
            problems.append(f"the tour does not close over the ground: it ends {gap:.3g} m "
                            f"from the first target, heading off by {turn:.3g} rad")
        if not np.all(np.isfinite(self.leg_time_s)):
            problems.append("a leg has no path that arrives on time")
        return CheckReport(tuple(problems), report.segment_count, report.target_count,
                           report.length_m, report.max_joint_gap_m,
                           report.max_joint_heading_error_rad, report.max_curvature_ratio,
                           max(report.max_target_miss_m, gap))


@numba.njit(cache=True)
def _crab(ground: float, v: float, wx: float, wy: float) -> float:
    """The air heading that tracks the ground direction ``ground``."""
    dx, dy = math.cos(ground), math.sin(ground)
    along_w = dx * wx + dy * wy
    ax, ay = wx - along_w * dx, wy - along_w * dy
    along = math.sqrt(max(v * v - ax * ax - ay * ay, 0.0))
    return math.atan2(along * dy - ay, along * dx - ax)


@numba.njit(cache=True)
def _crabs(ground: np.ndarray, v: float, wx: float, wy: float) -> np.ndarray:
    out = np.empty_like(ground)
    for i in range(len(ground)):
        out[i] = _crab(ground[i], v, wx, wy)
    return out


def crab_headings(ground_rad: np.ndarray, airspeed_m_s: float,
                  wind_m_s: tuple[float, float]) -> np.ndarray:
    """The air headings that make the aircraft track the ground directions ``ground_rad``
    (the wind slower than the airspeed)."""
    ground = np.ascontiguousarray(ground_rad, dtype=float)
    return _crabs(ground, float(airspeed_m_s), float(wind_m_s[0]), float(wind_m_s[1]))


_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
#: A move of the order or a heading is kept only if it saves more than this (seconds).
_GAIN_S = 1e-9


@numba.njit(cache=True)
def _time(targets, a, ha, b, hb, rho, v, wx, wy, tol):
    """:func:`_leg_time` from target ``a`` (air heading ``ha``) to target ``b`` (``hb``)."""
    return _leg_time(targets[a, 0], targets[a, 1], ha, targets[b, 0], targets[b, 1], hb, rho, v,
                     wx, wy, tol)


@numba.njit(cache=True)
def _around(points, headings, i, heading, rho, v, wx, wy, tol):
    """Time of the two legs at point ``i`` of the closed order with this heading there."""
    n = len(points)
    h, j = (i - 1) % n, (i + 1) % n
    return (_leg_time(points[h, 0], points[h, 1], headings[h], points[i, 0], points[i, 1],
                      heading, rho, v, wx, wy, tol)
            + _leg_time(points[i, 0], points[i, 1], heading, points[j, 0], points[j, 1],
                        headings[j], rho, v, wx, wy, tol))


@numba.njit(cache=True)
def _refine_times(points, headings, rho, v, wx, wy, tol, half_width, sweeps, iterations):
    """Golden-section search of each air heading within +-``half_width`` for the least time of
    its two legs, in place; a heading changes only if that saves time."""
    n = len(points)
    for _ in range(sweeps):
        for i in range(n):
            current = _around(points, headings, i, headings[i], rho, v, wx, wy, tol)
            low, high = headings[i] - half_width, headings[i] + half_width
            x1 = high - _GOLDEN * (high - low)
            x2 = low + _GOLDEN * (high - low)
            f1 = _around(points, headings, i, x1, rho, v, wx, wy, tol)
            f2 = _around(points, headings, i, x2, rho, v, wx, wy, tol)
            for _ in range(iterations):
                if f1 < f2:
                    high, x2, f2 = x2, x1, f1
                    x1 = high - _GOLDEN * (high - low)
                    f1 = _around(points, headings, i, x1, rho, v, wx, wy, tol)
                else:
                    low, x1, f1 = x1, x2, f2
                    x2 = low + _GOLDEN * (high - low)
                    f2 = _around(points, headings, i, x2, rho, v, wx, wy, tol)
            best, value = (x1, f1) if f1 < f2 else (x2, f2)
            if value < current - _GAIN_S:
                headings[i] = best


@numba.njit(cache=True)
def _or_opt(targets, order, headings, neighbours, rho, v, wx, wy, tol, max_segment, max_passes):
    """Or-opt on flight time: a run of up to ``max_segment`` consecutive targets moved, in its
    direction, next to one of the ``neighbours`` of its ends, wherever that saves time (a single
    target also tries the air headings tracking its new legs and the chord across).  First
    improvement, until a pass finds none or ``max_passes``.  Returns (order, headings, moves)."""
    n = len(order)
    order = order.copy()
    headings = headings.copy()
    pos = np.empty(n, dtype=np.int64)
    for k in range(n):
        pos[order[k]] = k
    moves = 0
    options = np.empty(4)
    for _ in range(max_passes):
        improved = False
        for length in range(1, max_segment + 1):
            if length > n - 3:
                break
            start = 0
            while start < n:
                s_last = (start + length - 1) % n
                first, last = order[start], order[s_last]
                before, after = (start - 1) % n, (start + length) % n
                p, q = order[before], order[after]
                hp, hq, hf, hl = headings[before], headings[after], headings[start], headings[s_last]
                gain = (_time(targets, p, hp, first, hf, rho, v, wx, wy, tol)
                        + _time(targets, last, hl, q, hq, rho, v, wx, wy, tol)
                        - _time(targets, p, hp, q, hq, rho, v, wx, wy, tol))
                if not (gain > _GAIN_S and gain < np.inf):
                    start += 1
                    continue
                best_delta, best_at, best_h = -_GAIN_S, -1, hf
                for end in range(2):
                    e = first if end == 0 else last
                    for m in range(neighbours.shape[1]):
                        u = neighbours[e, m]
                        for side in range(2):
                            c_at = pos[u] if side == 0 else (pos[u] - 1) % n
                            d_at = (c_at + 1) % n
                            if ((c_at - start) % n < length or (d_at - start) % n < length):
                                continue
                            c, d = order[c_at], order[d_at]
                            hc, hd = headings[c_at], headings[d_at]
                            base = _time(targets, c, hc, d, hd, rho, v, wx, wy, tol)
                            count = 1
                            options[0] = hf
                            if length == 1:
                                options[1] = _crab(math.atan2(targets[first, 1] - targets[c, 1],
                                                              targets[first, 0] - targets[c, 0]),
                                                   v, wx, wy)
                                options[2] = _crab(math.atan2(targets[d, 1] - targets[first, 1],
                                                              targets[d, 0] - targets[first, 0]),
                                                   v, wx, wy)
                                options[3] = _crab(math.atan2(targets[d, 1] - targets[c, 1],
                                                              targets[d, 0] - targets[c, 0]),
                                                   v, wx, wy)
                                count = 4
                            for o in range(count):
                                h_in = options[o]
                                h_out = h_in if length == 1 else hl
                                delta = (_time(targets, c, hc, first, h_in, rho, v, wx, wy, tol)
                                         + _time(targets, last, h_out, d, hd, rho, v, wx, wy, tol)
                                         - base - gain)
                                if delta < best_delta:
                                    best_delta, best_at, best_h = delta, c_at, h_in
                if best_at < 0:
                    start += 1
                    continue
                # The run goes after position best_at, everything else in its order.
                new_order = np.empty(n, dtype=np.int64)
                new_headings = np.empty(n)
                w = 0
                for k in range(n):
                    if (k - start) % n < length:
                        continue
                    new_order[w], new_headings[w] = order[k], headings[k]
                    w += 1
                    if k == best_at:
                        for r in range(length):
                            at = (start + r) % n
                            new_order[w], new_headings[w] = order[at], headings[at]
                            w += 1
                        if length == 1:
                            new_headings[w - 1] = best_h
                order, headings = new_order, new_headings
                for k in range(n):
                    pos[order[k]] = k
                moves += 1
                improved = True
                start += 1
        if not improved:
            break
    return order, headings, moves


def _headings_for_order(points: np.ndarray, rho_m: float, airspeed_m_s: float,
                        wind_m_s: tuple[float, float], grid: int,
                        ground: np.ndarray | None = None) -> np.ndarray:
    incoming, outgoing = edge_directions(points)
    natural = crab_headings(straight_through_headings(points), airspeed_m_s, wind_m_s)
    offsets = 2.0 * np.pi * np.arange(grid) / grid
    tracks = (incoming, outgoing) + (() if ground is None else (ground,))
    crabbed = [crab_headings(h, airspeed_m_s, wind_m_s) for h in tracks]
    candidates = np.column_stack([*crabbed, natural[:, None] + offsets[None, :]])
    costs = _time_costs(points, np.ascontiguousarray(candidates), float(rho_m),
                        float(airspeed_m_s), float(wind_m_s[0]), float(wind_m_s[1]),
                        _LEG_TOLERANCE_RHO * rho_m)
    headings = candidates[np.arange(len(points)), _best_cycle(costs)].copy()
    _refine_times(points, headings, float(rho_m), float(airspeed_m_s), float(wind_m_s[0]),
                  float(wind_m_s[1]), _LEG_TOLERANCE_RHO * rho_m, math.pi / grid, 3, 24)
    return headings


def plan_wind_tour(targets_m: np.ndarray, order: np.ndarray, rho_m: float, airspeed_m_s: float,
                   wind_m_s: tuple[float, float], grid: int = 24,
                   both_ways: bool = True, improve: bool = True, neighbours: int = 8,
                   max_segment: int = 3, max_passes: int = 50,
                   ground_headings_rad: np.ndarray | None = None) -> WindTour:
    """The fastest tour in the wind ``wind_m_s`` ((east, north) m/s, slower than the airspeed)
    found from ``order`` (or, with ``both_ways``, its reverse if that is faster): air headings
    chosen exactly by dynamic programming among ``grid`` + 2 candidates per target (those that
    track the edges in and out over the ground -- a straight leg between two targets needs
    both --, and ``grid`` evenly spaced from the one tracking the chord from the target before
    to the one after; with ``ground_headings_rad``, per target, those tracking a calm tour's
    headings at its visits -- then in calm air the tour is never longer than that one on the
    same order), each then refined on its own within half a grid step while that saves
    time; with ``improve``, the order then improved on flight time (Or-opt: runs of up to
    ``max_segment`` targets moved next to one of the ``neighbours`` nearest targets of their
    ends, up to ``max_passes`` passes) and its headings chosen again the same way.  The tour
    passes :meth:`WindTour.check`; a target appears once in ``order``; it is never slower than
    the headings chosen for ``order`` (or its reverse) alone.  Deterministic."""
    targets = np.asarray(targets_m, dtype=float).reshape(-1, 2)
    order = np.asarray(order, dtype=np.int64)
    wind = (float(wind_m_s[0]), float(wind_m_s[1]))
    if not (math.isfinite(rho_m) and rho_m > 0):
        raise InputError(f"the turn radius must be a positive number, got {rho_m!r}")
    if not (math.isfinite(airspeed_m_s) and airspeed_m_s > 0):
        raise InputError(f"the airspeed must be a positive number, got {airspeed_m_s!r}")
    if not (all(math.isfinite(c) for c in wind) and math.hypot(*wind) < airspeed_m_s):
        raise InputError(f"a wind of {math.hypot(*wind):g} m/s is not slower than the airspeed "
                         f"{airspeed_m_s:g} m/s")
    if len(order) < 2 or sorted(order.tolist()) != list(range(len(targets))):
        raise InputError("a wind tour needs an order visiting each of at least two targets once")

    def toured(candidate: np.ndarray, headings: np.ndarray) -> WindTour:
        times = leg_times_s(targets[candidate], headings, rho_m, airspeed_m_s, wind)
        return WindTour(targets, candidate, headings, times, float(rho_m), float(airspeed_m_s),
                        wind)

    given = (None if ground_headings_rad is None
             else np.asarray(ground_headings_rad, dtype=float).reshape(len(targets)))
    best = None
    for turn, candidate in ((0.0, order), (math.pi, order[::-1].copy()))[:2 if both_ways else 1]:
        ground = None if given is None else given[candidate] + turn
        tour = toured(candidate, _headings_for_order(targets[candidate], rho_m, airspeed_m_s,
                                                     wind, grid, ground))
        if best is None or tour.time_s < best.time_s:
            best = tour
    if improve and len(targets) > 4 and np.all(np.isfinite(best.leg_time_s)):
        from scipy.spatial import cKDTree
        k = min(neighbours, len(targets) - 1)
        near = cKDTree(targets).query(targets, k + 1)[1][:, 1:]
        moved, headings, moves = _or_opt(targets, best.order, best.air_headings_rad,
                                         np.ascontiguousarray(near, dtype=np.int64),
                                         float(rho_m), float(airspeed_m_s), wind[0], wind[1],
                                         _LEG_TOLERANCE_RHO * rho_m, max_segment, max_passes)
        if moves:
            for tour in (toured(moved, headings),
                         toured(moved, _headings_for_order(targets[moved], rho_m, airspeed_m_s,
                                                           wind, grid))):
                if tour.time_s < best.time_s:
                    best = tour
    return best
