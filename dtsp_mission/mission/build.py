"""The mission stage composed: from a tour and settings to the mission items an autopilot
flies, each step once -- the settings checked (:mod:`.settings`), the flight path
(:mod:`.flight_path`), the waypoints (:mod:`.waypoints`: geometric, or for the guidance), the
actions placed (:mod:`.placement`), the items (:mod:`.items`) within the vehicle's storage.
Wider turns where the guidance cannot hold the tour are :mod:`.widening`, a stage of its own.

Item order: NAV_TAKEOFF (to the end of the climb-out), DO_CHANGE_SPEED (if an airspeed is
given), NAV_WAYPOINTs along the path -- every target one of them, at the target's own
coordinates and with a small acceptance radius, so that "item reached" means "target
overflown" -- then the return: NAV_RETURN_TO_LAUNCH, or DO_LAND_START, the lead-out waypoints,
the approach waypoint and NAV_LAND at home, or nothing.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError
from ..frame import LocalFrame
from ..targets import GeoTargets
from ..targets.model import target_name
from ..tour import Tour
from ..vehicle import bearing_to_heading_rad, heading_to_bearing_deg
from ..autopilot.commands import AUTOPILOTS, Command
from ..autopilot.parameters import parameters_of
from . import actions as action_items
from .flight_path import climb_distance_m, plan_flight_path
from .guidance import GuidanceDesign
from .items import mission_items
from .model import FlightPath, GuidancePrediction, Home, Mission, MissionItem
from .placement import AtTargets, action_items_of, target_actions
from .settings import PREFERRED_TOLERANCE_FRACTION, MissionSettings, check_altitude_floor
from .waypoints import design_for_guidance, fit_waypoints, guidance_tail


@dataclass(frozen=True)
class _Prepared:
    """What every mission of a tour starts from: the checked settings (the design the
    autopilot can take), the flight path from take-off to the return, the action items, the
    home and the notes so far."""

    settings: MissionSettings
    path: FlightPath
    at_targets: AtTargets
    home_deg: tuple[float, float]
    home_m: np.ndarray
    notes: list[str]


def _px4_top_speed(asked_m_s: float, airframe, max_m_s: float) -> list[str]:
    """A note when PX4 will fly slower than the airspeed asked: it flies no faster than
    ``FW_AIRSPD_MAX``, and PX4 SITL's SIH plane no faster than its own top speed (13.9 m/s
    true); the design is made for the speed flown, and the operator is told which."""
    flown = airframe.airspeed_m_s / airframe.airspeed_ratio      # as asked (indicated)
    if asked_m_s <= flown + 0.05:
        return []
    why = (f"its FW_AIRSPD_MAX ({max_m_s:g} m/s)" if asked_m_s > max_m_s and flown >= max_m_s - 0.05
           else f"PX4 SITL's SIH plane flies no faster than {airframe.airspeed_m_s:.1f} m/s true "
                "airspeed")
    return [f"asked {asked_m_s:g} m/s, PX4 will fly {flown:.1f} m/s ({why}): the mission is "
            "designed for the speed it flies"]


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
    airframe = settings.design_airframe()
    if settings.autopilot == "px4" and settings.airspeed_m_s is not None:
        notes += _px4_top_speed(settings.airspeed_m_s, airframe,
                                parameters_of("px4", settings.vehicle).FW_AIRSPD_MAX)
    if settings.autopilot == "px4" and settings.return_mode != "land":
        notes.append("PX4 refuses to start a fixed-wing mission without a landing unless "
                     "MIS_TKO_LAND_REQ allows it; consider `return_mode` land")
    launch = (None if settings.launch_bearing_deg is None
              else bearing_to_heading_rad(settings.launch_bearing_deg))
    landing = (None if settings.landing_bearing_deg is None
               else bearing_to_heading_rad(settings.landing_bearing_deg))
    altitudes = targets.altitudes_m
    if altitudes is not None:       # NaN: not given in the targets file, the mission's altitude
        altitudes = np.where(np.isnan(altitudes), settings.altitude_m, altitudes)
        check_altitude_floor(targets, settings)
    actions = target_actions(targets, settings)
    radius = action_items.loiter_radius_m(tour.rho_m, settings.loiter_radius_m)  # >= rho: checked
    loiters = {int(t): (int(actions.loiter_turns[t]), radius)
               for t in np.flatnonzero(actions.loiter_turns)}
    if loiters and settings.autopilot == "px4" and settings.airspeed_m_s is None:
        raise InputError("a PX4 loiter is given in seconds (NAV_LOITER_TIME): give the airspeed "
                         "(`airspeed_m_s`) so that the turns can be timed")
    # the first target beyond the climb-out and two L1 distances of settling after it
    settle = 2.0 * airframe.l1_distance_m(airframe.airspeed_m_s)
    path = plan_flight_path(tour, home_m, settings.altitude_m, settings.return_mode, launch,
                            landing, altitudes, loiters, settle)
    at_targets = action_items_of(path, frame, targets, actions, settings)
    notes += _steep_steps(path, targets, settings)
    launch_heading = path.chain.starts[0, 2]
    if settings.launch_bearing_deg is None:
        notes.append(f"launch bearing not given: towards the first target "
                     f"({heading_to_bearing_deg(launch_heading):.0f} deg)")
    return _Prepared(settings, path, at_targets, (home_lat, home_lon), home_m, notes)


def _steep_steps(path: FlightPath, targets: GeoTargets, settings: MissionSettings) -> list[str]:
    """Warnings for altitude changes between targets steeper than the aircraft climbs or
    sinks at its airspeed (TECS_CLMB_MAX, TECS_SINK_MAX): it reaches such a target off its
    altitude."""
    vehicle = parameters_of("ardupilot", settings.vehicle)
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
    target, the geometric one its waypoints at ``settings.tolerance_m``.  Designs and predicts nothing
    (milliseconds where :func:`build_mission` flies the mission for minutes)."""
    prepared = _prepare(tour, frame, targets, settings)
    settings, path, count = prepared.settings, prepared.path, prepared.at_targets.count
    if settings.design == "guidance":
        guidance_tail(path, tour, settings, count)
    else:
        fit_waypoints(path, tour.rho_m, settings, count)


