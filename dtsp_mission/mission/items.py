"""The mission's items from the chosen waypoints: take-off, speed, the waypoints (each target
one of them), the return."""

from __future__ import annotations

import numpy as np

from ..frame import LocalFrame
from ..targets import GeoTargets
from ..autopilot.commands import Command, Frame
from .guidance import GuidanceDesign, revisited, waypoint_altitudes_m
from .model import FlightPath, MissionItem, waypoint
from .settings import MissionSettings


def mission_items(path: FlightPath, chosen: np.ndarray, frame: LocalFrame, targets: GeoTargets,
           settings: MissionSettings, home_lat: float, home_lon: float,
           design: GuidanceDesign | None = None) -> list[MissionItem]:
    """The items; with a guidance ``design``, its aim points stand for the targets (where the
    autopilot must be sent to pass over them) and its shaping waypoints are plain waypoints."""
    points = path.chain.pose_at(chosen)[:, :2] if design is None else design.aim_m
    latitudes, longitudes = frame.to_geodetic(points)
    altitudes = (path.altitude_m(chosen) if design is None
                 else waypoint_altitudes_m(path, chosen, design.target_of))
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
    speeds = None if design is None else design.speed_before_m_s
    for k in range(1, len(chosen)):
        s = float(chosen[k])
        if speeds is not None and np.isfinite(speeds[k]):
            # a slow zone of the guidance design (or its end): ArduPilot and PX4 both act on
            # DO_CHANGE_SPEED as it becomes current, after the waypoint before it
            items.append(MissionItem(Command.DO_CHANGE_SPEED, Frame.MISSION,
                                     (0.0, float(speeds[k]), -1.0, 0.0), role="speed"))
        if design is not None and k in target_at:
            index = target_at[k]
            items.append(waypoint(latitudes[k], longitudes[k], altitudes[k], "target", index,
                                  settings.target_acceptance_m))
        elif design is None and s in target_at:
            index = target_at[s]
            items.append(waypoint(targets.latitudes_deg[index], targets.longitudes_deg[index],
                                  altitudes[k], "target", index, settings.target_acceptance_m))
        elif design is not None and revisited(int(design.target_of[k])) >= 0:
            items.append(waypoint(latitudes[k], longitudes[k], altitudes[k], "revisit",
                                  revisited(int(design.target_of[k])), settings.target_acceptance_m))
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
