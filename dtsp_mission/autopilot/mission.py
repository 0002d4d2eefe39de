"""What a vehicle receives: mission items in plain units, the home they are relative to, the
autopilot flavour -- the form files are read into and uploaders and the simulated vehicle
take.  Below the mission design (importing it needs nothing of the planner or the designer).

Coordinates are exact degrees (float64); a format that needs integers (MISSION_ITEM_INT)
rounds them with :func:`degrees_to_e7` -- in one place.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

from .commands import Autopilot, Command, Frame


def degrees_to_e7(degrees: float) -> int:
    """Degrees as the int32 of MISSION_ITEM_INT (``round(deg * 1e7)``, about 1 cm)."""
    return int(round(degrees * 1e7))


@dataclass(frozen=True)
class MissionItem:
    """One mission item, as MISSION_ITEM_INT carries it, in plain units.

    ``params`` are param1..param4; for items without a position (frame MISSION)
    ``latitude_deg``/``longitude_deg`` carry param5/param6 as plain numbers (MISSION_ITEM_INT's
    x and y unscaled, as ArduPilot and QGroundControl read them: DO_DIGICAM_CONTROL's shutter
    flag), 0 for most.  ``altitude_m`` is relative to home in frame GLOBAL_RELATIVE_ALT.
    ``role`` says why the item is there (takeoff, speed, path, target, land_start, approach,
    land, return) and ``target`` which target (input order) a ``target`` item visits.
    """

    command: int
    frame: int
    params: tuple[float, float, float, float]
    latitude_deg: float = 0.0
    longitude_deg: float = 0.0
    altitude_m: float = 0.0
    autocontinue: bool = True
    role: str = "path"
    target: int = -1

    @property
    def has_position(self) -> bool:
        return self.frame != Frame.MISSION


@dataclass(frozen=True)
class Home:
    """Launch (home) position; ``altitude_amsl_m`` is above mean sea level."""

    latitude_deg: float
    longitude_deg: float
    altitude_amsl_m: float = 0.0


@dataclass(frozen=True)
class MissionTarget:
    """A target the mission was planned to pass -- not an item (the vehicle never receives it;
    a guidance design aims its waypoint elsewhere): where it is, its altitude above home (NaN:
    not given) and its name."""

    name: str
    latitude_deg: float
    longitude_deg: float
    altitude_m: float = float("nan")


_POSITIONLESS_FRAMES = {2}      # MAV_FRAME_MISSION: x and y are parameters, not a position
#: Frames whose altitude is above home or above the terrain (GLOBAL_RELATIVE_ALT, _INT,
#: GLOBAL_TERRAIN_ALT, _INT): a navigation item there below 0 flies into the ground.
_ABOVE_HOME_FRAMES = {3, 6, 10, 11}


_FLOAT32_MAX = 3.4028234663852886e38
#: Frames whose altitude is above mean sea level (GLOBAL, GLOBAL_INT).
_AMSL_FRAMES = {0, 5}
#: No item of a mission is farther than this from its home: the flat mission frame ends about
#: there (frame.MAX_SCALE_ERROR), and no small fixed wing flies a mission that wide.
MAX_REACH_M = 150_000.0
#: No item flies higher above home than this (targets.model.MAX_ALTITUDE_M).
MAX_ALTITUDE_ABOVE_HOME_M = 10_000.0
#: Commands that navigate without climbing away from the ground on purpose: a landing ends
#: there.
_DOWN_TO_GROUND = {int(Command.NAV_LAND), 85}     # NAV_LAND, NAV_VTOL_LAND


@functools.lru_cache(maxsize=1)
def known_commands() -> frozenset[int]:
    """Every MAV_CMD the MAVLink dialects of ArduPilot and PX4 define (pymavlink's
    ardupilotmega, which includes common): a command outside it no autopilot knows."""
    from pymavlink.dialects.v20 import ardupilotmega
    return frozenset(int(value) for value in ardupilotmega.enums["MAV_CMD"]
                     if not ardupilotmega.enums["MAV_CMD"][value].name.endswith("ENUM_END"))


@functools.lru_cache(maxsize=1)
def _geod():
    from pyproj import Geod
    return Geod(ellps="WGS84")


def _reach_m(home: "Home", item: "MissionItem") -> float:
    _, _, distance = _geod().inv(home.longitude_deg, home.latitude_deg,
                                 item.longitude_deg, item.latitude_deg)
    return float(distance)


def _is_nav(item: "MissionItem") -> bool:
    return int(item.command) < 100          # MAV_CMD_NAV_LAST is 95


@dataclass(frozen=True)
class VehicleMission:
    """What a vehicle receives: the items, the home they are relative to, and the autopilot
    flavour (ArduPilot keeps home at seq 0, PX4 does not).  Files read back and planned
    missions both give this, so uploaders and the simulator need nothing else.

    ``autopilot_stated`` is False for a file format that does not say the autopilot (QGC WPL
    110): ``autopilot`` is then ArduPilot's, the format's origin, and an uploader takes the
    vehicle's instead."""

    items: tuple[MissionItem, ...]
    home: Home
    autopilot: Autopilot
    autopilot_stated: bool = True
    #: the wind the mission was designed for: (m/s, degrees true it comes from); None: unknown
    design_wind: tuple[float, float] | None = None
    #: the targets it was planned for, in visiting order (a plan file written by dtsp-mission
    #: carries them); empty: unknown
    targets: tuple[MissionTarget, ...] = ()
    #: the navigation parameters of the aircraft the mission was designed for
    #: (:class:`~dtsp_mission.autopilot.parameters.VehicleParameters` or ``PX4Parameters``;
    #: a plan file written by dtsp-mission carries them); None: unknown
    designed_for: Any = None
    #: the geofence, as the items of MAV_MISSION_TYPE_FENCE (polygon vertices, circles, a
    #: return point: :func:`fence_items`), and the rally points (MAV_MISSION_TYPE_RALLY)
    fence: tuple[MissionItem, ...] = ()
    rally: tuple[MissionItem, ...] = ()

    def problems(self) -> list[str]:
        """What no autopilot would take, or no operator would fly, from this mission: a home or
        an item position off the globe (MAVLink's int32 degrees x 1e7 cannot even carry it) or
        not a number; a navigation item (other than a landing) below home or the terrain; a
        command, frame or value that MISSION_ITEM_INT cannot carry (command 16 bits, frame 8,
        parameters and altitude 32-bit floats)."""
        found = []
        for number, item in enumerate(self.items, start=1):
            values = (*item.params, item.altitude_m)
            if not (0 <= int(item.command) <= 0xFFFF and 0 <= int(item.frame) <= 0xFF):
                found.append(f"item {number}: command {int(item.command)} / frame "
                             f"{int(item.frame)} is not a MAVLink command / frame number")
            elif any(abs(v) > _FLOAT32_MAX for v in values):      # NaN passes: PX4's "unset"
                found.append(f"item {number} (command {int(item.command)}): a parameter or the "
                             "altitude is beyond what MAVLink carries (32-bit floats, "
                             f"at most {_FLOAT32_MAX:.3g})")
        if not (-90 <= self.home.latitude_deg <= 90 and -180 <= self.home.longitude_deg <= 180):
            found.append(f"home ({self.home.latitude_deg:g}, {self.home.longitude_deg:g}) is not "
                         "a latitude and longitude in degrees")
        for number, item in enumerate(self.items, start=1):
            if int(item.frame) in _POSITIONLESS_FRAMES:
                continue
            if not (-90 <= item.latitude_deg <= 90 and -180 <= item.longitude_deg <= 180):
                found.append(f"item {number} (command {int(item.command)}) is at latitude "
                             f"{item.latitude_deg:g}, longitude {item.longitude_deg:g}: not a "
                             "position in degrees")
            elif (int(item.frame) in _ABOVE_HOME_FRAMES and _is_nav(item)
                  and int(item.command) not in _DOWN_TO_GROUND
                  and not (item.altitude_m >= 0)):       # NaN too
                found.append(f"item {number} (command {int(item.command)}) is {item.altitude_m:g} m "
                             "above home: below the ground the aircraft took off from")
            elif (int(item.frame) in _AMSL_FRAMES and _is_nav(item)
                  and int(item.command) not in _DOWN_TO_GROUND
                  and not (item.altitude_m >= self.home.altitude_amsl_m)):
                found.append(f"item {number} (command {int(item.command)}) is at "
                             f"{item.altitude_m:g} m above mean sea level, "
                             f"{self.home.altitude_amsl_m - item.altitude_m:g} m below home "
                             f"({self.home.altitude_amsl_m:g} m): below the ground the aircraft "
                             "took off from")
            elif (reach := _reach_m(self.home, item)) > MAX_REACH_M:
                found.append(f"item {number} (command {int(item.command)}) at "
                             f"({item.latitude_deg:.6f}, {item.longitude_deg:.6f}) is "
                             f"{reach / 1000:,.0f} km from home: not part of a "
                             f"mission flown from there (at most {MAX_REACH_M / 1000:.0f} km)")
            if _is_nav(item) and self.height_above_home_m(item) > MAX_ALTITUDE_ABOVE_HOME_M:
                found.append(f"item {number} (command {int(item.command)}) is "
                             f"{self.height_above_home_m(item):,.0f} m above home: beyond the "
                             f"{MAX_ALTITUDE_ABOVE_HOME_M:,.0f} m a mission is planned to")
        known = known_commands()
        for number, item in enumerate(self.items, start=1):
            if int(item.command) not in known:
                found.append(f"item {number}: command {int(item.command)} is no MAVLink command "
                             "an autopilot knows (MAV_CMD); the vehicle would refuse it midway")
            elif (int(item.command) == Command.NAV_LOITER_TURNS and int(self.autopilot)
                  == Autopilot.ARDUPILOTMEGA and not 0 < item.params[0] <= 255):
                found.append(f"item {number} (NAV_LOITER_TURNS): {item.params[0]:g} turns; "
                             "ArduPilot keeps from 1 to 255 turns")
        return found

    def height_above_home_m(self, item: MissionItem) -> float:
        """The item's altitude above home (above the terrain for terrain frames; NaN for an
        item without a position)."""
        if int(item.frame) in _POSITIONLESS_FRAMES:
            return float("nan")
        if int(item.frame) in _AMSL_FRAMES:
            return item.altitude_m - self.home.altitude_amsl_m
        return item.altitude_m

    def below_floor(self, min_altitude_m: float) -> list[str]:
        """The navigation items (take-off, waypoints, loiters; not a landing) that fly lower
        above home than ``min_altitude_m``, as ``plan --min-alt`` would refuse them."""
        low = []
        for number, item in enumerate(self.items, start=1):
            if (_is_nav(item) and int(item.frame) not in _POSITIONLESS_FRAMES
                    and int(item.command) not in _DOWN_TO_GROUND
                    and int(item.command) != Command.NAV_RETURN_TO_LAUNCH
                    and self.height_above_home_m(item) < min_altitude_m - 1e-6):
                low.append(f"item {number} (command {int(item.command)}) at "
                           f"{self.height_above_home_m(item):g} m above home")
        return low


