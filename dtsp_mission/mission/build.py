"""The mission stage composed: from a tour and checked settings (:mod:`.settings`) to the
mission items an autopilot flies -- the flight path, the waypoints (geometric or for the
guidance), the actions at the targets, the storage check, and the turn-margin retry.

Item order: NAV_TAKEOFF (to the end of the climb-out), DO_CHANGE_SPEED (if an airspeed is
given), NAV_WAYPOINTs along the path -- every target one of them, at the target's own
coordinates and with a small acceptance radius, so that "item reached" means "target
overflown" -- then the return: NAV_RETURN_TO_LAUNCH, or DO_LAND_START, the lead-out waypoints,
the approach waypoint and NAV_LAND at home, or nothing.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..errors import DtspError, InputError, MissionTooLarge
from ..frame import LocalFrame
from ..targets import GeoTargets
from ..targets.actions import TargetActions
from ..targets.model import target_name
from ..tour import Tour
from ..vehicle import bearing_to_heading_rad, heading_to_bearing_deg
from ..autopilot.commands import AUTOPILOTS, Command, Frame
from ..autopilot.navigation import Airframe
from ..autopilot.parameters import ARDUPLANE_DEFAULTS
from . import actions as action_items
from .guidance import GuidanceDesign, design_waypoints
from .discretise import waypoint_s
from .flight_path import climb_distance_m, plan_flight_path
from .model import FlightPath, Home, Mission, MissionItem, waypoint
from .settings import PREFERRED_TOLERANCE_FRACTION, MissionSettings, check_altitude_floor

def _fixed_items(settings: MissionSettings, actions: int = 0) -> int:
    """Items that are not waypoints on the path (takeoff, speed, return; ArduPilot's home;
    the ``actions`` at the targets)."""
    return (actions + 1 + (settings.airspeed_m_s is not None)
            + {"rtl": 1, "land": 2, "none": 0}[settings.return_mode]
            + (settings.autopilot == "ardupilot"))


def _path_waypoints(path: FlightPath, rho_m: float, tolerance_m: float) -> np.ndarray:
    """Waypoint arc lengths within ``tolerance_m`` of the path, none on a loiter's circles (a
    loiter item flies them)."""
    chosen = waypoint_s(path.chain, rho_m, path.target_s_m, tolerance_m)
    return chosen[~path.in_loiter(chosen)] if path.loiters else chosen


def _fit_waypoints(path: FlightPath, rho_m: float, settings: MissionSettings,
                   actions: int = 0) -> tuple[np.ndarray, float]:
    """Waypoint arc lengths at the finest tolerance in [preferred, tolerance] that fits the
    item budget, and that tolerance."""
    budget = settings.max_items - _fixed_items(settings, actions) + 1   # the takeoff point is free
    fine = PREFERRED_TOLERANCE_FRACTION * settings.tolerance_m
    chosen = _path_waypoints(path, rho_m, fine)
    if len(chosen) <= budget:
        return chosen, fine
    coarse = _path_waypoints(path, rho_m, settings.tolerance_m)
    if len(coarse) > budget:
        needed = len(coarse) - 1 + _fixed_items(settings, actions)
        raise MissionTooLarge(
            f"the mission needs {needed} items at a waypoint tolerance of "
            f"{settings.tolerance_m:.3g} m but the vehicle holds {settings.max_items} "
            f"(--max-items). Allow more items if the vehicle has the space (ArduPilot with the "
            f"mission on SD card, BRD_SD_MISSION, holds about 4,300), accept a coarser "
            f"--tolerance, or split the targets into several missions", needed, settings.max_items)
    low, high, chosen = fine, settings.tolerance_m, coarse
    for _ in range(12):
        middle = math.sqrt(low * high)
        attempt = _path_waypoints(path, rho_m, middle)
        if len(attempt) <= budget:
            high, chosen = middle, attempt
        else:
            low = middle
    return chosen, high


def _design_for_guidance(path: FlightPath, tour: Tour, frame: LocalFrame, targets: GeoTargets,
                         settings: MissionSettings, actions: int = 0,
                         progress: Callable[[int, int], None] | None = None) -> GuidanceDesign:
    """Waypoints for ArduPlane's guidance (:mod:`.guidance`) within the item budget; the
    lead-out of a landing stays a geometric polyline."""
    parameters = settings.vehicle or ARDUPLANE_DEFAULTS
    airframe = Airframe.from_parameters(parameters, settings.airspeed_m_s)
    tail = _guidance_tail(path, tour, settings, actions)
    budget = settings.max_items - _fixed_items(settings, actions) - len(tail)
    head = ([(Command.DO_CHANGE_SPEED, (0.0, float(settings.airspeed_m_s), -1.0, 0.0))]
            if settings.airspeed_m_s is not None else [])
    altitudes = (np.full(len(tour.targets_m), settings.altitude_m) if targets.altitudes_m is None
                 else np.asarray(targets.altitudes_m, dtype=float))
    altitudes = np.where(np.isnan(altitudes), settings.altitude_m, altitudes)   # not given
    design = design_waypoints(path, tour.targets_m, altitudes, airframe, settings.design_limit_m,
                              budget, head, settings.target_acceptance_m, progress=progress,
                              as_stored=lambda points: stored_position_m(frame, points),
                              winds=settings.design_winds(),
                              spread_margin_m=settings.max_miss_m - settings.design_limit_m,
                              tuning=settings.tuning)
    return replace(design, s_m=np.concatenate([[0.0], design.s_m, tail]),
                   aim_m=np.vstack([path.chain.pose_at(np.array([0.0]))[:, :2], design.aim_m,
                                    path.chain.pose_at(tail)[:, :2].reshape(-1, 2)]),
                   target_of=np.concatenate([[-1], design.target_of, np.full(len(tail), -1)]))


def _guidance_tail(path: FlightPath, tour: Tour, settings: MissionSettings,
                   actions: int) -> np.ndarray:
    """The tail waypoints of a guidance design (:func:`_tail_waypoints`), or
    :class:`MissionTooLarge` if the least it needs -- one waypoint per target, the fixed items,
    the tail -- does not fit ``settings.max_items``."""
    tail = _tail_waypoints(path, tour.rho_m, settings)
    fixed = _fixed_items(settings, actions)
    needed = len(tour.targets_m) + fixed + len(tail)
    if needed > settings.max_items:
        kinds = ["take-off"] + (["speed"] if settings.airspeed_m_s is not None else [])
        kinds += {"rtl": ["return"], "land": ["landing"], "none": []}[settings.return_mode]
        kinds += (["home slot"] if settings.autopilot == "ardupilot" else [])
        kinds += ([f"{actions} actions"] if actions else [])
        parts = [f"{len(tour.targets_m)} for the target(s), one each",
                 f"{fixed} for {', '.join(kinds)}"]
        if len(tail):
            parts.append(f"{len(tail)} to the landing approach")
        raise MissionTooLarge(
            f"the mission needs at least {needed} items ({', '.join(parts)}) but the vehicle holds "
            f"{settings.max_items} (--max-items): allow more if it has the space (ArduPilot with "
            "the mission on SD card holds about 4,300) or split the targets into several "
            "missions", needed, settings.max_items)
    return tail


def stored_position_m(frame: LocalFrame, points_m: np.ndarray) -> np.ndarray:
    """Positions (local frame) moved to where a vehicle stores them: latitude and longitude
    rounded to MISSION_ITEM_INT's 1e-7 degree (about 1 cm)."""
    latitudes, longitudes = frame.to_geodetic(np.asarray(points_m, dtype=float).reshape(-1, 2))
    return frame.to_local(np.round(latitudes * 1e7) / 1e7, np.round(longitudes * 1e7) / 1e7)


