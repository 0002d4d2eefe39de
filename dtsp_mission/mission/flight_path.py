"""From the closed tour to the path a mission flies: take off, join the tour, leave it.

A closed tour returns to its first target; a mission does not need that last leg.  The tour is
opened at the leg whose removal saves the most once the way in from home and the way back are
counted, joined from the end of the climb-out by an exact Dubins path, and (for a landing) left
by an exact Dubins path to the approach point lined up with the landing direction.  The whole
path is one C1 chain with curvature at most ``1 / rho``, which the checker verifies.
"""

from __future__ import annotations

import math

import numpy as np

from ..dubins import shortest_path
from ..errors import TourInvalidError
from ..segments import SegmentChain
from ..tour import Tour
from ..tour.check import check_path
from .model import FlightPath, LoiterSpan

#: Glide slope of the landing approach, degrees (PX4's FW_LND_ANG default is 5).
LANDING_GLIDE_DEG = 5.0
#: Height of the approach point above home, metres (lower if the cruise altitude is lower).
APPROACH_ALTITUDE_M = 40.0
#: Takeoff climb angle assumed to place the end of the climb-out, degrees.
TAKEOFF_CLIMB_DEG = 15.0


def climb_distance_m(altitude_m: float) -> float:
    """Ground distance covered while climbing to ``altitude_m`` at :data:`TAKEOFF_CLIMB_DEG`."""
    return altitude_m / math.tan(math.radians(TAKEOFF_CLIMB_DEG))


def approach(altitude_m: float) -> tuple[float, float]:
    """Altitude of the approach point and its distance before the touchdown point."""
    height = min(APPROACH_ALTITUDE_M, altitude_m)
    return height, height / math.tan(math.radians(LANDING_GLIDE_DEG))


def _open_at(tour: Tour, home_m: np.ndarray, returns_home: bool,
             first_beyond_m: float = 0.0) -> tuple[int, np.ndarray]:
    """Position (in visit order) of the target the opened tour starts with, and the order:
    the opening that saves the most, among targets at least ``first_beyond_m`` from home
    where there are any."""
    order = tour.visit_order
    visits = tour.visit_s_m[order]
    points = tour.targets_m[order]
    gaps = visits - np.roll(visits, 1)
    gaps[0] += tour.length_m
    entry = np.hypot(*(points - home_m).T)
    back = np.roll(entry, 1) if returns_home else 0.0
    cost = entry + back - gaps
    far = entry >= first_beyond_m
    if far.any():
        cost = np.where(far, cost, np.inf)
    return int(np.argmin(cost)), order


def _unit(heading_rad: float) -> np.ndarray:
    return np.array([math.cos(heading_rad), math.sin(heading_rad)])


