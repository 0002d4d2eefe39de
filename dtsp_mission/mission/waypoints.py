"""The tour's flight path turned into waypoints: the polyline within a tolerance of the exact
path (the geometric design, coarsened to fit the vehicle), or the waypoints aimed for the
autopilot's guidance (:mod:`.guidance`); and the least each needs of the vehicle's storage.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Callable

import numpy as np

from ..errors import MissionTooLarge
from ..frame import LocalFrame
from ..targets import GeoTargets
from ..tour import Tour
from ..autopilot.commands import Command
from ..planning.lead_ins import with_lead_ins
from .discretise import waypoint_s
from .guidance import DesignTuning, GuidanceDesign, design_waypoints, revisited
from .model import FlightPath
from .settings import PREFERRED_TOLERANCE_FRACTION, MissionSettings


def fixed_items(settings: MissionSettings, actions: int = 0) -> int:
    """Items that are not waypoints on the path (takeoff, speed, return; ArduPilot's home;
    the ``actions`` at the targets)."""
    return (actions + 1 + (settings.airspeed_m_s is not None)
            + {"rtl": 1, "land": 2, "none": 0}[settings.return_mode]
            + (settings.autopilot == "ardupilot"))


def path_waypoints(path: FlightPath, rho_m: float, tolerance_m: float) -> np.ndarray:
    """Waypoint arc lengths within ``tolerance_m`` of the path, none on a loiter's circles (a
    loiter item flies them)."""
    chosen = waypoint_s(path.chain, rho_m, path.target_s_m, tolerance_m)
    return chosen[~path.in_loiter(chosen)] if path.loiters else chosen


def fit_waypoints(path: FlightPath, rho_m: float, settings: MissionSettings,
                   actions: int = 0) -> tuple[np.ndarray, float]:
    """Waypoint arc lengths at the finest tolerance in [preferred, tolerance] that fits the
    item budget, and that tolerance."""
    budget = settings.max_items - fixed_items(settings, actions) + 1   # the takeoff point is free
    fine = PREFERRED_TOLERANCE_FRACTION * settings.tolerance_m
    chosen = path_waypoints(path, rho_m, fine)
    if len(chosen) <= budget:
        return chosen, fine
    coarse = path_waypoints(path, rho_m, settings.tolerance_m)
    if len(coarse) > budget:
        needed = len(coarse) - 1 + fixed_items(settings, actions)
        raise MissionTooLarge(
            f"the mission needs {needed} items at a waypoint tolerance of "
            f"{settings.tolerance_m:.3g} m but the vehicle holds {settings.max_items} "
            f"(`max_items`). Allow more items if the vehicle has the space (ArduPilot with the "
            f"mission on SD card, BRD_SD_MISSION, holds about 4,300), accept a coarser "
            f"`tolerance_m`, or split the targets into several missions", needed, settings.max_items)
    low, high, chosen = fine, settings.tolerance_m, coarse
    for _ in range(12):
        middle = math.sqrt(low * high)
        attempt = path_waypoints(path, rho_m, middle)
        if len(attempt) <= budget:
            high, chosen = middle, attempt
        else:
            low = middle
    return chosen, high


def design_for_guidance(path: FlightPath, tour: Tour, frame: LocalFrame, targets: GeoTargets,
                         settings: MissionSettings, actions: int = 0,
                         progress: Callable[[int, int], None] | None = None,
                         path_of: Callable[[Tour], FlightPath] | None = None
                         ) -> tuple[GuidanceDesign, FlightPath, Tour]:
    """Waypoints for the autopilot's guidance (:mod:`.guidance`, flying
    :meth:`MissionSettings.design_airframe`) within the item budget; the lead-out of a landing
    stays a geometric polyline.  Returned with the path and tour they fly: ``tour`` itself, or
    with ``DesignTuning.stuck_lead_in_l1`` (and ``path_of``, the flight path of a tour), in a
    forecast wind, the tour with straight lead-ins before the targets the design passes twice
    where that design holds as many targets in a shorter predicted flight."""
    airframe = settings.design_airframe()
    head = ([(Command.DO_CHANGE_SPEED, (0.0, float(settings.airspeed_m_s), -1.0, 0.0))]
            if settings.airspeed_m_s is not None else [])
    altitudes = (np.full(len(tour.targets_m), settings.altitude_m) if targets.altitudes_m is None
                 else np.asarray(targets.altitudes_m, dtype=float))
    altitudes = np.where(np.isnan(altitudes), settings.altitude_m, altitudes)   # not given

    def designed(tuning: DesignTuning, slow_targets: tuple[int, ...] = ()) -> GuidanceDesign:
        """The design of ``path`` (of ``tour``) as they are when called."""
        budget = (settings.max_items - fixed_items(settings, actions)
                  - len(guidance_tail(path, tour, settings, actions)))
        lead_s_m = lead_in_starts_m(path, tour)
        return design_waypoints(path, tour.targets_m, altitudes, airframe, settings.design_limit_m,
                                budget, head, settings.target_acceptance_m, progress=progress,
                                as_stored=lambda points: stored_position_m(frame, points),
                                winds=settings.design_winds(),
                                spread_margin_m=settings.max_miss_m - settings.design_limit_m,
                                tuning=tuning, lead_s_m=lead_s_m,
                                slow_targets=slow_targets)
    tuning = settings.tuning
    if tuning.slow_rounds > 0 and tuning.slow_from_start:
        # The targets the design at the airspeed cannot hold are flown slower from the
        # start of a second design: its repair aims every waypoint for the speed it is flown
        # at.  (Starting it from the first design's waypoints and aims was measured: bundled
        # site 28.6 km instead of 25.1 km, no faster.)
        def slowed() -> GuidanceDesign:
            """The design of the path as it is, slowing for what a first design cannot hold."""
            first = designed(replace(tuning, revisits=False, slow_rounds=0,
                                     refine_passes=min(tuning.refine_passes,
                                                       tuning.slow_first_refine_passes)))
            stuck = tuple(int(t) for t in np.flatnonzero(
                first.judged_miss_m > settings.design_limit_m - tuning.slow_margin_m))
            return designed(tuning, stuck) if stuck else first
        design = slowed()
        passed_again = {revisited(int(marker)) for marker in design.target_of} - {-1}
        held_again = sorted(passed_again | set(np.flatnonzero(
            design.judged_miss_m > settings.design_limit_m).tolist()))
        if (held_again and tuning.stuck_lead_in_l1 and path_of is not None
                and settings.wind.speed_m_s > 0):
            # In a forecast wind the targets passed twice (or not held) are entered along a
            # straight planned into the tour instead, and that tour designed: kept if it holds
            # as many targets in a shorter predicted flight (docs/design-time.md).
            fastest = airframe.airspeed_m_s + settings.wind.speed_m_s
            lead_m = tuning.stuck_lead_in_l1 * airframe.l1_distance_m(fastest)
            led_tour = with_lead_ins(tour, {int(t): lead_m for t in held_again})
            plain = (path, tour)
            path, tour = path_of(led_tour), led_tour
            led = slowed()
            if (_beyond(led, settings.design_limit_m), led.predicted_time_s) < (
                    _beyond(design, settings.design_limit_m), design.predicted_time_s):
                design = led
            else:
                path, tour = plain
    else:
        design = designed(tuning)
    tail = guidance_tail(path, tour, settings, actions)
    return replace(design, s_m=np.concatenate([[0.0], design.s_m, tail]),
                   aim_m=np.vstack([path.chain.pose_at(np.array([0.0]))[:, :2], design.aim_m,
                                    path.chain.pose_at(tail)[:, :2].reshape(-1, 2)]),
                   target_of=np.concatenate([[-1], design.target_of, np.full(len(tail), -1)]),
                   speed_before_m_s=(None if design.speed_before_m_s is None else np.concatenate(
                       [[np.nan], design.speed_before_m_s, np.full(len(tail), np.nan)]))), path, tour


def _beyond(design: GuidanceDesign, limit_m: float) -> int:
    return int((design.judged_miss_m > limit_m).sum())


def lead_in_starts_m(path: FlightPath, tour: Tour) -> np.ndarray:
    """Arc lengths on ``path`` where the straight lead-ins the tour plans before its targets
    begin (:attr:`Tour.lead_in_m`), for the targets the path reaches by the tour (the first
    is reached from the climb-out instead)."""
    if tour.lead_in_m is None:
        return np.zeros(0)
    led = np.flatnonzero(tour.lead_in_m > 0.0)
    starts = path.target_s_m[led] - tour.lead_in_m[led]
    return np.sort(starts[starts > path.tour_start_s_m + 1e-6])


def guidance_tail(path: FlightPath, tour: Tour, settings: MissionSettings,
                   actions: int) -> np.ndarray:
    """The tail waypoints of a guidance design (:func:`tail_waypoints`), or
    :class:`MissionTooLarge` if the least it needs -- one waypoint per target, the fixed items,
    the tail -- does not fit ``settings.max_items``."""
    tail = tail_waypoints(path, tour.rho_m, settings)
    fixed = fixed_items(settings, actions)
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
            f"{settings.max_items} (`max_items`): allow more if it has the space (ArduPilot with "
            "the mission on SD card holds about 4,300) or split the targets into several "
            "missions", needed, settings.max_items)
    return tail


def stored_position_m(frame: LocalFrame, points_m: np.ndarray) -> np.ndarray:
    """Positions (local frame) moved to where a vehicle stores them: latitude and longitude
    rounded to MISSION_ITEM_INT's 1e-7 degree (about 1 cm)."""
    latitudes, longitudes = frame.to_geodetic(np.asarray(points_m, dtype=float).reshape(-1, 2))
    return frame.to_local(np.round(latitudes * 1e7) / 1e7, np.round(longitudes * 1e7) / 1e7)


def tail_waypoints(path: FlightPath, rho_m: float, settings: MissionSettings) -> np.ndarray:
    """Arc lengths of the waypoints after the last target (the way to a landing approach)."""
    if settings.return_mode != "land":
        return np.zeros(0)
    chosen = waypoint_s(path.chain, rho_m, path.target_s_m, settings.tolerance_m)
    return chosen[chosen > path.tour_end_s_m + 1e-9]