def build_mission(tour: Tour, frame: LocalFrame, targets: GeoTargets,
                  settings: MissionSettings,
                  progress: Callable[[int, int], None] | None = None) -> Mission:
    """The mission that flies ``tour`` (planned in ``frame``) from take-off to the return.

    Guarantees: the waypoint polyline stays within the reported tolerance of the exact flight
    path; every target is one NAV_WAYPOINT at its own coordinates; the item count fits
    ``max_items`` (with ArduPilot's home slot) or :class:`InputError` says how many are needed.
    ``progress(flights, rounds)`` follows the guidance design's predicted flights.
    """
    prepared, given = _prepare(tour, frame, targets, settings), settings
    settings, path, at_targets, notes = (prepared.settings, prepared.path, prepared.at_targets,
                                         prepared.notes)
    (home_lat, home_lon), home_m = prepared.home_deg, prepared.home_m
    design, asked = None, tour
    if settings.design == "guidance":
        tried: list[tuple[Tour, _Prepared]] = []     # the tours with lead-ins, prepared once

        def path_of(led: Tour) -> FlightPath:
            tried.append((led, _prepare(led, frame, targets, given)))
            return tried[-1][1].path
        design, path, tour = design_for_guidance(
            path, tour, frame, targets, settings, at_targets.count, progress, path_of=path_of)
        if tour is not asked:
            at_targets = next(ready for led, ready in tried if led is tour).at_targets
            led = np.flatnonzero(tour.lead_in_m > 0)
            notes.append(f"straight lead-ins planned into the tour before {len(led)} targets "
                         f"the guidance held from it only with second passes: the tour "
                         f"{asked.length_m / 1e3:,.2f} -> {tour.length_m / 1e3:,.2f} km, "
                         f"flown in less time (in the model, the forecast wind)")
        chosen, tolerance = design.s_m, float("nan")
        judged = design.judged_miss_m
        held = judged <= settings.design_limit_m
        if not held.all():
            worst = np.argsort(-judged)[: int((~held).sum())]
            listed = ", ".join(f"{target_name(targets.names, i)} ({judged[i]:.1f} m)"
                               for i in worst[:8])
            more = f" and {len(worst) - 8} more" if len(worst) > 8 else ""
            notes.append(f"{int((~held).sum())} of {len(held)} targets are predicted beyond "
                         f"{settings.design_limit_m:g} m (`max_miss_m` {settings.max_miss_m:g} m "
                         f"less the model's margin of {settings.max_miss_m - settings.design_limit_m:g} m) "
                         f"in the forecast wind, or beyond `max_miss_m` in the others: "
                         f"{listed}{more}")
    else:
        chosen, tolerance = fit_waypoints(path, tour.rho_m, settings, at_targets.count)
        if tolerance > PREFERRED_TOLERANCE_FRACTION * settings.tolerance_m:
            notes.append(f"waypoints coarsened to a tolerance of {tolerance:.3g} m to fit "
                         f"{settings.max_items} mission slots")
    items = at_targets.inserted(mission_items(path, chosen, frame, targets, settings, home_lat, home_lon,
                                       design))
    summary = _summary(tour, path, items, settings, home_m, design)
    if design is not None and tour is not asked:
        # the tour as planned (at the radius asked), and the one the mission flies
        summary.update(tour_length_m=asked.length_m, lead_in_tour_length_m=tour.length_m)
    if at_targets.count:
        counts = Counter(item.role for item in items)
        summary["actions"] = {role: counts[role] for role in ("photo", "roi", "gimbal", "loiter")
                              if counts[role]}
    guidance = None
    if design is not None:
        guidance = GuidancePrediction(
            design.predicted_miss_m, design.judged_miss_m, design.worst_miss_m,
            settings.design_limit_m, design.predicted_length_m, design.planned_length_m,
            sum(i.role == "shaping" for i in items), design.rounds,
            (settings.wind.speed_m_s, settings.wind.from_deg), settings.wind_spread_m_s,
            tuple((w.speed_m_s, w.from_deg) for w in settings.design_winds()),
            sum(i.role == "revisit" for i in items), design.predicted_time_s)
        summary.update(guidance.as_summary())
    autopilot = AUTOPILOTS[settings.autopilot]
    mission = Mission(tuple(items), Home(home_lat, home_lon, settings.home_altitude_amsl_m),
                      autopilot, settings.airspeed_m_s, tour.rho_m, tolerance, frame, tour, path,
                      targets.names, tuple(notes), summary,
                      (np.asarray(targets.latitudes_deg), np.asarray(targets.longitudes_deg)),
                      guidance, parameters_of(settings.autopilot, settings.vehicle))
    summary["vehicle_slots"] = mission.vehicle_item_count()
    return mission