def _tail_waypoints(path: FlightPath, rho_m: float, settings: MissionSettings) -> np.ndarray:
    """Arc lengths of the waypoints after the last target (the way to a landing approach)."""
    if settings.return_mode != "land":
        return np.zeros(0)
    chosen = waypoint_s(path.chain, rho_m, path.target_s_m, settings.tolerance_m)
    return chosen[chosen > path.tour_end_s_m + 1e-9]


@dataclass(frozen=True)
class _Prepared:
    """What every mission of a tour starts from: the checked settings (the design the
    autopilot can take), the flight path from take-off to the return, the action items, the
    home and the notes so far."""

    settings: MissionSettings
    path: FlightPath
    at_targets: "_AtTargets"
    home_deg: tuple[float, float]
    home_m: np.ndarray
    notes: list[str]


def _prepare(tour: Tour, frame: LocalFrame, targets: GeoTargets,
             settings: MissionSettings) -> _Prepared:
    settings = settings.checked(tour.rho_m)
    notes: list[str] = []
    if settings.home_deg is None:
        home_lat, home_lon = frame.origin_lat_deg, frame.origin_lon_deg
        notes.append(f"home (launch) not given: using the centre of the targets "
                     f"({home_lat:.7f}, {home_lon:.7f})")
    else:
        home_lat, home_lon = settings.home_deg
        frame.check_extent(home_lat, home_lon, "targets and home")
    home_m = frame.to_local(home_lat, home_lon)[0]
    if settings.autopilot == "px4" and settings.return_mode != "land":
        notes.append("PX4 refuses to start a fixed-wing mission without a landing unless "
                     "MIS_TKO_LAND_REQ allows it; consider --return land")
    launch = (None if settings.launch_bearing_deg is None
              else bearing_to_heading_rad(settings.launch_bearing_deg))
    landing = (None if settings.landing_bearing_deg is None
               else bearing_to_heading_rad(settings.landing_bearing_deg))
    altitudes = targets.altitudes_m
    if altitudes is not None:       # NaN: not given in the targets file, the mission's altitude
        altitudes = np.where(np.isnan(altitudes), settings.altitude_m, altitudes)
        check_altitude_floor(targets, settings)
    actions = _actions(targets, settings)
    radius = action_items.loiter_radius_m(tour.rho_m, settings.loiter_radius_m)  # >= rho: checked
    loiters = {int(t): (int(actions.loiter_turns[t]), radius)
               for t in np.flatnonzero(actions.loiter_turns)}
    if loiters and settings.autopilot == "px4" and settings.airspeed_m_s is None:
        raise InputError("a PX4 loiter is given in seconds (NAV_LOITER_TIME): give the airspeed "
                         "(--airspeed) so that the turns can be timed")
    path = plan_flight_path(tour, home_m, settings.altitude_m, settings.return_mode, launch,
                            landing, altitudes, loiters)
    at_targets = _action_items(path, frame, targets, actions, settings)
    notes += _steep_steps(path, targets, settings)
    launch_heading = path.chain.starts[0, 2]
    if settings.launch_bearing_deg is None:
        notes.append(f"launch bearing not given: towards the first target "
                     f"({heading_to_bearing_deg(launch_heading):.0f} deg)")
    if settings.design == "guidance" and settings.autopilot != "ardupilot":
        notes.append("waypoints placed by geometry: the guidance design predicts ArduPlane's "
                     "navigation, and PX4's is not modelled")
        settings = replace(settings, design="geometry")
    return _Prepared(settings, path, at_targets, (home_lat, home_lon), home_m, notes)


