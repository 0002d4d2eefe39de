"""The mission: a format-independent list of MAVLink mission items and what it was made from.

Exporters read this model; what a vehicle receives (:class:`VehicleMission`, its
:class:`MissionItem`s and :class:`Home`) lives below it, in :mod:`dtsp_mission.autopilot.mission`,
so that uploaders and the simulated vehicle need nothing of the designer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..frame import LocalFrame
from ..segments import SegmentChain
from ..tour import Tour
from ..autopilot.commands import Autopilot, Command, Frame
from ..autopilot.mission import Home, MissionItem, MissionTarget, VehicleMission, degrees_to_e7  # noqa: F401 (re-exported)
from ..targets.model import target_name


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
    predicted flights made, the waypoints passing a target a second time, the predicted
    flight's time (s, NaN if not predicted), the forecast wind (speed m/s, from deg) with its spread (m/s) and
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
    revisit_waypoints: int = 0
    predicted_flight_s: float = math.nan    # the predicted flight's time in the forecast wind

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
                "predicted_flight_s": self.predicted_flight_s,
                "shaping_waypoints": self.shaping_waypoints, "design_rounds": self.design_rounds,
                "revisit_waypoints": self.revisit_waypoints,
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
    #: the navigation parameters of the aircraft it was designed for (VehicleParameters or
    #: PX4Parameters); carried to the vehicle mission and the .plan
    designed_for: Any = None

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

    def visited_targets(self) -> tuple[MissionTarget, ...]:
        """The targets themselves (not their waypoints, which the guidance design aims
        elsewhere), in visiting order, with the altitude of their waypoint and their names."""
        latitudes, longitudes = self.target_positions_deg
        return tuple(MissionTarget(target_name(self.target_names, item.target),
                                   float(latitudes[item.target]), float(longitudes[item.target]),
                                   float(item.altitude_m))
                     for item in self.items if item.role == "target")

    def for_vehicle(self) -> VehicleMission:
        """The mission as a vehicle receives it, with the design wind and the targets."""
        return VehicleMission(self.items, self.home, self.autopilot,
                              design_wind=None if self.guidance is None else self.guidance.design_wind,
                              targets=self.visited_targets(), designed_for=self.designed_for)

    def vehicle_item_count(self) -> int:
        """Mission slots on the vehicle: the items plus ArduPilot's home at seq 0."""
        return len(self.items) + (1 if self.autopilot == Autopilot.ARDUPILOTMEGA else 0)


def waypoint(latitude_deg: float, longitude_deg: float, altitude_m: float, role: str = "path",
             target: int = -1, acceptance_m: float = 0.0) -> MissionItem:
    """A NAV_WAYPOINT (param2: acceptance radius, 0 for the autopilot's default)."""
    return MissionItem(Command.NAV_WAYPOINT, Frame.GLOBAL_RELATIVE_ALT,
                       (0.0, float(acceptance_m), 0.0, 0.0), float(latitude_deg),
                       float(longitude_deg), float(altitude_m), True, role, target)