# -- geofence and rally points -----------------------------------------------------------------

#: MAV_CMD of the geofence items (MAV_MISSION_TYPE_FENCE) and of a rally point (_RALLY).
FENCE_RETURN_POINT, FENCE_VERTEX_INCLUSION, FENCE_VERTEX_EXCLUSION = 5000, 5001, 5002
FENCE_CIRCLE_INCLUSION, FENCE_CIRCLE_EXCLUSION, RALLY_POINT = 5003, 5004, 5100


def fence_items(polygons, circles, breach_return=None) -> tuple[MissionItem, ...]:
    """The geofence as MAVLink sends it (QGroundControl's encoding): per polygon
    ``(inclusion, [(lat, lon), ...])`` one vertex item each, param1 the vertex count, frame
    GLOBAL; per circle ``(inclusion, (lat, lon), radius_m)`` one item, param1 the radius;
    ``breach_return`` ``(lat, lon, alt)`` a return point."""
    items = []
    if breach_return is not None:
        items.append(MissionItem(FENCE_RETURN_POINT, int(Frame.GLOBAL_RELATIVE_ALT),
                                 (0.0, 0.0, 0.0, 0.0), *map(float, breach_return)))
    for inclusion, vertices in polygons:
        command = FENCE_VERTEX_INCLUSION if inclusion else FENCE_VERTEX_EXCLUSION
        items += [MissionItem(command, int(Frame.GLOBAL), (float(len(vertices)), 0.0, 0.0, 0.0),
                              float(lat), float(lon), 0.0) for lat, lon in vertices]
    for inclusion, (lat, lon), radius in circles:
        command = FENCE_CIRCLE_INCLUSION if inclusion else FENCE_CIRCLE_EXCLUSION
        items.append(MissionItem(command, int(Frame.GLOBAL), (float(radius), 0.0, 0.0, 0.0),
                                 float(lat), float(lon), 0.0))
    return tuple(items)


def rally_items(points) -> tuple[MissionItem, ...]:
    """Rally points ``(lat, lon, alt above home)`` as MAVLink sends them."""
    return tuple(MissionItem(RALLY_POINT, int(Frame.GLOBAL_RELATIVE_ALT), (0.0, 0.0, 0.0, 0.0),
                             float(lat), float(lon), float(alt)) for lat, lon, alt in points)
