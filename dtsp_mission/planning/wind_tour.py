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

:func:`plan_wind_tour` keeps a given order (the calm planner's, or its reverse when that is
faster) and chooses the air headings at the targets for the least flight time: exact dynamic
programming over candidate headings, as :mod:`.headings` does for length in calm air.  In calm
air its times are the calm tour's Dubins lengths over the airspeed.
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
    previous = t
    for _ in range(100000):
        length = _air_length(x0, y0, th0, x1 - wx * t, y1 - wy * t, th1, rho)
        g = length - v * t
        if g >= 0.0 and w * g / v <= tolerance_m:
            return length / v           # a hair late: over the target within the tolerance
        if g < 0.0:
            break
        previous = t
        t += min(g / (v + w), _MAX_STEP_RHO * rho / v)
    else:
        return np.inf
    # Behind a jump: the first time in (previous, t] the path is not late, if it is on time.
    lo, hi, g_hi = previous, t, g
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        g_mid = _air_length(x0, y0, th0, x1 - wx * mid, y1 - wy * mid, th1, rho) - v * mid
        if g_mid <= 0.0:
            hi, g_hi = mid, g_mid
        else:
            lo = mid
    if w * (-g_hi) / v > tolerance_m:
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
            here = points[k] - w * starts[k]
            there = points[j] - w * (starts[k] + self.leg_time_s[k])
            legs.append(shortest_path(np.append(here, self.air_headings_rad[k]),
                                      np.append(there, self.air_headings_rad[j]),
                                      self.rho_m).chain())
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


def crab_headings(ground_rad: np.ndarray, airspeed_m_s: float,
                  wind_m_s: tuple[float, float]) -> np.ndarray:
    """The air headings that make the aircraft track the ground directions ``ground_rad``
    (the wind slower than the airspeed)."""
    d = np.column_stack([np.cos(ground_rad), np.sin(ground_rad)])
    w = np.asarray(wind_m_s, dtype=float)
    across = w - (d @ w)[:, None] * d
    along = np.sqrt(np.maximum(airspeed_m_s ** 2 - (across ** 2).sum(axis=1), 0.0))
    air = along[:, None] * d - across
    return np.arctan2(air[:, 1], air[:, 0])


def _headings_for_order(points: np.ndarray, rho_m: float, airspeed_m_s: float,
                        wind_m_s: tuple[float, float], grid: int) -> np.ndarray:
    incoming, outgoing = edge_directions(points)
    natural = crab_headings(straight_through_headings(points), airspeed_m_s, wind_m_s)
    offsets = 2.0 * np.pi * np.arange(grid) / grid
    crabbed = [crab_headings(h, airspeed_m_s, wind_m_s) for h in (incoming, outgoing)]
    candidates = np.column_stack([*crabbed, natural[:, None] + offsets[None, :]])
    costs = _time_costs(points, np.ascontiguousarray(candidates), float(rho_m),
                        float(airspeed_m_s), float(wind_m_s[0]), float(wind_m_s[1]),
                        _LEG_TOLERANCE_RHO * rho_m)
    choice = _best_cycle(costs)
    return candidates[np.arange(len(points)), choice]


def plan_wind_tour(targets_m: np.ndarray, order: np.ndarray, rho_m: float, airspeed_m_s: float,
                   wind_m_s: tuple[float, float], grid: int = 24,
                   both_ways: bool = True) -> WindTour:
    """The fastest tour in the wind ``wind_m_s`` ((east, north) m/s, slower than the airspeed)
    over ``order`` (or, with ``both_ways``, its reverse if that is faster) among ``grid`` + 2
    candidate air headings per target (those that track the edges in and out over the ground
    -- a straight leg between two targets needs both --, and ``grid`` evenly spaced from the one
    tracking the chord from the target before to the one after), chosen exactly by dynamic
    programming.  The tour passes :meth:`WindTour.check`; a target appears once in ``order``."""
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
    best = None
    for candidate in (order, order[::-1].copy()) if both_ways else (order,):
        points = targets[candidate]
        headings = _headings_for_order(points, rho_m, airspeed_m_s, wind, grid)
        times = leg_times_s(points, headings, rho_m, airspeed_m_s, wind)
        tour = WindTour(targets, candidate, headings, times, float(rho_m), float(airspeed_m_s),
                        wind)
        if best is None or tour.time_s < best.time_s:
            best = tour
    return best
