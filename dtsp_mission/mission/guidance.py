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
   ``correct_above`` of ``max_miss_m`` has its waypoint moved by the miss (the aim point:
   where the autopilot must be sent so that it passes over the target);
3. the round is kept only if the total miss beyond ``max_miss_m`` (each target beyond counted
   ``beyond_cost`` of it more) shrinks; if not, the corrections that did not hurt where they
   act (their target and the next ``affects_next``) are flown alone; if that does not help
   either, the next round tries half the corrections (waypoints closer than the L1 distance
   pull each other's tracks, so full corrections of neighbours overshoot together);
4. after ``idle_rounds`` rounds in a row that gain less than ``progress``, each target still
   beyond gets a shaping waypoint on the exact path before it (in the longest waypoint gap
   within ``lookback_l1``) and the corrections go on from there;
5. repeat until every target holds or the predicted flights (``rounds``) or the item budget
   are spent;
6. the verifying flight: the design flown afresh at the model's own step (``verify_step_s``,
   the step its agreement with ArduPlane was measured at, and the one ``fly`` and
   ``predict_flight`` use), every waypoint where the vehicle stores it (rounded to 1e-7
   degree: a switch one step earlier or later moves the track by decimetres);
7. the local repair, at that step: each target it finds beyond, in visit order, is flown
   again from a checkpoint of the flight ``local_back`` waypoints before it to
   ``local_ahead`` after it (a few seconds of flight instead of the whole mission; none of the
   waypoints moved is at or before the checkpoint's), its own waypoint and the
   ``local_move`` before it moved by a pattern search (steps along east and north, halved when
   none helps); if that leaves it beyond, the search again from those of them that stand for
   targets put back on their targets (``local_reset``), and from the best of ``local_starts``
   random placements of them within ``local_spread_m`` (none by default); the change is kept only if the mission flown
   on from the checkpoint costs less.  Up to ``refine_passes`` passes, each ending with the whole mission flown afresh;
   the design returned is the best of those fresh flights;
8. with ``revisits`` (the default): each target still beyond is passed a second time later in
   the mission -- a waypoint over it (its altitude, its acceptance radius) where it lengthens
   the straight legs least, at least ``revisit_apart`` waypoints from any other pass of it --
   and the local repair runs again (a revisit's waypoint is moved for its target like the
   target's own); up to ``revisit_rounds`` rounds, each kept only if the robust cost falls.
   Targets still beyond then get *detours*: a lead-in waypoint ``revisit_lead_l1`` L1 distances
   before the target (a straight the guidance settles on), the target, and a rejoin waypoint as
   far before the next waypoint of the leg the detour leaves (so that waypoint is approached as
   before); up to ``detour_rounds`` rounds, kept likewise.  A target's miss is the closest of
   its passes.  Only if targets stay beyond does the wider-turn stage plan the tour again
   (:mod:`.widening`).  In a forecast wind the targets passed twice are instead entered along
   straights planned into the tour and that tour designed again, kept if it flies shorter
   (``stuck_lead_in_l1``, :func:`dtsp_mission.mission.waypoints.design_for_guidance`).

The rounds 2-5 (at the coarser ``prediction_step_s``) hold the targets within ``max_miss_m -
PREDICTION_MARGIN_M``; the verifying flight and the local repair within ``max_miss_m -
VERIFY_MARGIN_M``.

Guarantee: the returned design says, per target, the miss of the mission as stored, flown
by the model at its own step from the start; nothing is claimed that the model did not fly.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..autopilot.commands import Command
from ..autopilot.navigation import (CALM, FLIGHT_LIMIT_S, MODEL_STEP_S, Airframe, LocalItem,
                                    MissionArrays, MissionFlight, Wind)
from .actions import loiter_turns_params
from .model import FlightPath


@dataclass(frozen=True)
class DesignTuning:
    """The guidance design's tuning, passed in (``MissionSettings.tuning``): each value as
    measured where its note says.  The defaults are the product's."""

    #: Prediction time step, s (the agreement with ArduPlane was measured at 0.02 s; 0.05 s
    #: changes predicted misses by a few decimetres and is 2.5 times faster).
    prediction_step_s: float = 0.05
    #: A target's aim is corrected once its miss exceeds this fraction of the allowed miss.
    correct_above: float = 0.5
    #: Aim corrections are tried at full size and halved each round they do not help; after
    #: ``idle_rounds`` rounds in a row without ``progress`` (a fraction of the total miss beyond
    #: the allowed one) the targets still beyond get shaping waypoints.
    idle_rounds: int = 2
    progress: float = 0.05
    #: A correction at a target is judged by its miss and the misses of this many targets after it
    #: (the track it moves settles again within a few L1 distances).
    affects_next: int = 2
    #: Predicted flights a design may take (measured: 30 -> 50 holds 1 to 3 more targets of 100-272
    #: on the mission-items sites, about 3 s more on the bundled site).
    rounds: int = 50
    #: A target beyond the allowed miss counts as missed by this fraction of the allowed miss more
    #: (measured on the eight sites of docs/mission-items.md: 1 instead of 0 leaves 31 instead of 41
    #: targets beyond 5 m, 16 instead of 24 on the 400-target clustered site, whose worst miss is
    #: 28.1 against 27.6 m).
    beyond_cost: float = 1.0
    #: A shaping waypoint goes into the longest stretch of the exact path among the waypoint gaps
    #: this many L1 distances before the stuck target: where the path turns that the autopilot
    #: could not follow (often before the previous target, when the two are close).
    lookback_l1: float = 4.0
    #: An arc of the exact path turning more than this is a loop the guidance does not fly from
    #: its ends alone (it cuts inside, the wrong way round): it gets waypoints on it from the start.
    loop_min_rad: float = math.pi
    #: Spacing of those waypoints along the loop, as turn angle.
    loop_step_rad: float = math.pi / 2
    #: The local repair: a target still beyond is re-flown from ``local_back`` waypoints before it
    #: to ``local_ahead`` after it, moving the waypoints ``local_move`` before it and its own, in at
    #: most ``local_trials`` short flights; a change is kept only if the whole mission flown again
    #: is better.  The flight resumes one waypoint before the first one moved: a waypoint's
    #: position already decides when the one before it is reached (its turn angle scales the
    #: acceptance radius) and when a loiter before it is left.
    local_back: int = 3
    local_ahead: int = 3
    local_move: int = 2
    local_trials: int = 40
    local_min_step_m: float = 0.25
    #: A target the pattern search leaves beyond can get up to this many other starts (seeded by
    #: its place in the mission; the first that holds it ends them), every movable waypoint
    #: anywhere within ``local_spread_m`` east and north of where it was; the pattern search goes
    #: on from the best of them if it is better than where it started.  Off by default: measured
    #: (docs/mission-items.md) before ``local_reset``, 100 starts took the 400-target clustered
    #: site from 4 to 2 targets beyond (worst 22.6 -> 17.4 m) and held the bundled site at 1.3
    #: rho instead of 1.6 (27.4 instead of 32.4 km, 1.12 instead of 1.24 items per target), but
    #: doubled the design time (bundled site 371 s against 145 s).  Since the model flies to a
    #: waypoint whose leg starts already past it (ArduPlane's set_next_WP), they leave more
    #: beyond on the fence site of tests/mission (one repair round: 5 posts against 2).
    local_starts: int = 0
    local_spread_m: float = 40.0
    #: A target the pattern search leaves beyond gets one more search, from the movable waypoints
    #: of targets put back on their targets: the repair's corrections of neighbouring waypoints
    #: pile up (each moved to pass its own target) where no small step undoes them.  Measured on
    #: the 400-target clustered site at 1.6 rho: the local repair ends with 0 targets beyond
    #: instead of 4 (worst 22.6 m), in 114 s instead of 96 s (the local repair alone, from the
    #: same repaired design; whole sites in docs/mission-items.md).
    local_reset: bool = True
    #: Passes of the local repair over the targets still beyond (it stops early when one gains
    #: nothing).
    refine_passes: int = 3
    #: The repair holds the targets this much closer than asked: its predictions (0.05 s steps)
    #: differ from the verifying flight's by up to 1.5 m (bundled site), mostly under half a metre.
    prediction_margin_m: float = 0.5
    #: The local repair flies at the step of the verifying flight (the one the model's agreement
    #: with ArduPlane was measured at, which `fly` and `predict_flight` fly too), and holds the
    #: targets this much inside ``max_miss_m``.
    verify_step_s: float = MODEL_STEP_S
    verify_margin_m: float = 0.05
    #: Turns of a loiter the design flies: the later ones repeat the last (their length is added).
    design_loiter_turns: int = 2
    #: The wider turn radii (times the one asked for) the whole tour is planned again with,
    #: in turn, when the design at the radius asked for does not hold every target.  None by
    #: default: a wider tour costs a whole tour and design again and flies 20-40 % longer
    #: (bundled site: 25.1 km at rho 80 with one target predicted 0.2 m beyond the design
    #: limit, 32.7 km at rho 128 holding it; 65 s against 132 s of planning); the targets
    #: still beyond are named instead.  (1.3, 1.6) was the default before slow zones.
    guidance_margins: tuple[float, ...] = ()
    #: ... also when the design holds every target but only by passing some twice (revisits,
    #: detours), if the wider tour is shorter than ``widen_below`` of that design's predicted
    #: flight: the second passes can cost more flight than wider turns.  Measured
    #: (docs/design-time.md, one core): in calm air, designing the wider tour whenever it is
    #: shorter than the flight shortened two of eight benchmark sites' flights by 3-4 % (dense
    #: 100: 19.49 -> 18.81 km, clustered 400: 95.54 -> 92.48 km) and took 1.1-2.4 times the
    #: design time elsewhere (bundled 20.6 -> 60.9 s, the same flight); in 5 m/s from 180 deg
    #: on the bundled site it cut the flight from 2,011 to 1,472 s (docs/wind-design.md).  The
    #: gate 0.8 keeps that gain; still off: in calm air it plans a wider tour it then skips
    #: (bundled 28.7 -> 36.2 s, no site's flight shorter).
    widen_after_revisits: bool = False
    widen_below: float = 0.8
    #: Targets the local repair leaves beyond are passed again later in the mission, before
    #: any wider tour is tried: one waypoint over each (its own acceptance radius), inserted
    #: where it lengthens the flight least (the straight-line detour, plus ``revisit_turn_m``
    #: per radian turned at it), at least ``revisit_apart`` waypoints from any other pass of
    #: it; then the local repair once more; up to ``revisit_rounds`` rounds while they help.
    #: Measured on the bundled site at rho 80: 10 targets beyond -> 3 (24.76 -> 27.25 km).
    revisits: bool = True
    #: Before any second pass: targets still beyond are flown slower, at ``slow_airspeed_ratio``
    #: of the airspeed (at least ``slow_min_airspeed_m_s``: 1.4 times ArduPlane's stock
    #: AIRSPEED_MIN), from the last waypoint at least the slowing-down distance and
    #: ``slow_settle_l1`` L1 distances before each, back to the airspeed after it; up to
    #: ``slow_rounds`` rounds (each adds the targets then beyond), each kept only if the robust
    #: cost falls.  Costs two DO_CHANGE_SPEED items per zone and time (the aircraft flies 25 %
    #: slower there), no length.  One round: after the second design, which slows for the
    #: targets the first left beyond from the start, a second or third round held nothing
    #: more on 16 benchmark cases in the model (docs/design-time.md; one held it with fewer
    #: second passes) and costs a local repair each (6 s of the 400-target site's design).
    #: 0.85 of the airspeed instead of 0.75 left more targets to second passes (1.17 instead
    #: of 1.15 x the tour's time on 9 cases, measured with ``slow_start_slack_l1`` 0.5).
    slow_airspeed_ratio: float = 0.75
    slow_min_airspeed_m_s: float = 14.0
    slow_settle_l1: float = 1.0
    slow_rounds: int = 1
    #: With a value, a zone starts at a waypoint of its own (a slowing waypoint on the leg the
    #: guidance flies there) unless one already stands within this many L1 distances before
    #: the point it should start at: the speed changes where a waypoint is reached, and the
    #: waypoint before a target may be a long leg back.  Off (None) by default: measured in
    #: the model on 13 benchmark cases (docs/design-time.md, rho 80, 22 m/s; 9 calm, 4 in 5 m/s)
    #: the flight's time over the tour's was 1.193 x on average with them (0.5 L1) against 1.192 x
    #: without -- shorter on uniform sites and in wind (uniform 100 in 5 m/s from 90 deg: 1.19
    #: instead of 1.31 x), longer on the dense and bundled sites (bundled 1.42 instead of
    #: 1.31 x: the extra waypoints cost the design second passes there).
    slow_start_slack_l1: float | None = None
    #: With a value, no target's own waypoint is aimed farther than this from the target (in
    #: the repair's corrections and the local repair's moves): a far aim holds the target only
    #: through the guidance's modelled overshoot, which the real autopilot varies.  Measured on
    #: 3,616 targets of 28 real ArduPlane flights (docs/real-flights.md): model and real
    #: differed by more than 3 m at 0.5 % of the targets aimed within 10 m, 2-3 % of those
    #: aimed 10-20 m away and 5-7 % of those aimed 20-50 m away.  15 m, flown again by the
    #: real ArduPlane on ten cases: 29 -> 10 targets beyond 5 m, flights as long on average;
    #: off by default, as the bundled site then flies 1.32 instead of 1.08 x its tour and
    #: takes 2.5 times as long to plan (docs/missions.md).
    max_aim_offset_m: float | None = None
    #: ... for the targets judged beyond the limit less this much (held, but by less than the
    #: real autopilot's flight-to-flight spread), kept if their cost at that tighter limit falls
    #: and none beyond the limit is added.
    slow_margin_m: float = 0.5
    #: ... and the targets the design at the airspeed leaves beyond are flown slower from the
    #: start of a second design (its whole repair aims for the slower flight).
    slow_from_start: bool = True
    #: ... that first design's local repair passes (it only finds the targets to slow for;
    #: measured, docs/design-time.md: 0 instead of 3 plans the bundled site in 33.5 s instead
    #: of 63 s on one core, every benchmark site held in the model, flights within 2 %).
    slow_first_refine_passes: int = 0
    #: In a forecast wind, the targets the design passes twice (or leaves beyond) are entered
    #: instead along a straight this many L1 distances long (the L1 distance at the fastest
    #: ground speed, the airspeed plus the wind) planned into the tour
    #: (:mod:`dtsp_mission.planning.lead_ins`), and that tour designed the same way; it is
    #: kept if it holds as many targets in a shorter predicted flight.  A target entered
    #: mid-turn holds only for the forecast wind; on a straight the guidance has settled
    #: whatever the wind.  Measured in the model (docs/design-time.md): uniform 100 in 8 m/s
    #: 1.56 -> 1.40 x the tour for the wind, the bundled site in 8 m/s 1.97 -> 1.69; in calm
    #: air a second pass costs less than the straight (bundled: 1,402 -> 1,422-1,581 s), so
    #: none there.  None: never.
    stuck_lead_in_l1: float | None = 1.2
    revisit_turn_m: float = 80.0
    revisit_apart: int = 4
    revisit_rounds: int = 3
    #: Targets the plain revisits leave beyond get a *detour*: a lead-in waypoint this many L1
    #: distances before the target (in one of ``revisit_directions`` directions), the target,
    #: and a rejoin waypoint as far before the next waypoint of the leg it leaves; up to
    #: ``detour_rounds`` rounds while they help.  Measured on the bundled site at rho 80: the
    #: 3 targets the revisits left beyond -> 0 (27.25 -> 32.01 km); with a lead-in of 1.2 L1,
    #: 1 left beyond (30.72 km).
    revisit_lead_l1: float = 2.0
    revisit_directions: int = 16
    detour_rounds: int = 2
    #: The repair and the verifying flights also fly the aircraft turning this fraction slower
    #: and faster (its turn efficiency) in the forecast wind, each held within the allowed miss
    #: itself like the design winds: an aim that holds only for the one turn rate the model
    #: flies -- a waypoint switch or a turn direction decided by a few decimetres -- is
    #: designed away (0: off).  Measured in ArduPlane SITL (one calm flight each,
    #: benchmarks/real_flights.py): the bundled site 8 -> 4 targets beyond 5 m (worst 11.7 ->
    #: 6.6 m; a loop flown the other way round by the real aircraft is gone), dense 100 4 -> 4
    #: (worst 35.2 -> 8.2 m), for a flight about as long (36.1 km) and no longer design.
    turn_spread: float = 0.06
    #: The repair and the verifying flights also fly the aircraft rolling slower in the forecast
    #: wind: its roll response's natural frequency times ``1 - roll_spread`` and its damping
    #: plus ``roll_damping_spread`` -- held within the allowed miss like the turn spread (0:
    #: off).  Measured against every target of the real ArduPlane flights
    #: (benchmarks/real_flights.py, 1,472 targets, 17 of them beyond 5 m): the model with this
    #: slower roll passes 7 of those 17 beyond 5 m and only 32 of the other 1,455 (where the
    #: model as fitted passed 1 of them beyond 3.4 m): the turn reversals and turn entries
    #: whose outcome hangs on how fast the bank builds.
    roll_spread: float = 0.2
    roll_damping_spread: float = 0.15
    #: The repair and the verifying flights also fly the aircraft rolling much slower still in
    #: the forecast wind (natural frequency times ``1 - flip_roll_spread``, damping plus
    #: ``flip_roll_damping_spread``), held only within the allowed miss plus
    #: ``flip_allowance_m``: not a tighter hold, a guard against the aims whose outcome flips
    #: -- a loop flown the other way round, a waypoint switched a turn later -- when the
    #: aircraft rolls otherwise than modelled (0: off).  Measured against every target of 25
    #: real ArduPlane flights (benchmarks/real_flights.py): the model flying this aircraft
    #: passes 92 of 3,616 targets beyond 6 m, 12 of the 27 the real aircraft passed beyond
    #: 5 m among them.  Flown by the real ArduPlane (docs/real-flights.md), five cases: 23 ->
    #: 13 targets beyond 5 m (bundled site in 5 m/s from 180 deg 9 -> 2, dense 100 in 8 m/s
    #: 4 -> 2 (worst 51.4 -> 8.0 m), dense 400 9 -> 6, clustered 100 1 -> 0; the bundled
    #: site calm 0 -> 3), flights as long on average (1.28 x the tour against 1.29: bundled
    #: 5@180 1.37 against 1.14, dense 100 8@90 1.65 against 1.93).
    flip_roll_spread: float = 0.4
    flip_roll_damping_spread: float = 0.3
    flip_allowance_m: float = 1.5
    #: Those flights of the aircraft turning or rolling otherwise are held this much within the
    #: allowed miss (the design winds' flights within it): the real ArduPlane's misses spread
    #: about a metre from flight to flight, and a target the model passes at 4.8 m with the
    #: aircraft turning 6 % slower was passed at 4.2-5.2 m in four real flights.
    perturbed_holdback_m: float = 0.5


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
                                    # in the forecast wind
    predicted_length_m: float       # predicted track length from take-off end to last target
    planned_length_m: float         # the exact path over the same span
    rounds: int                     # predicted flights the design took
    #: per target, what the design is judged by (:func:`_judged`: the forecast's miss, or the
    #: worst in the other design winds less the margin); None: the forecast's miss
    judged_miss_m: np.ndarray | None = None
    #: per target, the worst miss over the design winds; None: the forecast's miss
    worst_miss_m: np.ndarray | None = None
    #: predicted time (s) over the span of ``predicted_length_m`` in the forecast wind (loiter
    #: turns the design does not fly counted at the airspeed); NaN: not predicted
    predicted_time_s: float = math.nan
    #: per waypoint, the airspeed (m/s) asked for (DO_CHANGE_SPEED) just before it, NaN where
    #: none; None: no change anywhere (the slow zones of :func:`_slow_zones`)
    speed_before_m_s: np.ndarray | None = None

    @property
    def shaping(self) -> int:
        return int((self.target_of < 0).sum())


def _fly(items: list[LocalItem], airframe: Airframe, heading_rad: float, stop_after_seq: int,
         targets_m: np.ndarray, wind: Wind = CALM, step_s: float = DesignTuning.prediction_step_s
         ) -> tuple[np.ndarray, dict[int, float], np.ndarray, float]:
    """Track rows (time, x, y), reach times, each target's closest approach after the take-off
    (``targets_m`` in the flight's frame) and the length flown from the take-off's end, until
    item ``stop_after_seq`` is reached."""
    flight = MissionFlight(items, airframe, heading_rad, 1, wind)
    run = flight.run(step_s, stop_after_seq, points_m=targets_m,
                     measure_from_seq=_AFTER_TAKEOFF, until_s=FLIGHT_LIMIT_S)
    track = np.vstack([np.zeros((1, 3)), run.track[:, :3]])
    return track, dict(flight.reached), run.closest_m, run.measured_length_m


#: The first item after the take-off (seq 1): the misses and length count from it.
_AFTER_TAKEOFF = 2


def _nearest_in(track_xy: np.ndarray, point: np.ndarray) -> np.ndarray:
    """The point of the polyline ``track_xy`` nearest to ``point``."""
    a, d = track_xy[:-1], np.diff(track_xy, axis=0)
    t = np.clip(((point - a) * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), 1e-12), 0.0, 1.0)
    q = a + t[:, None] * d
    return q[int(np.argmin(((q - point) ** 2).sum(axis=1)))]


#: ``target_of`` of a revisit of target t: ``REVISIT - t`` (plain shaping waypoints are -1).
REVISIT = -2


def revisited(marker: int) -> int:
    """The target a waypoint's ``target_of`` marks as revisited, or -1."""
    return REVISIT - marker if marker <= REVISIT else -1


def waypoint_altitudes_m(path: FlightPath, s_wp, target_of) -> np.ndarray:
    """Each waypoint's altitude: the path's where it stands, a revisit's its target's."""
    altitudes = path.altitude_m(np.asarray(s_wp, dtype=float))
    of = np.array([revisited(int(marker)) for marker in target_of], dtype=np.int64)
    again = of >= 0
    altitudes[again] = path.altitude_m(path.target_s_m[of[again]])
    return altitudes


def _local_items(takeoff_m: np.ndarray, takeoff_alt_m: float, head_items, aim_m: np.ndarray,
                 altitudes_m: np.ndarray, target_of: list[int], target_acceptance_m: float,
                 loiters: dict[int, tuple[float, float, tuple]] | None = None,
                 speeds: list[float] | None = None) -> tuple[list[LocalItem], list[int]]:
    """The mission the design flies (home slot, take-off, head items, the waypoints at ``aim_m``
    relative to home, each target's loiter after it -- ``loiters``: target -> (x, y, params)
    -- and RTL), and the seq of each waypoint.  ``speeds`` (one per waypoint, NaN for none):
    a DO_CHANGE_SPEED to that airspeed just before the waypoint."""
    items = [LocalItem(0, Command.NAV_WAYPOINT, math.nan, math.nan, 0.0, (0.0,) * 4),
             LocalItem(1, Command.NAV_TAKEOFF, float(takeoff_m[0]), float(takeoff_m[1]),
                       takeoff_alt_m, (15.0, 0.0, 0.0, 0.0))]
    for command, params in head_items:
        items.append(LocalItem(len(items), command, math.nan, math.nan, 0.0, params))
    seqs = []
    for k, (point, altitude, t) in enumerate(zip(aim_m, altitudes_m, target_of)):
        if speeds is not None and math.isfinite(speeds[k]):
            items.append(LocalItem(len(items), Command.DO_CHANGE_SPEED, math.nan, math.nan, 0.0,
                                   (0.0, float(speeds[k]), -1.0, 0.0)))
        seqs.append(len(items))
        items.append(LocalItem(len(items), Command.NAV_WAYPOINT, float(point[0]), float(point[1]),
                               float(altitude),
                               (0.0, target_acceptance_m if t >= 0 or t <= REVISIT else 0.0,
                                0.0, 0.0)))
        if loiters and t in loiters:
            x, y, params = loiters[t]
            items.append(LocalItem(len(items), Command.NAV_LOITER_TURNS, x, y, float(altitude),
                                   params))
    items.append(LocalItem(len(items), Command.NAV_RETURN_TO_LAUNCH, math.nan, math.nan,
                           float(altitudes_m[-1]), (0.0,) * 4))
    return items, seqs




def _loop_waypoints(path: FlightPath, room: int, tuning: DesignTuning) -> np.ndarray:
    """Arc lengths of waypoints on the loops of the tour part of ``path`` (arcs turning more
    than ``loop_min_rad``), every ``loop_step_rad`` of turn, at most ``room``."""
    chain = path.chain
    offsets = chain.offsets_m
    turn = np.abs(chain.curvatures_1_m) * chain.lengths_m
    chosen = []
    for k in np.flatnonzero(turn > tuning.loop_min_rad):
        start = offsets[k]
        if start < path.tour_start_s_m - 1e-9 or start > path.tour_end_s_m:
            continue
        count = int(math.ceil(turn[k] / tuning.loop_step_rad)) - 1
        step = chain.lengths_m[k] / (count + 1)
        chosen += [start + step * (j + 1) for j in range(count)]
    chosen = np.asarray(chosen, dtype=float)
    if path.loiters:
        chosen = chosen[~path.in_loiter(chosen)]
    return chosen[:max(room, 0)]


@dataclass
class _Trial:
    """One flown candidate design and what the model predicted for it."""

    s_wp: list[float]
    target_of: list[int]
    offsets: dict[int, np.ndarray]
    design: GuidanceDesign
    cost: np.ndarray                 # per target (input order): what the repair minimises
    corrections: dict[int, np.ndarray]   # per target: where the track should have been moved

    @staticmethod
    def cost_of(miss_m: np.ndarray, max_miss_m: float,
                beyond_cost: float = DesignTuning.beyond_cost) -> np.ndarray:
        """Per target, its miss beyond ``max_miss_m`` and ``beyond_cost`` of it if beyond."""
        excess = np.maximum(miss_m - max_miss_m, 0.0)
        return excess + beyond_cost * max_miss_m * (excess > 0.0)

    @property
    def total(self) -> float:
        return float(self.cost.sum())


def _with_shaping(trial: _Trial, targets: list[int], lookback_m: float,
                  loiter_ends: dict[float, float],
                  fly: Callable[[list[float], list[int], dict[int, np.ndarray]], _Trial]) -> _Trial:
    """``trial`` flown again with a shaping waypoint before each of ``targets`` (their aims
    reset onto the targets)."""
    s_wp, target_of, offsets = list(trial.s_wp), list(trial.target_of), dict(trial.offsets)
    chosen = set(targets)
    insert = sorted({_shaping_gap(s_wp, k, lookback_m, loiter_ends)
                     for k, t in enumerate(target_of) if t in chosen}, reverse=True)
    for s, k in insert:
        s_wp.insert(k, s)
        target_of.insert(k, -1)
    for t in chosen:
        offsets[t] = np.zeros(2)
    return fly(s_wp, target_of, offsets)




_POOL: ThreadPoolExecutor | None = None
#: The pattern search's moves: east, west, north, south.
_STEPS = tuple(np.array(d, dtype=float) for d in ((1, 0), (-1, 0), (0, 1), (0, -1)))


def _cores() -> int:
    """The cores this process may run on (its affinity: ``taskset``, a container's limit)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:          # not on Linux
        return os.cpu_count() or 1


def _each(function: Callable, items) -> list:
    """``[function(item) for item in items]``, on every core the process may use (the
    compiled flights release the GIL); in order, so the result does not depend on the machine."""
    global _POOL
    items = list(items)
    if len(items) < 2 or _cores() < 2:
        return [function(item) for item in items]
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=min(_cores(), 8),
                                   thread_name_prefix="design-flights")
    return list(_POOL.map(function, items))


def _conditions(airframe: Airframe, winds: tuple[Wind, ...],
                tuning: DesignTuning) -> list[tuple[Airframe, Wind]]:
    """The flights a design is judged by: the aircraft in each design wind (the forecast
    first), then, with ``tuning.turn_spread``, the aircraft turning that much slower and
    faster in the forecast, and with ``tuning.roll_spread`` rolling slower in it."""
    flown = [(airframe, wind) for wind in winds]
    if tuning.turn_spread > 0:
        flown += [(replace(airframe, turn_efficiency=airframe.turn_efficiency * (1.0 + sign *
                                                                               tuning.turn_spread)),
                   winds[0]) for sign in (-1.0, 1.0)]
    if tuning.roll_spread > 0 or tuning.roll_damping_spread > 0:
        flown.append((rolling_slower(airframe, tuning.roll_spread, tuning.roll_damping_spread),
                      winds[0]))
    if _flips(tuning):
        flown.append((rolling_slower(airframe, tuning.flip_roll_spread,
                                     tuning.flip_roll_damping_spread), winds[0]))
    return flown


def rolling_slower(airframe: Airframe, spread: float, damping_spread: float) -> Airframe:
    """``airframe`` with its roll response's natural frequency times ``1 - spread`` and its
    damping plus ``damping_spread``."""
    return replace(airframe, roll_natural_rad_s=airframe.roll_natural_rad_s * (1.0 - spread),
                   roll_damping=airframe.roll_damping + damping_spread)


def _flips(tuning: DesignTuning) -> int:
    """How many flights of :func:`_conditions` guard against flipped outcomes (the last)."""
    return int(tuning.flip_roll_spread > 0 or tuning.flip_roll_damping_spread > 0)


def _judged(misses: list[np.ndarray], spread_margin_m: float) -> np.ndarray:
    """Per target, the miss a design is judged by: its miss in the forecast wind (the first),
    or its worst miss in the other winds less ``spread_margin_m`` if that is more (the model's
    error margin covers the forecast; the other winds are the forecast's own error, held
    within the limit the user asked for)."""
    judged = np.array(misses[0], dtype=float)
    for i in range(1, len(misses)):
        judged = np.maximum(judged, misses[i] - _margin(spread_margin_m, i))
    return judged


def _margin(spread_margin_m: float | tuple[float, ...], condition: int) -> float:
    """The margin the misses of the ``condition``-th flight of :func:`_conditions` are judged
    with: none for the forecast (0), else ``spread_margin_m`` -- one for all, or one per
    condition."""
    if condition == 0:
        return 0.0
    if isinstance(spread_margin_m, tuple):
        return spread_margin_m[condition]
    return float(spread_margin_m)


def _refine(aim: np.ndarray, target_of: list[int], items: list[LocalItem], seqs: list[int],
            home: np.ndarray, targets_m: np.ndarray, max_miss_m: float, airframe: Airframe,
            heading: float, stored: Callable[[np.ndarray], np.ndarray],
            winds: tuple[Wind, ...] = (CALM,), spread_margin_m: float = 0.0,
            tuning: DesignTuning = DesignTuning()) -> tuple[np.ndarray, np.ndarray, float, int]:
    """(aims, per-target miss, predicted length, whole flights) after up to
    ``refine_passes`` passes of the local repair over the targets still beyond
    ``max_miss_m``, in visit order, each from the design as repaired so far.  A target's miss
    is :func:`_judged` over ``winds`` (each flown; the first is the forecast, whose flight
    gives the length).  A change is kept only if the mission flown on with it from its checkpoints
    costs less (:meth:`_Trial.cost_of`); a moved waypoint is placed ``stored``.  Each pass ends
    with the whole mission flown afresh from the start: the misses and length returned are
    those of the best such flights (a resumed flight can differ from a fresh one by a few
    decimetres), so they are what the mission flies."""
    mission = MissionArrays.of(items)
    seq_set = set(seqs)
    last = len(items) - 2
    local_targets = targets_m - home

    def afresh(mission: MissionArrays):
        runs = _each(lambda flown: MissionFlight(mission, flown[0], heading, 1, flown[1]).run(
                         tuning.verify_step_s, last, marks=seq_set, points_m=local_targets,
                         measure_from_seq=_AFTER_TAKEOFF, track=False, until_s=FLIGHT_LIMIT_S),
                     _conditions(airframe, winds, tuning))
        miss = _judged([run.closest_m for run in runs], spread_margin_m)
        marks = {seq: [run.checkpoints[seq] for run in runs] for seq in runs[0].checkpoints
                 if all(seq in run.checkpoints for run in runs)}
        cost = _Trial.cost_of(miss, max_miss_m, tuning.beyond_cost)
        return marks, miss, runs[0].measured_length_m, cost

    def within_cap(j: int, point: np.ndarray) -> np.ndarray:
        """``point`` for waypoint ``j``: no farther from its target than the cap."""
        own = target_of[j]
        if own < 0 or tuning.max_aim_offset_m is None:
            return point
        return targets_m[own] + _capped(point - targets_m[own], tuning.max_aim_offset_m)

    marks, miss, length, cost = afresh(mission)
    flights = 1
    aim = aim.copy()
    best = (aim, miss, length, cost.sum())
    for _ in range(tuning.refine_passes):
        before_pass = cost.sum()
        if before_pass <= 0.0:
            break
        for k, marker in enumerate(target_of):
            t = marker if marker >= 0 else revisited(marker)      # a revisit repairs its target
            if t < 0 or cost[t] <= 0.0:
                continue
            begin, end = max(k - tuning.local_back, 0), min(k + tuning.local_ahead, len(seqs) - 1)
            checkpoints = marks[seqs[begin]]
            window = [u for u in dict.fromkeys(m if m >= 0 else revisited(m)
                                               for m in target_of[begin:end + 1]) if u >= 0]
            movable = list(range(max(k - tuning.local_move, begin + 1 if begin > 0 else 0), k + 1))
            movable_index = np.array([seqs[j] for j in movable], dtype=np.int64)

            def with_aims(points: np.ndarray) -> MissionArrays:
                return mission.with_positions(movable_index, points[movable] - home)

            def flown(changed: MissionArrays, checkpoint) -> np.ndarray:
                return checkpoint.resumed(changed).run(
                    tuning.verify_step_s, seqs[end], track=False, points_m=local_targets[window],
                    closest_m=checkpoint.closest_m[window], measure_from_seq=_AFTER_TAKEOFF,
                    until_s=FLIGHT_LIMIT_S).closest_m

            def local_cost(points: np.ndarray, bound: float = math.inf,
                           parallel: bool = True) -> float:
                """The window's cost with these aims; a trial that cannot beat ``bound`` may
                be cut short: the misses of the winds flown so far bound the cost from below
                (the judged miss is their maximum, less the margin for the winds after the
                forecast), so the cost returned is then only a value at least ``bound``.  The
                winds are flown heaviest first (their weights in the last full trial), one at
                a time in a trial that already runs on one core, and stop as soon as the bound
                is met.  Exact otherwise: the same decisions as flying every wind.
                ``parallel`` flies the other winds on every core (not from a trial that
                already runs on one) after the heaviest."""
                changed = with_aims(points)
                lead = heaviest[0][0]
                misses: list[np.ndarray | None] = [None] * len(checkpoints)
                if bound < math.inf and len(checkpoints) > 1:
                    misses[lead] = flown(changed, checkpoints[lead])
                    judged = misses[lead] - _margin(spread_margin_m, lead)
                    low = float(_Trial.cost_of(judged, max_miss_m, tuning.beyond_cost).sum())
                    if low >= bound:
                        return low
                    if not parallel:
                        # one wind after the other, each raising the judged misses (their
                        # maximum) and so the bound from below: stopped as soon as it is met
                        for i in heaviest[0]:
                            if misses[i] is not None:
                                continue
                            misses[i] = flown(changed, checkpoints[i])
                            judged = np.maximum(judged, misses[i] - _margin(spread_margin_m, i))
                            low = float(_Trial.cost_of(judged, max_miss_m,
                                                       tuning.beyond_cost).sum())
                            if low >= bound:
                                return low
                rest = [i for i in range(len(checkpoints)) if misses[i] is None]
                fly_rest = (lambda i: flown(changed, checkpoints[i]))
                for i, miss in zip(rest, _each(fly_rest, rest) if parallel
                                   else [fly_rest(i) for i in rest]):
                    misses[i] = miss
                worst = _judged(misses, spread_margin_m)
                weights = [_Trial.cost_of(m - _margin(spread_margin_m, i), max_miss_m,
                                          tuning.beyond_cost).sum() for i, m in enumerate(misses)]
                heaviest[0] = sorted(range(len(weights)), key=lambda i: -weights[i])
                return float(_Trial.cost_of(worst, max_miss_m, tuning.beyond_cost).sum())

            def descend(candidate: np.ndarray, current: float, step_m: float
                        ) -> tuple[np.ndarray, float]:
                """Pattern search from ``candidate``: the best aims found and their cost.  The
                moves of a step are flown on every core, each cut short against the cost it
                must beat; the first of the cheapest is taken -- the move a search trying them
                one after another would take, whatever the machine."""
                trials = 0
                while (trials < tuning.local_trials and step_m >= tuning.local_min_step_m
                       and current > 0.0):
                    moves = []
                    for j in movable:
                        for direction in _STEPS:
                            if trials + len(moves) < tuning.local_trials:
                                moved = candidate.copy()
                                moved[j] = stored(within_cap(j, moved[j] + step_m * direction)[None])[0]
                                moves.append(moved)
                    trials += len(moves)
                    costs = _each(lambda moved, bound=current: local_cost(moved, bound, False),
                                  moves)
                    best = int(np.argmin(costs))
                    if costs[best] < current:
                        candidate, current = moves[best], costs[best]
                    else:
                        step_m *= 0.5
                return candidate, current

            first_step_m = max(min(miss[t] - max_miss_m, 10.0), 1.0)
            # the winds by the weight of their misses in the last full trial, heaviest first
            heaviest = [list(range(len(checkpoints)))]
            initial = local_cost(aim)
            candidate, current = descend(aim.copy(), initial, first_step_m)
            if current > 0.0 and tuning.local_reset:
                reset = aim.copy()
                on = [j for j in movable if target_of[j] >= 0]
                reset[on] = stored(targets_m[[target_of[j] for j in on]])
                if np.any(reset != aim):
                    other, other_cost = descend(reset, local_cost(reset), first_step_m)
                    if other_cost < current:
                        candidate, current = other, other_cost
            if current > 0.0:
                # The repair's corrections can leave the waypoints where no small step helps:
                # other starts, the movable waypoints each anywhere within local_spread_m.
                rng = np.random.default_rng(k)
                best_start, best_cost = None, initial
                for _ in range(tuning.local_starts):
                    moved = aim.copy()
                    moved[movable] = stored(aim[movable] + rng.uniform(
                        -tuning.local_spread_m, tuning.local_spread_m, (len(movable), 2)))
                    c = local_cost(moved, best_cost)
                    if c < best_cost:
                        best_start, best_cost = moved, c
                        if c <= 0.0:
                            break
                if best_start is not None:
                    other, other_cost = descend(best_start, best_cost, first_step_m)
                    if other_cost < current:
                        candidate, current = other, other_cost
            if not np.any(candidate != aim):
                continue
            changed = with_aims(candidate)
            later = {q for q in seq_set if q >= seqs[begin]}
            runs = _each(lambda checkpoint: checkpoint.resumed(changed).run(
                             tuning.verify_step_s, last, track=False, marks=later,
                             points_m=local_targets,
                             closest_m=checkpoint.closest_m, measure_from_seq=_AFTER_TAKEOFF,
                             until_s=FLIGHT_LIMIT_S), checkpoints)
            flights += 1
            new_miss = _judged([run.closest_m for run in runs], spread_margin_m)
            new_cost = _Trial.cost_of(new_miss, max_miss_m, tuning.beyond_cost)
            if new_cost.sum() < cost.sum():
                aim, mission = candidate, changed
                miss, length, cost = new_miss, runs[0].measured_length_m, new_cost
                marks.update({seq: [run.checkpoints[seq] for run in runs]
                              for seq in runs[0].checkpoints
                              if all(seq in run.checkpoints for run in runs)})
        if cost.sum() >= before_pass:
            break
        marks, miss, length, cost = afresh(mission)
        flights += 1
        if cost.sum() < best[3]:
            best = (aim, miss, length, cost.sum())
    return best[0], best[1], best[2], flights


def _capped(offset: np.ndarray, cap_m: float | None) -> np.ndarray:
    """``offset`` shortened to ``cap_m`` if it is longer (unchanged if ``cap_m`` is None)."""
    length = float(np.hypot(offset[0], offset[1]))
    if cap_m is None or length <= cap_m:
        return offset
    return offset * (cap_m / length)


def _turn_rad(into: np.ndarray, out: np.ndarray) -> float:
    """The heading change from direction ``into`` to ``out`` (0 to pi)."""
    return abs(math.atan2(into[0] * out[1] - into[1] * out[0], float(into @ out)))


def _with_revisits(s_wp: list[float], target_of: list[int], aim: np.ndarray,
                   targets_m: np.ndarray, beyond: list[int], tuning: DesignTuning,
                   stored: Callable[[np.ndarray], np.ndarray], end_s_m: float = math.inf,
                   lead_m: float = 0.0, speeds: list[float] | None = None
                   ) -> tuple[list[float], list[int], np.ndarray, list[float]]:
    """The waypoints with one more pass over each of ``beyond`` (its waypoint placed ``stored``,
    as the vehicle keeps it), on the leg a -> b of the mission where it costs least, at least
    ``revisit_apart`` waypoints from any other pass of the target and before ``end_s_m``.

    With ``lead_m`` 0 the pass is one waypoint between a and b (cost: the longer straight legs
    plus ``revisit_turn_m`` per radian turned at it).  With ``lead_m`` > 0 it is a *detour*: a
    lead-in waypoint ``lead_m`` before the target, in one of ``revisit_directions`` directions
    (a straight the guidance settles on, whatever the turn onto it), the target, and a rejoin
    waypoint on the leg ``lead_m`` before b, so that b is approached as before (cost: the
    detour's length plus ``revisit_turn_m`` per radian of its four turns).  Either way the
    flight up to a does not change.  ``speeds`` (per waypoint, :func:`_local_items`) are
    returned with NaN (no change) for the waypoints inserted."""
    s_wp, target_of, points = list(s_wp), list(target_of), list(np.asarray(aim))
    speeds = [math.nan] * len(s_wp) if speeds is None else list(speeds)
    angles = 2.0 * math.pi * np.arange(tuning.revisit_directions) / tuning.revisit_directions
    directions = np.column_stack([np.cos(angles), np.sin(angles)])
    for t in beyond:
        here = stored(np.asarray(targets_m[t], dtype=float)[None])[0]
        leads = stored(here - lead_m * directions) if lead_m > 0 else None
        passes = [k for k, marker in enumerate(target_of) if marker == t or revisited(marker) == t]
        best, best_cost = None, math.inf
        for k in range(len(points) - 1):
            if (s_wp[k] >= end_s_m - 1e-9
                    or any(abs(k - p) < tuning.revisit_apart or abs(k + 1 - p) < tuning.revisit_apart
                           for p in passes)):
                continue
            a, b = points[k], points[k + 1]
            leg = b - a
            length = float(np.hypot(*leg))
            if lead_m <= 0:
                into, out = here - a, b - here
                la, lb = float(np.hypot(*into)), float(np.hypot(*out))
                if la < 1e-6 or lb < 1e-6:
                    continue
                cost = la + lb - length + tuning.revisit_turn_m * _turn_rad(into, out)
                if cost < best_cost:
                    best, best_cost = (k, [here]), cost
                continue
            if length < 2.0 * lead_m or target_of[k + 1] <= REVISIT:
                continue                # no room to rejoin, or b is itself a revisit
            rejoin = b - lead_m * leg / length
            for lead, direction in zip(leads, directions):
                into, out = lead - a, rejoin - here
                la, lb = float(np.hypot(*into)), float(np.hypot(*out))
                if la < 1e-6 or lb < 1e-6:
                    continue
                turned = (_turn_rad(leg, into) + _turn_rad(into, direction)
                          + _turn_rad(direction, out) + _turn_rad(out, leg))
                cost = la + 2.0 * lead_m + lb - length + tuning.revisit_turn_m * turned
                if cost < best_cost:
                    best, best_cost = (k, [lead, here, stored(rejoin[None])[0]]), cost
        if best is None:
            continue
        k, inserted = best
        s_wp[k + 1:k + 1] = [s_wp[k]] * len(inserted)
        target_of[k + 1:k + 1] = ([REVISIT - t] if len(inserted) == 1
                                  else [-1, REVISIT - t, -1])   # lead-in and rejoin shape it
        points[k + 1:k + 1] = inserted
        speeds[k + 1:k + 1] = [math.nan] * len(inserted)
    return s_wp, target_of, np.array(points), speeds


def _slow_zones(s_wp, target_of: list[int], beyond: list[int], slow_m_s: float,
                cruise_m_s: float, before_m: float) -> list[float]:
    """Per waypoint, the airspeed asked for just before it (NaN: none): the aircraft slows to
    ``slow_m_s`` on reaching the last waypoint at least ``before_m`` of path before each target
    of ``beyond`` and is back at ``cruise_m_s`` from that target's waypoint on; overlapping
    zones are one.  No zone ends after the last waypoint (the return flies on slowly)."""
    n = len(s_wp)
    slow = np.zeros(n + 1, dtype=bool)          # waypoint k flown towards slowly
    at = {t: k for k, t in enumerate(target_of) if t >= 0}
    for t in beyond:
        k = at.get(int(t))
        if k is None:
            continue
        first = 0
        for i in range(k - 1, -1, -1):
            if s_wp[k] - s_wp[i] >= before_m:
                first = i + 1
                break
        slow[first:k + 1] = True
    speeds = [math.nan] * n
    for k in range(n):
        was = slow[k - 1] if k > 0 else False
        if slow[k] and not was:
            speeds[k] = slow_m_s
        elif was and not slow[k]:
            speeds[k] = cruise_m_s
    return speeds


def _speed_items(speeds: list[float]) -> int:
    """The DO_CHANGE_SPEED items of per-waypoint ``speeds`` (:func:`_slow_zones`)."""
    return sum(math.isfinite(v) for v in speeds)


def _with_zone_starts(s_wp: list[float], target_of: list[int], among, before_m: float,
                      slack_m: float, loiter_ends: dict[float, float]
                      ) -> tuple[list[float], list[int], list[int]]:
    """``s_wp`` and ``target_of`` with a waypoint (marked -1) ``before_m`` of path before each
    target of ``among`` whose slow zone (:func:`_slow_zones`) would otherwise start more than
    ``slack_m`` earlier -- unless that point is before the path, inside a loiter (start ->
    end in ``loiter_ends``) or inside the zone of an earlier target of ``among``.  Also the
    indices (into the lists returned) of the waypoints inserted."""
    s_wp, target_of = list(s_wp), list(target_of)
    chosen = set(int(t) for t in among)
    ks = [k for k, t in enumerate(target_of) if t in chosen]
    starts = []
    zone_end = -math.inf
    for k in ks:
        start = s_wp[k] - before_m - 1e-3          # the zone starts on reaching it
        if start > zone_end and start > 0.0 and not any(a <= start <= b
                                                        for a, b in loiter_ends.items()):
            before = [s for s in s_wp[:k] if s <= start]
            if not before or start - before[-1] > slack_m:
                starts.append(start)
        zone_end = s_wp[k]
    inserted = []
    for start in starts:
        k = int(np.searchsorted(s_wp, start))
        s_wp.insert(k, start)
        target_of.insert(k, -1)
        inserted = [i + 1 if i >= k else i for i in inserted] + [k]
    return s_wp, target_of, sorted(inserted)


def design_waypoints(path: FlightPath, targets_m: np.ndarray, altitudes_m: np.ndarray,
                     airframe: Airframe, max_miss_m: float, budget: int,
                     head_items: list[tuple[int, tuple[float, float, float, float]]] = (),
                     target_acceptance_m: float = 5.0, rounds: int | None = None,
                     progress: Callable[[int, int], None] | None = None,
                     as_stored: Callable[[np.ndarray], np.ndarray] | None = None,
                     winds: tuple[Wind, ...] = (CALM,), spread_margin_m: float = 0.0,
                     tuning: DesignTuning = DesignTuning(),
                     lead_s_m: np.ndarray | None = None,
                     slow_targets: tuple[int, ...] = ()) -> GuidanceDesign:
    """The waypoints (``budget`` at most) that make the modelled autopilot pass every target
    of ``path`` within ``max_miss_m``, as far as ``rounds`` predicted flights of the repair and
    the local repair's passes allow.

    ``targets_m`` are the targets (input order, local frame), ``altitudes_m`` their altitudes
    above home; ``head_items`` are the (command, params) of the items flown between the take-off
    and the first waypoint (DO_CHANGE_SPEED).  The flight starts at the path's climb start
    (home) facing the start of the path.  The design returned is the best flown (least
    :attr:`_Trial.total`): a round that makes it worse is never kept.  ``progress(flights,
    rounds)`` is called after each predicted flight and after each local repair pass (those
    fly beyond ``rounds``: one whole flight per change they keep or reject).
    ``as_stored`` maps positions (``(k, 2)``, local frame) to where the
    vehicle stores them (the mission's rounding to 1e-7 degree): the design flies those, since
    the switch of a waypoint one step earlier or later moves the track by decimetres.
    ``slow_targets`` are flown slower from the start (:func:`_slow_zones`; the design adds
    the targets it then leaves beyond, see ``DesignTuning.slow_rounds``).
    ``lead_s_m`` are the arc lengths where straight lead-ins planned into the tour begin
    (:mod:`dtsp_mission.planning.lead_ins`): each gets a waypoint from the start, so that the
    guidance flies the straight from there to its target.
    """
    home = path.climb_start_m
    stored = as_stored if as_stored is not None else (lambda points: points)
    flips = _flips(tuning)
    perturbed = len(_conditions(airframe, winds, tuning)) - len(winds) - flips
    if perturbed or flips:
        # the aircraft turning and rolling otherwise is held that much within the limit; the
        # one rolling much slower only within the limit plus the flip allowance
        spread = float(spread_margin_m)
        spread_margin_m = tuple([0.0] + [spread] * (len(winds) - 1)
                                + [spread - tuning.perturbed_holdback_m] * perturbed
                                + [spread + tuning.flip_allowance_m] * flips)
    repair_miss_m = max(max_miss_m - tuning.prediction_margin_m, 0.5 * max_miss_m)
    order = np.argsort(path.target_s_m, kind="stable")
    s_wp = list(path.target_s_m[order])
    target_of = list(order)
    leads = [] if lead_s_m is None else [float(s) for s in lead_s_m]
    for s in sorted(leads[:max(budget - len(s_wp), 0)]) + list(
            _loop_waypoints(path, budget - len(s_wp) - len(leads), tuning)):
        k = int(np.searchsorted(s_wp, s))
        s_wp.insert(k, float(s))
        target_of.insert(k, -1)
    takeoff = stored(path.chain.pose_at(np.array([0.0]))[:, :2])[0] - home   # as stored, too
    heading = math.atan2(takeoff[1], takeoff[0])
    l1_m = airframe.l1_distance_m(airframe.airspeed_m_s)
    lookback_m = tuning.lookback_l1 * l1_m
    # The design flies each loiter's first design_loiter_turns turns: later turns repeat the
    # last one (same circle, same exit), so they add their length and change no miss.
    loiters = {span.target: (float(span.centre_m[0] - home[0]), float(span.centre_m[1] - home[1]),
                             loiter_turns_params(min(span.turns, tuning.design_loiter_turns),
                                                 span.radius_m, span.clockwise))
               for span in path.loiters}
    # The flights end with the last target's loiter, if it has one: so does the plan compared.
    planned_end_s = max([float(path.target_s_m.max())] + [span.end_s_m for span in path.loiters])
    skipped_m = sum(2.0 * math.pi * span.radius_m * max(span.turns - tuning.design_loiter_turns, 0)
                    for span in path.loiters)
    loiter_ends = {float(span.start_s_m): float(span.end_s_m) for span in path.loiters}
    takeoff_alt = float(path.altitude_m(np.array([0.0]))[0])
    rounds = tuning.rounds if rounds is None else rounds
    rank = np.empty(len(order), dtype=int)          # each target's place in the visit order
    rank[order] = np.arange(len(order))
    flights = 0
    slow_m_s = max(tuning.slow_airspeed_ratio * airframe.airspeed_m_s, tuning.slow_min_airspeed_m_s)
    can_slow = (tuning.slow_rounds > 0 and slow_m_s < airframe.airspeed_m_s
                and airframe.airspeed_time_constant_s <= 0.0)
    slow_before_m = ((airframe.airspeed_m_s ** 2 - slow_m_s ** 2)
                     / (2.0 * max(airframe.airspeed_down_m_s2, 0.05)) + tuning.slow_settle_l1 * l1_m)
    slow_set = set(int(t) for t in slow_targets) if can_slow else set()

    def zone_speeds(s_wp, target_of, among: set[int]) -> list[float] | None:
        """The airspeeds asked before each waypoint for slow zones before ``among``."""
        if not among:
            return None
        speeds = _slow_zones(list(s_wp), list(target_of), sorted(among), slow_m_s,
                             airframe.airspeed_m_s, slow_before_m)
        if len(s_wp) + _speed_items(speeds) > budget:
            return None                 # no room for the speed changes
        return speeds

    def with_starts(s_wp, target_of, aim: np.ndarray, among: set[int]):
        """``s_wp``, ``target_of`` and ``aim`` with the slowing waypoints of the zones before
        ``among`` (:func:`_with_zone_starts`; none if the zones would then not fit the
        vehicle), each aimed on the leg the guidance flies there (between the aims of the
        waypoints either side, as far along as it is along the path): the leg is the same
        line, only the speed changes where the waypoint is reached."""
        if tuning.slow_start_slack_l1 is None:
            return list(s_wp), list(target_of), aim
        s_new, target_new, inserted = _with_zone_starts(
            list(s_wp), list(target_of), among, slow_before_m, tuning.slow_start_slack_l1 * l1_m,
            loiter_ends)
        if not inserted or zone_speeds(s_new, target_new, among) is None:
            return list(s_wp), list(target_of), aim
        aim = np.asarray(aim, dtype=float)
        for k in inserted:
            if k == 0:          # before the first waypoint: on the leg from the take-off
                a, s_a = takeoff + home, 0.0
            else:
                a, s_a = aim[k - 1], s_new[k - 1]
            b, s_b = aim[k], s_new[k + 1]
            share = (s_new[k] - s_a) / max(s_b - s_a, 1e-9)
            aim = np.insert(aim, k, stored((a + share * (b - a))[None])[0], axis=0)
        return s_new, target_new, aim

    def fly(s_wp: list[float], target_of: list[int], offsets: dict[int, np.ndarray]) -> _Trial:
        nonlocal flights
        flights += 1
        if progress is not None:
            progress(flights, rounds)
        exact = path.chain.pose_at(np.asarray(s_wp))[:, :2]
        offsets = {t: _capped(offset, tuning.max_aim_offset_m) for t, offset in offsets.items()}
        aim = stored(np.array([targets_m[t] + offsets[t] if t >= 0 else exact[k]
                               for k, t in enumerate(target_of)]))
        items, seqs = _local_items(takeoff, takeoff_alt, head_items, aim - home,
                                   path.altitude_m(np.asarray(s_wp)), target_of,
                                   target_acceptance_m, loiters,
                                   zone_speeds(s_wp, target_of, slow_set))
        track, reached, miss, predicted = _fly(items, airframe, heading, len(items) - 2,
                                               targets_m - home, winds[0], tuning.prediction_step_s)
        flown = track[:, 1:] + home
        after_takeoff = track[:, 0] >= reached.get(1, 0.0)
        start_s = reached.get(1, 0.0)
        design = GuidanceDesign(np.asarray(s_wp), aim, np.asarray(target_of), miss,
                                predicted + skipped_m, planned_end_s, flights)
        corrections = {}
        for k, t in enumerate(target_of):       # the track near each target's own leg
            if t < 0 or miss[t] <= tuning.correct_above * repair_miss_m:
                continue
            begin = reached.get(seqs[k] - 1, start_s)
            end = reached.get(seqs[k] + 1, track[-1, 0])
            window = (track[:, 0] >= begin) & (track[:, 0] <= end)
            if window.sum() < 2:
                window = after_takeoff
            corrections[t] = targets_m[t] - _nearest_in(flown[window], targets_m[t])
        return _Trial(list(s_wp), list(target_of), dict(offsets), design,
                      _Trial.cost_of(miss, repair_miss_m, tuning.beyond_cost), corrections)

    def local(trial: _Trial, t: int) -> float:
        """Cost at target t and the next targets it affects (visit order)."""
        k = rank[t]
        return float(trial.cost[order[k:k + tuning.affects_next + 1]].sum())

    best = current = fly(s_wp, target_of, {int(t): np.zeros(2) for t in order})
    step, idle = 1.0, 0
    while best.total > 0.0 and flights < rounds:
        # Aim corrections (a fraction ``step`` of each), from the current design.
        proposal = dict(current.offsets)
        for t, correction in current.corrections.items():
            proposal[t] = current.offsets[t] + step * correction
        trial = fly(current.s_wp, current.target_of, proposal)
        if trial.total >= current.total and flights < rounds:
            # Keep only the corrections that did not hurt where they act.
            kept = {t for t in current.corrections if local(trial, t) <= local(current, t)}
            if kept and len(kept) < len(current.corrections):
                trial = fly(current.s_wp, current.target_of,
                            {t: proposal[t] if t in kept else current.offsets[t]
                             for t in current.offsets})
        if trial.total < current.total:
            idle = 0 if trial.total < (1.0 - tuning.progress) * current.total else idle + 1
            current = trial
            best = trial if trial.total < best.total else best
        else:
            step, idle = 0.5 * step, idle + 1
        if idle < tuning.idle_rounds or flights >= rounds:
            continue
        # Corrections no longer help: a shaping waypoint before each target still beyond;
        # the corrections go on from there (the best design flown is kept).
        beyond = [int(t) for t in np.flatnonzero(current.cost > 0.0)]
        room = budget - len(current.s_wp)
        if room <= 0 or not beyond:
            break
        current = _with_shaping(current, beyond[:room], lookback_m, loiter_ends, fly)
        best = current if current.total < best.total else best
        step, idle = 1.0, 0
    # The design as the verifying flight sees it (its slow zones from waypoints of their
    # own), and the local repair of what it misses.
    design = best.design
    s_final, target_final, aim = with_starts(design.s_m, best.target_of, design.aim_m, slow_set)
    s_final = np.asarray(s_final)
    items, seqs = _local_items(takeoff, takeoff_alt, head_items, aim - home,
                               waypoint_altitudes_m(path, s_final, target_final), target_final,
                               target_acceptance_m, loiters,
                               zone_speeds(s_final, target_final, slow_set))
    verify_miss_m = max(max_miss_m - tuning.verify_margin_m, 0.5 * max_miss_m)
    aim, miss, length, flown = _refine(aim, target_final, items, seqs, home,
                                       targets_m, verify_miss_m, airframe, heading, stored, winds,
                                       spread_margin_m, tuning)
    flights += flown
    speeds_final = zone_speeds(s_final, target_final, slow_set) or [math.nan] * len(target_final)
    # Targets still beyond: flown slower from a little before them (the guidance follows
    # tighter turns slower: its L1 distance shrinks with the speed, the turn radius with its
    # square), while that helps.
    if can_slow:
        zones = set(slow_set)
        slow_limit_m = verify_miss_m - tuning.slow_margin_m
        for _ in range(tuning.slow_rounds):
            beyond = [int(t) for t in np.flatnonzero(miss > slow_limit_m)]
            if not beyond or not (set(beyond) - zones):
                break
            trial_zones = zones | set(beyond)
            s_new, target_new, aim_new = with_starts(s_final, target_final, aim, trial_zones)
            speeds = zone_speeds(s_new, target_new, trial_zones)
            if speeds is None:
                break
            items, seqs = _local_items(takeoff, takeoff_alt, head_items, aim_new - home,
                                       waypoint_altitudes_m(path, s_new, target_new),
                                       target_new, target_acceptance_m, loiters, speeds)
            aim2, miss2, length2, flown2 = _refine(aim_new, target_new, items, seqs, home,
                                                   targets_m, verify_miss_m, airframe, heading,
                                                   stored, winds, spread_margin_m, tuning)
            flights += flown2
            if not (_Trial.cost_of(miss2, slow_limit_m).sum()
                    < _Trial.cost_of(miss, slow_limit_m).sum()
                    and _Trial.cost_of(miss2, verify_miss_m).sum()
                    <= _Trial.cost_of(miss, verify_miss_m).sum()):
                break
            zones, speeds_final, aim, miss, length = trial_zones, speeds, aim2, miss2, length2
            s_final, target_final = np.asarray(s_new), target_new
    # Targets still beyond: passed again (plain revisits while they help), then by detours.
    lead_m = tuning.revisit_lead_l1 * l1_m
    kinds = ([0.0] * tuning.revisit_rounds + [lead_m] * tuning.detour_rounds
             if tuning.revisits else [])
    failed = None
    for kind in kinds:
        if kind == failed:
            continue
        beyond = [int(t) for t in np.flatnonzero(miss > verify_miss_m)]
        room = (budget - len(target_final) - _speed_items(speeds_final)) // (1 if kind == 0.0 else 3)
        if not beyond or room <= 0:
            break
        s_new, target_new, aim_new, speeds_new = _with_revisits(
            list(s_final), list(target_final), aim, targets_m, beyond[:room], tuning, stored,
            path.tour_end_s_m, kind, speeds_final)
        items, seqs = _local_items(takeoff, takeoff_alt, head_items, aim_new - home,
                                   waypoint_altitudes_m(path, s_new, target_new), target_new,
                                   target_acceptance_m, loiters, speeds_new)
        aim2, miss2, length2, flown2 = _refine(aim_new, target_new, items, seqs, home, targets_m,
                                               verify_miss_m, airframe, heading, stored, winds,
                                               spread_margin_m, tuning)
        flights += flown2
        if not (_Trial.cost_of(miss2, verify_miss_m).sum() < _Trial.cost_of(miss, verify_miss_m).sum()):
            failed = kind
            continue
        s_final, target_final, aim, miss, length = np.asarray(s_new), target_new, aim2, miss2, length2
        speeds_final = speeds_new
    if progress is not None:
        progress(min(flights, rounds), rounds)
    final, _ = _local_items(takeoff, takeoff_alt, head_items, aim - home,
                            waypoint_altitudes_m(path, s_final, target_final), target_final,
                            target_acceptance_m, loiters, speeds_final)

    def verified(flown: tuple[Airframe, Wind]) -> tuple[np.ndarray, float]:
        """Misses of the final design flown by that aircraft in that wind, and its time from
        the take-off's end."""
        flight = MissionFlight(final, flown[0], heading, 1, flown[1])
        run = flight.run(tuning.verify_step_s, len(final) - 2, points_m=targets_m - home,
                         track=False, measure_from_seq=_AFTER_TAKEOFF, until_s=FLIGHT_LIMIT_S)
        start = dict(flight.reached).get(_AFTER_TAKEOFF - 1, 0.0)
        return run.closest_m, flight.time_s - start
    flown = _each(verified, _conditions(airframe, winds, tuning))
    misses = [miss for miss, _ in flown]
    return GuidanceDesign(np.asarray(s_final), aim, np.asarray(target_final), misses[0], length + skipped_m,
                          design.planned_length_m, flights + len(flown),
                          _judged(misses, spread_margin_m), np.max(misses, axis=0),
                          flown[0][1] + skipped_m / airframe.airspeed_m_s,
                          (np.asarray(speeds_final, dtype=float)
                           if any(math.isfinite(v) for v in speeds_final) else None))