def _summary(tour: Tour, path: FlightPath, items: list[MissionItem],
             settings: MissionSettings, home_m: np.ndarray,
             design: GuidanceDesign | None = None) -> dict:
    """Lengths and times a user wants before flying (distances in metres, times in seconds):
    along the exact path, and for a guidance ``design`` the model's flight from the take-off to
    the last target instead of that part of it (the second passes, the turns the guidance swings
    wide) and its time in the forecast wind, the rest of the flight timed as if all against the
    wind (``flight_time_s``; without a design: the length at the airspeed)."""
    climb = climb_distance_m(settings.altitude_m)
    flown = climb + path.chain.length_m
    if settings.return_mode != "none":    # straight home (RTL) or down the approach (land)
        flown += float(np.hypot(*(path.chain.ends()[-1, :2] - home_m)))
    if design is not None:
        flown += design.predicted_length_m - design.planned_length_m
    summary = {"targets": len(tour.targets_m), "tour_length_m": tour.length_m,
               "path_length_m": path.chain.length_m, "flight_length_m": flown,
               "items": len(items), "waypoints": sum(i.command == Command.NAV_WAYPOINT for i in items)}
    if settings.airspeed_m_s is not None:
        summary["flight_time_s"] = flown / settings.airspeed_m_s
        if design is not None and math.isfinite(design.predicted_time_s):
            # The model's time where it flew; the rest (climb-out, return) against the wind.
            rest_m = flown - design.predicted_length_m
            summary["flight_time_s"] = design.predicted_time_s + rest_m / max(
                settings.airspeed_m_s - settings.wind.speed_m_s, 0.3 * settings.airspeed_m_s)
    return summary
