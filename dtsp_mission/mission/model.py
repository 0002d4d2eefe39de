"""The mission: a format-independent list of MAVLink mission items and what it was made from.

Exporters and uploaders read this model and nothing else.  Coordinates are exact degrees
(float64); a format that needs integers (MISSION_ITEM_INT) rounds them with
:func:`degrees_to_e7` -- in one place.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..frame import LocalFrame
from ..segments import SegmentChain
from ..tour import Tour
from ..autopilot.commands import Autopilot, Command, Frame


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


_POSITIONLESS_FRAMES = {2}      # MAV_FRAME_MISSION: x and y are parameters, not a position
#: Frames whose altitude is above home or above the terrain (GLOBAL_RELATIVE_ALT, _INT,
#: GLOBAL_TERRAIN_ALT, _INT): a navigation item there below 0 flies into the ground.
_ABOVE_HOME_FRAMES = {3, 6, 10, 11}


_FLOAT32_MAX = 3.4028234663852886e38


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
    #: what the file holds beside the mission items, which an upload of the items does not
    #: carry ("a geofence of 1 polygon", "1 rally point")
    not_carried: tuple[str, ...] = ()

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
            elif (int(item.frame) in _ABOVE_HOME_FRAMES and int(item.command) < 100
                  and int(item.command) != Command.NAV_LAND
                  and not (item.altitude_m >= 0)):       # NaN too
                found.append(f"item {number} (command {int(item.command)}) is {item.altitude_m:g} m "
                             "above home: below the ground the aircraft took off from")
        return found


@dataclass(frozen=True)
class LoiterSpan:
    """Whole circles flown through a target: ``[start_s_m, end_s_m]`` of the flight path, around
    ``centre_m`` (local frame) at ``radius_m``."""

    target: int
    start_s_m: float
    end_s_m: float
    centre_m: np.ndarray
    radius_m: float
    clockwise: bool
    turns: int


@dataclass(frozen=True)
class FlightPath:
    """The exact path the mission flies, in the local frame: lead-in from the end of the
    climb-out, the tour opened at its best cut, and the lead-out to the landing approach.

    ``target_s_m[i]`` is the arc length at which target ``i`` is overflown; the tour part spans
    ``[tour_start_s_m, tour_end_s_m]``.
    """

    chain: SegmentChain
    target_s_m: np.ndarray
    tour_start_s_m: float
    tour_end_s_m: float
    climb_start_m: np.ndarray          # home (x, y): where the takeoff begins
    altitudes_at_s: tuple[np.ndarray, np.ndarray]   # knots (s_m, altitude_m) for np.interp
    loiters: tuple[LoiterSpan, ...] = ()            # in path order

    def in_loiter(self, s_m: np.ndarray) -> np.ndarray:
        """Whether each arc length lies on a loiter's circles after its start."""
        s_m = np.asarray(s_m, dtype=float)
        inside = np.zeros(s_m.shape, dtype=bool)
        for span in self.loiters:
            inside |= (s_m > span.start_s_m + 1e-9) & (s_m <= span.end_s_m + 1e-9)
        return inside

    def altitude_m(self, s_m: np.ndarray) -> np.ndarray:
        return np.interp(s_m, *self.altitudes_at_s)