def _steep_steps(path: FlightPath, targets: GeoTargets, settings: MissionSettings) -> list[str]:
    """Warnings for altitude changes between targets steeper than the aircraft climbs or
    sinks at its airspeed (TECS_CLMB_MAX, TECS_SINK_MAX): it reaches such a target off its
    altitude."""
    vehicle = settings.vehicle or ARDUPLANE_DEFAULTS
    airspeed = settings.airspeed_m_s or vehicle.AIRSPEED_CRUISE
    knots_s, knots_alt = path.altitudes_at_s
    steps = np.diff(knots_alt)
    runs = np.maximum(np.diff(knots_s), 1e-9)
    rates = steps / runs * airspeed               # m/s of climb (+) or sink (-) the step needs
    limit = np.where(steps > 0, vehicle.TECS_CLMB_MAX, vehicle.TECS_SINK_MAX)
    steep = np.flatnonzero((np.abs(rates) > limit * (1 + 1e-9)) & (np.abs(steps) > 1.0))
    if not len(steep):
        return []
    k = int(steep[0])
    target_at = {float(s): t for t, s in enumerate(path.target_s_m)}
    where = target_at.get(float(knots_s[k + 1]))
    label = targets.label(where) if where is not None else "the landing approach"
    verb, name = ("climb", "TECS_CLMB_MAX") if steps[k] > 0 else ("descent", "TECS_SINK_MAX")
    return [f"warning: {len(steep)} altitude step(s) steeper than the aircraft climbs or sinks "
            f"at {airspeed:g} m/s; first, to {label}: a {verb} of {abs(steps[k]):.0f} m in "
            f"{runs[k]:.0f} m of flight needs {abs(rates[k]):.1f} m/s ({name} "
            f"{float(limit[k]):g} m/s): the aircraft reaches it off its altitude"]


