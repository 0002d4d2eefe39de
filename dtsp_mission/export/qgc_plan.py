"""QGroundControl ``.plan`` files (JSON), written to pass QGroundControl's loader and MAVSDK's
stricter importer.

The rules those readers enforce (QGroundControl ``PlanMasterController::loadFromFile``,
``MissionController::_loadJsonMissionFileV2``, ``SimpleMissionItem::load``; MAVSDK
``mission_import.cpp``) are written out once, in :func:`plan_rule_violations`; the exporter
checks its own output against them before writing anything.
"""

from __future__ import annotations

import dataclasses
import json
import math
from typing import Any

from ..errors import FileFormatError, TourInvalidError
from ..files import read_json
from ..mission import Autopilot, Home, Mission, MissionItem, VehicleMission
from ..autopilot.mission import MissionTarget, fence_items, rally_items
from ..autopilot.parameters import checked_parameters
from ..autopilot.commands import VEHICLE_TYPE_FIXED_WING
from .base import Exporter

#: QGroundControl's default fixed-wing cruise speed, written when no airspeed is given (QGC
#: only uses it for time estimates).
QGC_DEFAULT_CRUISE_SPEED_M_S = 15.0
#: MAV_TYPE values of vehicles that are no fixed wing (a plan made for one is not flown here).
NOT_FIXED_WING = {2: "a quadrotor", 3: "a coaxial helicopter", 4: "a helicopter",
                  10: "a ground rover", 11: "a surface boat", 12: "a submarine",
                  13: "a hexarotor", 14: "an octorotor", 15: "a tricopter"}
#: globalPlanAltitudeMode 1: altitudes relative to home.
ALTITUDE_MODE_RELATIVE = 1


def plan_dict(mission: Mission) -> dict[str, Any]:
    """The mission as a QGroundControl plan document."""
    items = []
    for number, item in enumerate(mission.items, start=1):
        items.append({
            "type": "SimpleItem",
            "command": int(item.command),
            "frame": int(item.frame),
            "params": [*item.params, item.latitude_deg, item.longitude_deg, item.altitude_m],
            "autoContinue": bool(item.autocontinue),
            "doJumpId": number,
        })
    home = mission.home
    document = {
        "fileType": "Plan",
        "version": 1,
        "groundStation": "dtsp-mission",
        "mission": {
            "version": 2,
            "firmwareType": int(mission.autopilot),
            "vehicleType": VEHICLE_TYPE_FIXED_WING,
            "cruiseSpeed": (mission.cruise_speed_m_s if mission.cruise_speed_m_s is not None
                            else QGC_DEFAULT_CRUISE_SPEED_M_S),
            "hoverSpeed": 5,
            "globalPlanAltitudeMode": ALTITUDE_MODE_RELATIVE,
            "plannedHomePosition": [home.latitude_deg, home.longitude_deg, home.altitude_amsl_m],
            "items": items,
        },
        "geoFence": {"circles": [], "polygons": [], "version": 2},
        "rallyPoints": {"points": [], "version": 2},
    }
    # Readers ignore keys they do not know: the design wind, and the targets themselves (a
    # guidance design aims their waypoints elsewhere), so that a flight of the file is
    # measured against them.
    ours: dict[str, Any] = {"targets": [
        {"name": t.name, "latitude_deg": t.latitude_deg, "longitude_deg": t.longitude_deg,
         **({} if math.isnan(t.altitude_m) else {"altitude_m": t.altitude_m})}
        for t in mission.visited_targets()]}
    if mission.guidance is not None:
        ours["designWind"] = mission.summary["design_wind"]
    if mission.designed_for is not None:
        # the aircraft the items were designed for, so that a flight check of the file flies it
        ours["aircraft"] = {"parameters": {f.name: getattr(mission.designed_for, f.name)
                                           for f in dataclasses.fields(mission.designed_for)}}
    document["dtspMission"] = ours
    return document


def _carried_targets(path, ours: dict) -> tuple[MissionTarget, ...]:
    """The targets a plan's ``dtspMission`` block carries (none if it has none), or
    :class:`FileFormatError` naming the first that is not a named position on the globe."""
    listed = ours.get("targets", [])
    if not isinstance(listed, list):
        raise FileFormatError(f"{path}: dtspMission.targets is not a list")
    targets = []
    for number, entry in enumerate(listed, start=1):
        fields = entry if isinstance(entry, dict) else {}
        lat, lon = fields.get("latitude_deg"), fields.get("longitude_deg")
        altitude = fields.get("altitude_m", math.nan)
        if not (isinstance(fields.get("name"), str) and _is_number(lat) and _is_number(lon)
                and -90 <= lat <= 90 and -180 <= lon <= 180
                and (_is_number(altitude) or altitude is math.nan)):
            raise FileFormatError(f"{path}: dtspMission.targets entry {number} is not a target "
                                  "(a name, latitude_deg in -90..90, longitude_deg in -180..180 "
                                  "and an optional altitude_m)")
        targets.append(MissionTarget(fields["name"], float(lat), float(lon), float(altitude)))
    return tuple(targets)