def plan_flight_path(tour: Tour, home_m: np.ndarray, cruise_altitude_m: float,
                     return_mode: str, launch_heading_rad: float | None = None,
                     landing_heading_rad: float | None = None,
                     target_altitudes_m: np.ndarray | None = None,
                     loiters: dict[int, tuple[int, float]] | None = None,
                     settle_m: float = 0.0) -> FlightPath:
    """The path from the end of the climb-out over every target (in tour order) to the end of
    the mission: the last target for ``rtl``/``none``, the approach point for ``land``.
    ``loiters`` (target -> (turns, radius)) adds whole circles through those targets.

    ``launch_heading_rad`` defaults to the direction from home to the first target and
    ``landing_heading_rad`` to the launch heading (same runway, same wind).  The first target
    is one at least ``settle_m`` beyond the end of the climb-out where there is one: the real
    autopilots' climb-out (faster than cruise, the first turn) is what the flight model
    predicts worst, so no target is passed before the aircraft has settled.
    """
    home = np.asarray(home_m, dtype=float).reshape(2)
    rho = tour.rho_m
    length = tour.length_m
    first, order = _open_at(tour, home, return_mode != "none",
                            climb_distance_m(cruise_altitude_m) + settle_m if settle_m > 0 else 0.0)
    visits = tour.visit_s_m[order]
    start_s, end_s = visits[first], visits[first - 1]
    # Forward from the first target to the last, wrapping past the end of the chain; with a
    # single target, the whole loop through it.
    wraps = end_s <= start_s
    opened = SegmentChain.concatenate([tour.chain.between(start_s, length if wraps else end_s),
                                       tour.chain.between(0.0, end_s if wraps else 0.0)])
    tour_start = opened.starts[0]
    if launch_heading_rad is None:
        towards = tour_start[:2] - home
        launch_heading_rad = (math.atan2(towards[1], towards[0]) if np.hypot(*towards) > 1e-9
                              else float(tour_start[2]))
    climb_end = np.append(home + climb_distance_m(cruise_altitude_m) * _unit(launch_heading_rad),
                          launch_heading_rad)
    lead_in = shortest_path(climb_end, tour_start, rho).chain()
    pieces = [lead_in, opened]
    tour_end = opened.ends()[-1]
    if return_mode == "land":
        heading = launch_heading_rad if landing_heading_rad is None else landing_heading_rad
        _, distance = approach(cruise_altitude_m)
        approach_pose = np.append(home - distance * _unit(heading), heading)
        pieces.append(shortest_path(tour_end, approach_pose, rho).chain())
    chain = SegmentChain.concatenate(pieces).without_empty(1e-12 * rho)
    lead_in_length = lead_in.length_m
    relative = np.mod(tour.visit_s_m - start_s, length)
    target_s = lead_in_length + relative
    tour_end_s = lead_in_length + opened.length_m
    target_s[order[first - 1]] = tour_end_s     # the last target closes the opened tour exactly
    target_s[order[first]] = lead_in_length
    altitudes = (np.full(len(order), float(cruise_altitude_m)) if target_altitudes_m is None
                 else np.asarray(target_altitudes_m, dtype=float))
    flown = np.roll(order, -first)
    knots_s = [0.0, *target_s[flown]]
    knots_alt = [float(cruise_altitude_m), *altitudes[flown]]
    if return_mode == "land":
        knots_s.append(chain.length_m)
        knots_alt.append(approach(cruise_altitude_m)[0])
    knots = (np.asarray(knots_s), np.asarray(knots_alt))
    spans: list[LoiterSpan] = []
    for target in sorted(loiters or {}, key=lambda t: -target_s[t]):   # the last one first
        turns, radius = loiters[target]
        chain, knots, span = _with_loiter(chain, knots, float(target_s[target]), target, turns,
                                          radius, rho)
        target_s = np.where(target_s > span.start_s_m, target_s + span.end_s_m - span.start_s_m,
                            target_s)
        tour_end_s += span.end_s_m - span.start_s_m
        spans = [_shifted(other, span.end_s_m - span.start_s_m) for other in spans]
        spans.insert(0, span)
    report = check_path(chain, rho, tour.targets_m, target_s, closed=False)
    if not report.ok:
        raise TourInvalidError("the flight path failed the checker: " + "; ".join(report.problems))
    return FlightPath(chain, target_s, lead_in_length, tour_end_s, home, knots, tuple(spans))


def _shifted(span: LoiterSpan, by_m: float) -> LoiterSpan:
    return LoiterSpan(span.target, span.start_s_m + by_m, span.end_s_m + by_m, span.centre_m,
                      span.radius_m, span.clockwise, span.turns)


def _with_loiter(chain: SegmentChain, knots, s_m: float, target: int, turns: int, radius_m: float,
                 rho_m: float):
    """The chain with ``turns`` circles of ``radius_m`` inserted at ``s_m`` (tangent there,
    turning the way the path turns just after, left on a straight), the altitude knots moved
    to match, and the span."""
    if radius_m < rho_m * (1 - 1e-9):
        raise TourInvalidError(f"a loiter radius of {radius_m:g} m is tighter than the turn "
                               f"radius {rho_m:g} m")
    pose = chain.pose_at(np.array([s_m]))[0]
    index, _ = chain.locate(np.array([min(s_m + 1e-6 * rho_m, chain.length_m)]))
    curvature = float(chain.curvatures_1_m[int(index[0])])
    left = curvature >= 0.0
    sign = 1.0 if left else -1.0
    circle = SegmentChain(pose.reshape(1, 3), np.array([2 * math.pi * radius_m * turns]),
                          np.array([sign / radius_m]))
    normal = np.array([-math.sin(pose[2]), math.cos(pose[2])]) * sign
    loop = circle.length_m
    joined = SegmentChain.concatenate([chain.between(0.0, s_m), circle,
                                       chain.between(s_m, chain.length_m)]).without_empty(1e-12 * rho_m)
    knots_s, knots_alt = knots
    altitude = float(np.interp(s_m, knots_s, knots_alt))
    after = knots_s > s_m
    knots = (np.concatenate([knots_s[~after], [s_m + loop], knots_s[after] + loop]),
             np.concatenate([knots_alt[~after], [altitude], knots_alt[after]]))
    span = LoiterSpan(target, s_m, s_m + loop, pose[:2] + radius_m * normal, float(radius_m),
                      not left, int(turns))
    return joined, knots, span