def check_storage(tour: Tour, frame: LocalFrame, targets: GeoTargets,
                  settings: MissionSettings) -> None:
    """Raises :class:`MissionTooLarge` if no mission that :func:`build_mission` could make of
    ``tour`` fits ``settings.max_items``: the guidance design needs at least one waypoint per
    target, the geometric one its waypoints at ``--tolerance``.  Designs and predicts nothing
    (milliseconds where :func:`build_mission` flies the mission for minutes)."""
    prepared = _prepare(tour, frame, targets, settings)
    settings, path, count = prepared.settings, prepared.path, prepared.at_targets.count
    if settings.design == "guidance":
        _guidance_tail(path, tour, settings, count)
    else:
        _fit_waypoints(path, tour.rho_m, settings, count)


def build_mission(tour: Tour, frame: LocalFrame, targets: GeoTargets,
                  settings: MissionSettings,
                  progress: Callable[[int, int], None] | None = None) -> Mission:
    """The mission that flies ``tour`` (planned in ``frame``) from take-off to the return.

    Guarantees: the waypoint polyline stays within the reported tolerance of the exact flight
    path; every target is one NAV_WAYPOINT at its own coordinates; the item count fits
    ``max_items`` (with ArduPilot's home slot) or :class:`InputError` says how many are needed.
    ``progress(flights, rounds)`` follows the guidance design's predicted flights.
    """
    prepared = _prepare(tour, frame, targets, settings)
    settings, path, at_targets, notes = (prepared.settings, prepared.path, prepared.at_targets,
                                         prepared.notes)
    (home_lat, home_lon), home_m = prepared.home_deg, prepared.home_m
    design = None
    if settings.design == "guidance":
        design = _design_for_guidance(path, tour, frame, targets, settings, at_targets.count,
                                      progress)
        chosen, tolerance = design.s_m, float("nan")
        judged = design.judged_miss_m
        held = judged <= settings.design_limit_m
        if not held.all():
            worst = np.argsort(-judged)[: int((~held).sum())]
            listed = ", ".join(f"{target_name(targets.names, i)} ({judged[i]:.1f} m)"
                               for i in worst[:8])
            more = f" and {len(worst) - 8} more" if len(worst) > 8 else ""
            notes.append(f"{int((~held).sum())} of {len(held)} targets are predicted beyond "
                         f"{settings.design_limit_m:g} m (--max-miss {settings.max_miss_m:g} m "
                         f"less the model's margin of {settings.max_miss_m - settings.design_limit_m:g} m) "
                         f"in the forecast wind, or beyond --max-miss in the others: "
                         f"{listed}{more}")
    else:
        chosen, tolerance = _fit_waypoints(path, tour.rho_m, settings, at_targets.count)
        if tolerance > PREFERRED_TOLERANCE_FRACTION * settings.tolerance_m:
            notes.append(f"waypoints coarsened to a tolerance of {tolerance:.3g} m to fit "
                         f"{settings.max_items} mission slots")
    items = at_targets.inserted(_items(path, chosen, frame, targets, settings, home_lat, home_lon,
                                       design))
    summary = _summary(tour, path, items, settings, home_m)
    if at_targets.count:
        counts = Counter(item.role for item in items)
        summary["actions"] = {role: counts[role] for role in ("photo", "roi", "gimbal", "loiter")
                              if counts[role]}
    if design is not None:
        summary.update(predicted_miss_m=design.predicted_miss_m.tolist(),
                       judged_miss_m=design.judged_miss_m.tolist(),
                       worst_wind_miss_m=design.worst_miss_m.tolist(),
                       predicted_flight_m=design.predicted_length_m,
                       planned_flight_m=design.planned_length_m,
                       shaping_waypoints=sum(i.role == "shaping" for i in items),
                       design_rounds=design.rounds,
                       design_wind={"speed_m_s": settings.wind.speed_m_s,
                                    "from_deg": settings.wind.from_deg,
                                    "spread_m_s": settings.wind_spread_m_s},
                       design_winds=[[w.speed_m_s, w.from_deg] for w in settings.design_winds()],
                       design_limit_m=settings.design_limit_m)
    autopilot = AUTOPILOTS[settings.autopilot]
    mission = Mission(tuple(items), Home(home_lat, home_lon, settings.home_altitude_amsl_m),
                      autopilot, settings.airspeed_m_s, tour.rho_m, tolerance, frame, tour, path,
                      targets.names, tuple(notes), summary,
                      (np.asarray(targets.latitudes_deg), np.asarray(targets.longitudes_deg)))
    summary["vehicle_slots"] = mission.vehicle_item_count()
    return mission