def _carried_aircraft(path, ours: dict, autopilot: Autopilot):
    """The navigation parameters of the aircraft a plan was designed for (``dtspMission.
    aircraft.parameters``), None if it does not say, :class:`FileFormatError` if it says
    something that is not such parameters."""
    aircraft = ours.get("aircraft")
    if aircraft is None:
        return None
    values = aircraft.get("parameters") if isinstance(aircraft, dict) else None
    if not isinstance(values, dict) or not all(isinstance(k, str) and _is_number(v)
                                               for k, v in values.items()):
        raise FileFormatError(f"{path}: dtspMission.aircraft.parameters is not a set of "
                              "navigation parameters (NAME: number)")
    return checked_parameters(int(autopilot), {k: float(v) for k, v in values.items()},
                              f"{path}: dtspMission.aircraft")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _is_integer(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def plan_rule_violations(data: Any) -> list[str]:
    """Every way ``data`` breaks the loader rules of QGroundControl and MAVSDK (empty if none)."""
    if not isinstance(data, dict):
        return ["the document is not a JSON object"]
    problems = []
    if data.get("fileType") != "Plan":
        problems.append("fileType must be \"Plan\"")
    if data.get("version") != 1:
        problems.append(f"version must be 1 (QGroundControl rejects others), got {data.get('version')!r}")
    if not isinstance(data.get("groundStation"), str):
        problems.append("groundStation must be a string")
    for key in ("mission", "geoFence", "rallyPoints"):
        if not isinstance(data.get(key), dict):
            problems.append(f"{key} must be an object")
    if problems:
        return problems
    mission = data["mission"]
    if mission.get("version") != 2:
        problems.append(f"mission.version must be 2, got {mission.get('version')!r}")
    for key in ("firmwareType", "vehicleType"):
        if not _is_integer(mission.get(key)):
            problems.append(f"mission.{key} must be an integer")
    # optional in QGroundControl's loader (older versions and other tools omit it)
    if "globalPlanAltitudeMode" in mission and not _is_integer(mission["globalPlanAltitudeMode"]):
        problems.append("mission.globalPlanAltitudeMode must be an integer when given")
    if mission.get("vehicleType") in NOT_FIXED_WING:
        problems.append(f"mission.vehicleType {mission['vehicleType']} is "
                        f"{NOT_FIXED_WING[mission['vehicleType']]}: these missions are for "
                        "fixed wings (vehicleType 1)")
    for key in ("cruiseSpeed", "hoverSpeed"):
        if not _is_number(mission.get(key)):
            problems.append(f"mission.{key} must be a number")
    home = mission.get("plannedHomePosition")
    if not (isinstance(home, list) and len(home) == 3 and all(map(_is_number, home))):
        problems.append("mission.plannedHomePosition must be exactly 3 numbers (lat, lon, AMSL alt)")
    items = mission.get("items")
    if not isinstance(items, list):
        problems.append("mission.items must be a list")
        items = []
    for number, item in enumerate(items):
        problems += [f"mission.items[{number}]: {p}" for p in _item_violations(item)]
    fence = data["geoFence"]
    if not (isinstance(fence.get("circles"), list) and isinstance(fence.get("polygons"), list)
            and fence.get("version") == 2):
        problems.append("geoFence must have lists circles and polygons and version 2")
    rally = data["rallyPoints"]
    if not (isinstance(rally.get("points"), list) and rally.get("version") == 2):
        problems.append("rallyPoints must have a list points and version 2")
    return problems


def _item_violations(item: Any) -> list[str]:
    if not isinstance(item, dict):
        return ["not an object"]
    if item.get("type") != "SimpleItem":
        return [f"type must be \"SimpleItem\", got {item.get('type')!r}"]
    problems = []
    for key in ("command", "frame", "doJumpId"):
        if not _is_integer(item.get(key)):
            problems.append(f"{key} must be an integer")
    if not isinstance(item.get("autoContinue"), bool):
        problems.append("autoContinue must be true or false (not 0/1)")
    params = item.get("params")
    if not (isinstance(params, list) and len(params) == 7):
        problems.append("params must be a list of exactly 7 values")
    else:
        if not all(p is None or _is_number(p) for p in params[:4]):
            problems.append("params 1-4 must be numbers or null")
        if not all(_is_number(p) for p in params[4:]):
            problems.append("params 5-7 (lat, lon, alt) must be numbers")
    # QGroundControl writes all three on every item it saves, AMSLAltAboveTerrain null unless
    # the altitude mode is terrain-following (it is the AMSL altitude computed for that mode).
    altitude_keys = [key in item for key in ("AltitudeMode", "Altitude", "AMSLAltAboveTerrain")]
    if any(altitude_keys) and not (
            all(altitude_keys) and _is_integer(item["AltitudeMode"]) and _is_number(item["Altitude"])
            and (item["AMSLAltAboveTerrain"] is None or _is_number(item["AMSLAltAboveTerrain"]))):
        problems.append("AltitudeMode, Altitude and AMSLAltAboveTerrain go together (an integer, "
                        "a number, and a number or null)")
    return problems


def _fence_and_rally(path, data: dict):
    """The plan's geofence and rally points as MAVLink items (:func:`fence_items`,
    :func:`rally_items`); :class:`FileFormatError` for a shape QGroundControl would not load."""
    fence, polygons, circles = data["geoFence"], [], []
    for k, entry in enumerate(fence["polygons"]):
        vertices = entry.get("polygon") if isinstance(entry, dict) else None
        if not (isinstance(vertices, list) and len(vertices) >= 3 and all(
                isinstance(v, list) and len(v) == 2 and all(map(_is_number, v)) for v in vertices)):
            raise FileFormatError(f"{path}: geoFence.polygons[{k}] must hold a 'polygon' of at "
                                  "least 3 [lat, lon] vertices")
        polygons.append((bool(entry.get("inclusion", True)), [tuple(v) for v in vertices]))
    for k, entry in enumerate(fence["circles"]):
        circle = entry.get("circle") if isinstance(entry, dict) else None
        centre = circle.get("center") if isinstance(circle, dict) else None
        radius = circle.get("radius") if isinstance(circle, dict) else None
        if not (isinstance(centre, list) and len(centre) == 2 and all(map(_is_number, centre))
                and _is_number(radius) and radius > 0):
            raise FileFormatError(f"{path}: geoFence.circles[{k}] must hold a 'circle' with a "
                                  "'center' [lat, lon] and a 'radius' above 0 m")
        circles.append((bool(entry.get("inclusion", True)), tuple(centre), float(radius)))
    breach = fence.get("breachReturn")
    if breach is not None and not (isinstance(breach, list) and len(breach) == 3
                                   and all(map(_is_number, breach))):
        raise FileFormatError(f"{path}: geoFence.breachReturn must be [lat, lon, alt]")
    points = data["rallyPoints"]["points"]
    for k, point in enumerate(points):
        if not (isinstance(point, list) and len(point) == 3 and all(map(_is_number, point))):
            raise FileFormatError(f"{path}: rallyPoints.points[{k}] must be [lat, lon, alt]")
    return fence_items(polygons, circles, breach), rally_items(points)


class QGCPlanExporter(Exporter):
    """QGroundControl plan (``.plan``)."""

    name = "plan"
    extensions = (".plan",)
    description = "QGroundControl .plan file"

    def document(self, mission: Mission) -> dict[str, Any]:
        """The plan document to write (a subclass may add a fence or rally points)."""
        return plan_dict(mission)

    def render(self, mission: Mission) -> str:
        data = self.document(mission)
        problems = plan_rule_violations(data)
        if problems:   # a bug here, never the user's input: say so instead of writing it
            raise TourInvalidError("internal error, the .plan breaks loader rules: "
                                   + "; ".join(problems))
        return json.dumps(data, indent=2, allow_nan=False) + "\n"

    readable = True

    def read(self, path) -> VehicleMission:
        data = read_json(path)
        problems = plan_rule_violations(data)
        if problems:
            raise FileFormatError(f"{path}: not a valid QGroundControl plan: " + "; ".join(problems[:3]))
        mission = data["mission"]
        try:
            autopilot = Autopilot(mission["firmwareType"])
        except ValueError:
            raise FileFormatError(f"{path}: firmwareType {mission['firmwareType']} is neither "
                                  "ArduPilot (3) nor PX4 (12)") from None
        items = []
        for item in mission["items"]:
            params = [0.0 if p is None else float(p) for p in item["params"]]
            items.append(MissionItem(item["command"], item["frame"], tuple(params[:4]), params[4],
                                     params[5], params[6], item["autoContinue"]))
        if not items:
            raise FileFormatError(f"{path}: the plan holds no mission items")
        ours = data.get("dtspMission") if isinstance(data.get("dtspMission"), dict) else {}
        wind = ours.get("designWind")
        design_wind = None
        if isinstance(wind, dict) and all(_is_number(wind.get(k)) for k in ("speed_m_s", "from_deg")):
            design_wind = (float(wind["speed_m_s"]), float(wind["from_deg"]))
        fence, rally = _fence_and_rally(path, data)
        read = VehicleMission(tuple(items), Home(*mission["plannedHomePosition"]), autopilot,
                              design_wind=design_wind, fence=fence, rally=rally,
                              targets=_carried_targets(path, ours),
                              designed_for=_carried_aircraft(path, ours, autopilot))
        problems = read.problems()
        if problems:
            raise FileFormatError(f"{path}: " + "; ".join(problems[:3]))
        return read