@dataclass(frozen=True)
class GuidancePrediction:
    """What the guidance design predicts of its mission in the flight model.

    Per target (target order), in metres: ``predicted_miss_m`` in the forecast wind,
    ``worst_wind_miss_m`` the worst over the design winds, ``judged_miss_m`` the miss the
    design is judged by (the forecast's, or the worst of the others less the model's margin,
    whichever is further beyond its limit: held when at most ``design_limit_m``).  The
    predicted flight and the planned one over the same span, the shaping waypoints added, the
    predicted flights made, the forecast wind (speed m/s, from deg) with its spread (m/s) and
    the winds flown.
    """

    predicted_miss_m: np.ndarray
    judged_miss_m: np.ndarray
    worst_wind_miss_m: np.ndarray
    design_limit_m: float
    predicted_flight_m: float
    planned_flight_m: float
    shaping_waypoints: int
    design_rounds: int
    design_wind: tuple[float, float]
    wind_spread_m_s: float
    design_winds: tuple[tuple[float, float], ...]

    def targets_beyond(self, limit_m: float | None = None) -> int:
        """Targets not held: judged beyond the design limit; with ``limit_m``, predicted
        beyond it in the forecast wind."""
        if limit_m is None:
            return int((self.judged_miss_m > self.design_limit_m).sum())
        return int((self.predicted_miss_m > limit_m).sum())

    def as_summary(self) -> dict[str, Any]:
        """The prediction as plain values (the report's and the JSON summary's keys)."""
        speed, from_deg = self.design_wind
        return {"predicted_miss_m": self.predicted_miss_m.tolist(),
                "judged_miss_m": self.judged_miss_m.tolist(),
                "worst_wind_miss_m": self.worst_wind_miss_m.tolist(),
                "predicted_flight_m": self.predicted_flight_m,
                "planned_flight_m": self.planned_flight_m,
                "shaping_waypoints": self.shaping_waypoints, "design_rounds": self.design_rounds,
                "design_wind": {"speed_m_s": speed, "from_deg": from_deg,
                                "spread_m_s": self.wind_spread_m_s},
                "design_winds": [list(w) for w in self.design_winds],
                "design_limit_m": self.design_limit_m}


@dataclass(frozen=True)
class Mission:
    """Mission items with everything exporters need to describe them; ``guidance`` is what
    the guidance design predicts of it (None for the geometric design)."""

    items: tuple[MissionItem, ...]
    home: Home
    autopilot: Autopilot
    cruise_speed_m_s: float | None
    rho_m: float
    tolerance_m: float                 # every point of the path is this close to the waypoints
    frame: LocalFrame
    tour: Tour
    path: FlightPath
    target_names: tuple[str, ...] | None = None
    notes: tuple[str, ...] = ()        # decisions the user should know about
    summary: dict[str, Any] = field(default_factory=dict)
    targets_deg: tuple[np.ndarray, np.ndarray] | None = None   # the input's latitudes, longitudes
    guidance: GuidancePrediction | None = None

    @property
    def target_items(self) -> list[int]:
        """Index (in ``items``) of the waypoint of each target, in target order."""
        index = {item.target: k for k, item in enumerate(self.items) if item.role == "target"}
        return [index[t] for t in range(len(self.tour.targets_m))]

    @property
    def target_positions_deg(self) -> tuple[np.ndarray, np.ndarray]:
        """Latitudes and longitudes of the targets themselves, in target order (a target's
        waypoint may stand elsewhere: the aim point of the guidance design)."""
        if self.targets_deg is not None:
            return self.targets_deg
        return self.frame.to_geodetic(self.tour.targets_m)

    @property
    def visit_numbers(self) -> np.ndarray:
        """0-based position of each target (in target order) in the visiting order."""
        order = np.argsort(self.path.target_s_m, kind="stable")
        numbers = np.empty(len(order), dtype=np.int64)
        numbers[order] = np.arange(len(order))
        return numbers

    def for_vehicle(self) -> VehicleMission:
        return VehicleMission(self.items, self.home, self.autopilot,
                              design_wind=None if self.guidance is None else self.guidance.design_wind)

    def vehicle_item_count(self) -> int:
        """Mission slots on the vehicle: the items plus ArduPilot's home at seq 0."""
        return len(self.items) + (1 if self.autopilot == Autopilot.ARDUPILOTMEGA else 0)


def waypoint(latitude_deg: float, longitude_deg: float, altitude_m: float, role: str = "path",
             target: int = -1, acceptance_m: float = 0.0) -> MissionItem:
    """A NAV_WAYPOINT (param2: acceptance radius, 0 for the autopilot's default)."""
    return MissionItem(Command.NAV_WAYPOINT, Frame.GLOBAL_RELATIVE_ALT,
                       (0.0, float(acceptance_m), 0.0, 0.0), float(latitude_deg),
                       float(longitude_deg), float(altitude_m), True, role, target)