def _actions(targets: GeoTargets, settings: MissionSettings) -> TargetActions:
    """The targets' own actions with the settings' for every target added."""
    base = targets.actions if targets.actions is not None else TargetActions.none(len(targets))
    return base.with_options(settings.photo, settings.roi, settings.gimbal_pitch_deg)


@dataclass(frozen=True)
class _AtTargets:
    """The action items of a mission: ``before[t]`` go after the previous target's items (the
    leg to ``t``), ``after[t]`` after ``t``'s waypoint, ``end`` after the last target's."""

    before: dict[int, list[MissionItem]]
    after: dict[int, list[MissionItem]]
    end: list[MissionItem]
    first: int                      # the first target visited
    next_of: dict[int, int]         # target -> the one visited after it

    @property
    def count(self) -> int:
        return (sum(map(len, self.before.values())) + sum(map(len, self.after.values()))
                + len(self.end))

    def inserted(self, items: list[MissionItem]) -> list[MissionItem]:
        """``items`` (take-off, waypoints, return) with the action items in their places."""
        if not self.count:
            return items
        out: list[MissionItem] = []
        started = False
        visited = 0
        total = sum(item.role == "target" for item in items)
        for item in items:
            if not started and item.command == Command.NAV_WAYPOINT:
                out += self.before.get(self.first, [])
                started = True
            out.append(item)
            if item.role == "target":
                visited += 1
                out += self.after.get(item.target, [])
                following = self.next_of.get(item.target)
                if following is not None:
                    out += self.before.get(following, [])
                if visited == total:
                    out += self.end
        return out


