"""Waypoints designed for the guidance that flies them, not for the geometry alone.

An autopilot does not fly the chords of a waypoint polyline: ArduPlane anticipates turns,
swings wide after sharp ones and lags in arcs, so dense waypoints along the exact path cost
about seven items per target and still miss targets by 10-40 m.  Here the items are chosen by
predicting the flight with the autopilot model (:mod:`dtsp_mission.autopilot.navigation`,
checked against recorded ArduPlane flights) and repairing what it misses:

1. every target is one NAV_WAYPOINT; a loop of the exact path (an arc turning more than half
   a circle: a sharp change of direction between close targets) gets a waypoint every quarter
   turn on it, because from its ends alone the autopilot cuts inside it the wrong way round;
2. fly the mission in the model; a target the predicted track misses by more than
   ``max_miss_m`` has its waypoint moved by the miss (the aim point: where the autopilot must
   be sent so that it passes over the target);
3. a target whose miss stops shrinking gets a shaping waypoint on the exact path before it
   (half way from the previous waypoint), which is aimed the same way;
4. repeat until every target holds, the rounds or the item budget are spent.

Guarantee: the returned design says, per target, the predicted miss; nothing is claimed that
the model did not fly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..autopilot.commands import Command
from ..autopilot.navigation import Airframe, LocalItem, MissionFlight, closest_approach_m
from .actions import loiter_turns_params
from .model import FlightPath

#: Prediction time step, s (the agreement with ArduPlane was measured at 0.02 s; 0.05 s
#: changes predicted misses by a few decimetres and is 2.5 times faster).
PREDICTION_STEP_S = 0.05
#: A target's aim is corrected once its miss exceeds this fraction of the allowed miss.
CORRECT_ABOVE = 0.5
#: Rounds without a 10 % improvement before a target gets a shaping waypoint.
STALL_ROUNDS = 2
#: A shaping waypoint goes into the longest stretch of the exact path among the waypoint gaps
#: this many L1 distances before the stuck target: where the path turns that the autopilot
#: could not follow (often before the previous target, when the two are close).
LOOKBACK_L1 = 4.0


def _shaping_gap(s_wp: list[float], k: int, lookback_m: float,
                 loiter_ends: dict[float, float] | None = None) -> tuple[float, int]:
    """(arc length, insertion index) of a shaping waypoint for the waypoint at index ``k``:
    the middle of the longest gap between waypoints within ``lookback_m`` of path before it
    (a gap after a loiter starts where its circles end: ``loiter_ends``, start -> end)."""
    ends = loiter_ends or {}
    best_length, best = -1.0, (0.5 * s_wp[k], 0)
    j = k
    while j >= 0:
        low = ends.get(s_wp[j - 1], s_wp[j - 1]) if j > 0 else 0.0
        gap = s_wp[j] - low
        if gap > best_length:
            best_length, best = gap, (0.5 * (low + s_wp[j]), j)
        if s_wp[k] - low > lookback_m:
            break
        j -= 1
    return best


@dataclass(frozen=True)
class GuidanceDesign:
    """Waypoints on the tour part of a flight path, and what the model predicts for them."""

    s_m: np.ndarray                 # arc length on the exact path each waypoint stands for
    aim_m: np.ndarray               # (k, 2) where each waypoint is placed (local frame)
    target_of: np.ndarray           # target index (input order) of target waypoints, else -1
    predicted_miss_m: np.ndarray    # per target (input order): closest approach of the track
    predicted_length_m: float       # predicted track length from take-off end to last target
    planned_length_m: float         # the exact path over the same span
    rounds: int

    @property
    def shaping(self) -> int:
        return int((self.target_of < 0).sum())


def _fly(items: list[LocalItem], airframe: Airframe, heading_rad: float,
         stop_after_seq: int) -> tuple[np.ndarray, dict[int, float]]:
    """Track rows (time, x, y) and reach times, until item ``stop_after_seq`` is reached."""
    flight = MissionFlight(items, airframe, heading_rad, 1)
    track = [(0.0, 0.0, 0.0)]
    limit = 36000.0
    while not flight.finished and flight.state.time_s < limit:
        flight.step(PREDICTION_STEP_S)
        state = flight.state
        track.append((state.time_s, state.x_m, state.y_m))
        if flight.reached and flight.reached[-1][0] >= stop_after_seq:
            break
    return np.array(track), dict(flight.reached)


def _nearest_in(track_xy: np.ndarray, point: np.ndarray) -> np.ndarray:
    """The point of the polyline ``track_xy`` nearest to ``point``."""
    a, d = track_xy[:-1], np.diff(track_xy, axis=0)
    t = np.clip(((point - a) * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), 1e-12), 0.0, 1.0)
    q = a + t[:, None] * d
    return q[int(np.argmin(((q - point) ** 2).sum(axis=1)))]


def _local_items(takeoff_m: np.ndarray, takeoff_alt_m: float, head_items, aim_m: np.ndarray,
                 altitudes_m: np.ndarray, target_of: list[int], target_acceptance_m: float,
                 loiters: dict[int, tuple[float, float, tuple]] | None = None
                 ) -> tuple[list[LocalItem], list[int]]:
    """The mission the design flies (home slot, take-off, head items, the waypoints at ``aim_m``
    relative to home, each target's loiter after it -- ``loiters``: target -> (x, y, params)
    -- and RTL), and the seq of each waypoint."""
    items = [LocalItem(0, Command.NAV_WAYPOINT, math.nan, math.nan, 0.0, (0.0,) * 4),
             LocalItem(1, Command.NAV_TAKEOFF, float(takeoff_m[0]), float(takeoff_m[1]),
                       takeoff_alt_m, (15.0, 0.0, 0.0, 0.0))]
    for command, params in head_items:
        items.append(LocalItem(len(items), command, math.nan, math.nan, 0.0, params))
    seqs = []
    for point, altitude, t in zip(aim_m, altitudes_m, target_of):
        seqs.append(len(items))
        items.append(LocalItem(len(items), Command.NAV_WAYPOINT, float(point[0]), float(point[1]),
                               float(altitude),
                               (0.0, target_acceptance_m if t >= 0 else 0.0, 0.0, 0.0)))
        if loiters and t in loiters:
            x, y, params = loiters[t]
            items.append(LocalItem(len(items), Command.NAV_LOITER_TURNS, x, y, float(altitude),
                                   params))
    items.append(LocalItem(len(items), Command.NAV_RETURN_TO_LAUNCH, math.nan, math.nan,
                           float(altitudes_m[-1]), (0.0,) * 4))
    return items, seqs


#: An arc of the exact path turning more than this is a loop the guidance does not fly from
#: its ends alone (it cuts inside, the wrong way round): it gets waypoints on it from the start.
LOOP_MIN_RAD = math.pi
#: Spacing of those waypoints along the loop, as turn angle.
LOOP_STEP_RAD = math.pi / 2


def _loop_waypoints(path: FlightPath, room: int) -> np.ndarray:
    """Arc lengths of waypoints on the loops of the tour part of ``path`` (arcs turning more
    than :data:`LOOP_MIN_RAD`), every :data:`LOOP_STEP_RAD` of turn, at most ``room``."""
    chain = path.chain
    offsets = chain.offsets_m
    turn = np.abs(chain.curvatures_1_m) * chain.lengths_m
    chosen = []
    for k in np.flatnonzero(turn > LOOP_MIN_RAD):
        start = offsets[k]
        if start < path.tour_start_s_m - 1e-9 or start > path.tour_end_s_m:
            continue
        count = int(math.ceil(turn[k] / LOOP_STEP_RAD)) - 1
        step = chain.lengths_m[k] / (count + 1)
        chosen += [start + step * (j + 1) for j in range(count)]
    chosen = np.asarray(chosen, dtype=float)
    if path.loiters:
        chosen = chosen[~path.in_loiter(chosen)]
    return chosen[:max(room, 0)]


def design_waypoints(path: FlightPath, targets_m: np.ndarray, altitudes_m: np.ndarray,
                     airframe: Airframe, max_miss_m: float, budget: int,
                     head_items: list[tuple[int, tuple[float, float, float, float]]] = (),
                     target_acceptance_m: float = 5.0, rounds: int = 30) -> GuidanceDesign:
    """The waypoints (``budget`` at most) that make the modelled autopilot pass every target
    of ``path`` within ``max_miss_m``, as far as the rounds allow.

    ``targets_m`` are the targets (input order, local frame), ``altitudes_m`` their altitudes
    above home; ``head_items`` are the (command, params) of the items flown between the take-off
    and the first waypoint (DO_CHANGE_SPEED).  The flight starts at the path's climb start
    (home) facing the start of the path.
    """
    home = path.climb_start_m
    order = np.argsort(path.target_s_m, kind="stable")
    s_wp = list(path.target_s_m[order])
    target_of = list(order)
    for s in _loop_waypoints(path, budget - len(s_wp)):
        k = int(np.searchsorted(s_wp, s))
        s_wp.insert(k, float(s))
        target_of.insert(k, -1)
    offsets = {int(t): np.zeros(2) for t in order}        # aim minus target, per target
    best: tuple[float, GuidanceDesign] | None = None
    takeoff = path.chain.pose_at(np.array([0.0]))[0, :2] - home
    heading = math.atan2(takeoff[1], takeoff[0])
    stalled = {int(t): 0 for t in order}
    lookback_m = LOOKBACK_L1 * airframe.l1_distance_m(airframe.airspeed_m_s)
    loiters = {span.target: (float(span.centre_m[0] - home[0]), float(span.centre_m[1] - home[1]),
                             loiter_turns_params(span.turns, span.radius_m, span.clockwise))
               for span in path.loiters}
    loiter_ends = {float(span.start_s_m): float(span.end_s_m) for span in path.loiters}
    previous_miss: np.ndarray | None = None
    for round_number in range(1, rounds + 1):
        exact = path.chain.pose_at(np.asarray(s_wp))[:, :2]
        aim = np.array([targets_m[t] + offsets[t] if t >= 0 else exact[k]
                        for k, t in enumerate(target_of)])
        items, seqs = _local_items(takeoff, float(path.altitude_m(np.array([0.0]))[0]),
                                   head_items, aim - home, path.altitude_m(np.asarray(s_wp)),
                                   target_of, target_acceptance_m, loiters)
        track, reached = _fly(items, airframe, heading, len(items) - 2)
        flown = track[:, 1:] + home
        after_takeoff = track[:, 0] >= reached.get(1, 0.0)
        miss = closest_approach_m(flown[after_takeoff], targets_m)
        start_s = reached.get(1, 0.0)
        span = after_takeoff & (track[:, 0] <= reached.get(len(items) - 2, np.inf))
        predicted = float(np.hypot(*np.diff(flown[span], axis=0).T).sum())
        designed = GuidanceDesign(np.asarray(s_wp), aim, np.asarray(target_of), miss, predicted,
                                  float(path.target_s_m.max()), round_number)
        excess = float(np.maximum(miss - max_miss_m, 0.0).sum())
        if best is None or excess < best[0]:
            best = (excess, designed)
        if excess == 0.0:
            break
        improved = (np.ones(len(miss), dtype=bool) if previous_miss is None
                    else miss < 0.9 * previous_miss)
        previous_miss = miss
        insert: list[tuple[float, int]] = []
        for k, t in enumerate(target_of):
            if t < 0 or miss[t] <= CORRECT_ABOVE * max_miss_m:
                continue
            seq = seqs[k]
            begin = reached.get(seq - 1, start_s)
            end = reached.get(seq + 1, track[-1, 0])
            window = (track[:, 0] >= begin) & (track[:, 0] <= end)
            if window.sum() < 2:
                window = after_takeoff
            nearest = _nearest_in(flown[window], targets_m[t])
            offsets[t] = offsets[t] + (targets_m[t] - nearest)
            stalled[t] = 0 if improved[t] else stalled[t] + 1
            if stalled[t] >= STALL_ROUNDS and miss[t] > max_miss_m:
                insert.append(_shaping_gap(s_wp, k, lookback_m, loiter_ends))
                stalled[t] = 0
                offsets[t] = np.zeros(2)
        for s, k in sorted(set(insert), reverse=True):
            if len(s_wp) >= budget:
                break
            s_wp.insert(k, s)
            target_of.insert(k, -1)
    return best[1]
