"""Mission items as they travel in MISSION_ITEM_INT, and the comparison of two such lists.

This is the one place where a :class:`~dtsp_mission.mission.VehicleMission` becomes
sequence-numbered wire items (ArduPilot's home placeholder at seq 0 included) and where a
downloaded mission is compared with the plan.  Values are normalised to what the wire can
carry (params and altitude as float32, latitude and longitude as int32 1e-7 degrees), so two
lists compare equal exactly when the vehicle holds the planned mission.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..mission import Autopilot, Command, Frame, VehicleMission, degrees_to_e7
from ..mission.model import Home, MissionItem

MISSION_TYPE_MISSION = 0


def _f32(value: float) -> float:
    return float(np.float32(value))


@dataclass(frozen=True)
class WireItem:
    """One MISSION_ITEM_INT, field for field (``x``/``y`` are int32 1e-7 degrees)."""

    seq: int
    frame: int
    command: int
    current: int
    autocontinue: int
    param1: float
    param2: float
    param3: float
    param4: float
    x: int
    y: int
    z: float
    mission_type: int = MISSION_TYPE_MISSION

    @classmethod
    def normalised(cls, seq, frame, command, current, autocontinue, param1, param2, param3,
                   param4, x, y, z, mission_type=MISSION_TYPE_MISSION) -> "WireItem":
        """The item with every value as the wire carries it."""
        return cls(int(seq), int(frame), int(command), int(current), int(bool(autocontinue)),
                   _f32(param1), _f32(param2), _f32(param3), _f32(param4), int(x), int(y),
                   _f32(z), int(mission_type))


#: Fields compared between plan and vehicle (``current`` is state, not content).
COMPARED = tuple(f.name for f in fields(WireItem) if f.name not in ("current", "seq"))


def home_placeholder(home: Home) -> WireItem:
    """ArduPilot's seq 0: a waypoint at home (altitude above sea level).  ArduPilot replaces
    it with its own home, so it is sent but never compared."""
    return WireItem.normalised(0, Frame.GLOBAL, Command.NAV_WAYPOINT, 0, 1, 0, 0, 0, 0,
                               degrees_to_e7(home.latitude_deg), degrees_to_e7(home.longitude_deg),
                               home.altitude_amsl_m)


def first_mission_seq(autopilot: Autopilot) -> int:
    """Sequence number of the first real item: 1 on ArduPilot (home is 0), else 0."""
    return 1 if autopilot == Autopilot.ARDUPILOTMEGA else 0


def to_wire(mission: VehicleMission) -> list[WireItem]:
    """The items to send, seq 0 first; the first is ``current``."""
    wire = [home_placeholder(mission.home)] if first_mission_seq(mission.autopilot) else []
    for item in mission.items:
        x, y = ((degrees_to_e7(item.latitude_deg), degrees_to_e7(item.longitude_deg))
                if item.has_position else (0, 0))
        wire.append(WireItem.normalised(len(wire), item.frame, item.command, 0, item.autocontinue,
                                        *item.params, x, y, item.altitude_m))
    if wire:
        wire[0] = WireItem(**{**wire[0].__dict__, "current": 1})
    return wire


def from_wire(wire: list[WireItem], autopilot: Autopilot) -> list[MissionItem]:
    """Mission items (without roles) from wire items, ArduPilot's home left out."""
    items = []
    for item in wire[first_mission_seq(autopilot):]:
        items.append(MissionItem(item.command, item.frame,
                                 (item.param1, item.param2, item.param3, item.param4),
                                 item.x / 1e7, item.y / 1e7, item.z, bool(item.autocontinue)))
    return items


def differences(planned: list[WireItem], on_vehicle: list[WireItem],
                autopilot: Autopilot, limit: int = 5) -> list[str]:
    """How the vehicle's mission differs from the plan, at most ``limit`` lines (empty if it
    holds exactly the plan)."""
    problems = []
    if len(planned) != len(on_vehicle):
        problems.append(f"the vehicle holds {len(on_vehicle)} items, the plan has {len(planned)}")
    for planned_item, vehicle_item in zip(planned, on_vehicle):
        if planned_item.seq < first_mission_seq(autopilot):
            continue
        changed = [name for name in COMPARED
                   if getattr(planned_item, name) != getattr(vehicle_item, name)]
        if changed:
            problems.append(f"item {planned_item.seq} differs in " + ", ".join(
                f"{name} ({getattr(vehicle_item, name)!r} instead of "
                f"{getattr(planned_item, name)!r})" for name in changed))
    if len(problems) > limit:
        problems = problems[:limit] + [f"... and {len(problems) - limit} more differences"]
    return problems


def describe_vehicle(on_vehicle: list[WireItem] | None, planned: list[WireItem],
                     autopilot: Autopilot) -> str:
    """One sentence on what the vehicle holds, for error messages."""
    if on_vehicle is None:
        return "what the vehicle holds now is unknown (downloading it failed too)"
    real = len(on_vehicle) - min(len(on_vehicle), first_mission_seq(autopilot))
    if real == 0:
        return "the vehicle holds no mission now"
    if not differences(planned, on_vehicle, autopilot):
        return "the vehicle holds exactly the planned mission"
    same = 0
    for planned_item, vehicle_item in zip(planned, on_vehicle):
        if planned_item.seq >= first_mission_seq(autopilot) and any(
                getattr(planned_item, n) != getattr(vehicle_item, n) for n in COMPARED):
            break
        same += 1
    matching = max(0, same - first_mission_seq(autopilot))
    return (f"the vehicle now holds a different mission of {real} items ({matching} leading "
            f"items match the plan): do not fly it")


__all__ = ["COMPARED", "WireItem", "describe_vehicle", "differences", "first_mission_seq",
           "from_wire", "home_placeholder", "to_wire"]