def _action_items(path: FlightPath, frame: LocalFrame, targets: GeoTargets,
                  actions: TargetActions, settings: MissionSettings) -> _AtTargets:
    autopilot = AUTOPILOTS[settings.autopilot]
    order = [int(t) for t in np.argsort(path.target_s_m, kind="stable")]
    loiters = {span.target: span for span in path.loiters}
    before: dict[int, list[MissionItem]] = {}
    after: dict[int, list[MissionItem]] = {}
    pitch_now = math.nan
    for t in order:
        leg: list[MissionItem] = []
        if actions.roi[t]:
            leg.append(action_items.roi_item(autopilot, targets.latitudes_deg[t],
                                             targets.longitudes_deg[t], t))
        pitch = actions.gimbal_pitch_deg[t]
        if not math.isnan(pitch) and pitch != pitch_now:
            leg.append(action_items.gimbal_item(autopilot, float(pitch), t))
            pitch_now = pitch
        if leg:
            before[t] = leg
        at: list[MissionItem] = []
        if actions.photo[t]:
            at.append(action_items.photo_item(autopilot, t))
        if t in loiters:
            span = loiters[t]
            latitude, longitude = frame.to_geodetic(span.centre_m.reshape(1, 2))
            altitude = float(path.altitude_m(np.array([span.start_s_m]))[0])
            at.append(action_items.loiter_item(autopilot, (float(latitude[0]), float(longitude[0])),
                                               altitude, span.radius_m, span.clockwise, span.turns,
                                               settings.airspeed_m_s, t))
        if at:
            after[t] = at
    end = [action_items.roi_off_item(autopilot)] if actions.roi.any() else []
    return _AtTargets(before, after, end, order[0] if order else -1, dict(zip(order, order[1:])))


def _items(path: FlightPath, chosen: np.ndarray, frame: LocalFrame, targets: GeoTargets,
           settings: MissionSettings, home_lat: float, home_lon: float,
           design: GuidanceDesign | None = None) -> list[MissionItem]:
    """The items; with a guidance ``design``, its aim points stand for the targets (where the
    autopilot must be sent to pass over them) and its shaping waypoints are plain waypoints."""
    points = path.chain.pose_at(chosen)[:, :2] if design is None else design.aim_m
    latitudes, longitudes = frame.to_geodetic(points)
    altitudes = path.altitude_m(chosen)
    if design is None:
        target_at = {float(s): index for index, s in enumerate(path.target_s_m)}
    else:
        target_at = {k: int(t) for k, t in enumerate(design.target_of) if t >= 0}
    items = [MissionItem(Command.NAV_TAKEOFF, Frame.GLOBAL_RELATIVE_ALT,
                         (float(settings.takeoff_pitch_deg), 0.0, 0.0, 0.0), float(latitudes[0]),
                         float(longitudes[0]), float(settings.altitude_m), True, "takeoff")]
    if settings.airspeed_m_s is not None:
        items.append(MissionItem(Command.DO_CHANGE_SPEED, Frame.MISSION,
                                 (0.0, float(settings.airspeed_m_s), -1.0, 0.0), role="speed"))
    for k in range(1, len(chosen)):
        s = float(chosen[k])
        if design is not None and k in target_at:
            index = target_at[k]
            items.append(waypoint(latitudes[k], longitudes[k], altitudes[k], "target", index,
                                  settings.target_acceptance_m))
        elif design is None and s in target_at:
            index = target_at[s]
            items.append(waypoint(targets.latitudes_deg[index], targets.longitudes_deg[index],
                                  altitudes[k], "target", index, settings.target_acceptance_m))
        elif design is not None and s <= path.tour_end_s_m:
            items.append(waypoint(latitudes[k], longitudes[k], altitudes[k], "shaping"))
        elif settings.return_mode == "land" and k == len(chosen) - 1:
            items.append(waypoint(latitudes[k], longitudes[k], path.altitudes_at_s[1][-1],
                                  "approach"))
        else:
            items.append(waypoint(latitudes[k], longitudes[k], altitudes[k]))
        if settings.return_mode == "land" and s == path.tour_end_s_m:
            items.append(MissionItem(Command.DO_LAND_START, Frame.MISSION, (0.0, 0.0, 0.0, 0.0),
                                     role="land_start"))
    if settings.return_mode == "rtl":
        items.append(MissionItem(Command.NAV_RETURN_TO_LAUNCH, Frame.MISSION,
                                 (0.0, 0.0, 0.0, 0.0), role="return"))
    elif settings.return_mode == "land":
        items.append(MissionItem(Command.NAV_LAND, Frame.GLOBAL_RELATIVE_ALT, (0.0, 0.0, 0.0, 0.0),
                                 home_lat, home_lon, 0.0, True, "land"))
    return items


def targets_beyond(mission: Mission, limit_m: float | None = None) -> int:
    """How many targets a guidance-designed mission does not hold: by default those judged
    beyond its design limit (--max-miss less the model's margin in the forecast wind, or
    beyond --max-miss in the other design winds); with ``limit_m``, those predicted beyond it
    in the forecast wind."""
    summary = mission.summary
    if limit_m is None:
        return sum(m > summary.get("design_limit_m", math.inf)
                   for m in summary.get("judged_miss_m", ()))
    return sum(m > limit_m for m in summary.get("predicted_miss_m", ()))


def length_excess(mission: Mission) -> float:
    """How much longer a guidance-designed mission's predicted flight is than the planned one
    over the same span (a fraction: 0.05 is 5 % longer)."""
    return mission.summary["predicted_flight_m"] / mission.summary["planned_flight_m"] - 1.0


def with_turn_margin(mission: Mission, replan: Callable[[float], Tour], targets: GeoTargets,
                     settings: MissionSettings,
                     progress: Callable[[int], Callable[[int, int], None]] | None = None) -> Mission:
    """``mission`` (guidance design) if it holds every target, else the best of it and the
    missions of tours planned with wider turn radii (``replan(rho)``,
    ``settings.tuning.guidance_margins``, tried in turn until one holds every target): the fewest targets
    beyond the design limit, then the shortest predicted flight -- flight time is what the
    operator pays for; how closely a flight follows its plan is only reported.
    ``progress(k)`` gives the progress callback of the k-th design tried (``mission``'s was the
    0th)."""
    def key(candidate: Mission) -> tuple[int, float]:
        return targets_beyond(candidate), candidate.summary["predicted_flight_m"]
    best = mission
    for index, factor in enumerate(settings.tuning.guidance_margins):
        if key(best)[0] == 0:
            break
        try:
            candidate = build_mission(replan(mission.rho_m * factor), mission.frame, targets,
                                      settings, None if progress is None else progress(index + 1))
        except DtspError:
            continue
        if key(candidate) < key(best):
            best = candidate
    return best


def _summary(tour: Tour, path: FlightPath, items: list[MissionItem],
             settings: MissionSettings, home_m: np.ndarray) -> dict:
    """Lengths and times a user wants before flying (distances in metres, times in seconds)."""
    climb = climb_distance_m(settings.altitude_m)
    flown = climb + path.chain.length_m
    if settings.return_mode != "none":    # straight home (RTL) or down the approach (land)
        flown += float(np.hypot(*(path.chain.ends()[-1, :2] - home_m)))
    summary = {"targets": len(tour.targets_m), "tour_length_m": tour.length_m,
               "path_length_m": path.chain.length_m, "flight_length_m": flown,
               "items": len(items), "waypoints": sum(i.command == Command.NAV_WAYPOINT for i in items)}
    if settings.airspeed_m_s is not None:
        summary["flight_time_s"] = flown / settings.airspeed_m_s
    return summary
