"""Mission items as they travel in MISSION_ITEM_INT, and the comparison of two such lists.

This is the one place where a :class:`~dtsp_mission.mission.VehicleMission` becomes
sequence-numbered wire items (ArduPilot's home placeholder at seq 0 included) and where a
downloaded mission is compared with the plan.  Each planned item is compared in the form the
autopilot stores it (:func:`~dtsp_mission.autopilot.storage.comparable`: ArduPilot's packed
radii, 1/256 turns and centimetres, frame 0 for items without a position), so two lists compare
equal exactly when the vehicle holds what it can hold of the planned mission.
"""

from __future__ import annotations

from dataclasses import fields

from .storage import MISSION_TYPE_MISSION, WireItem, comparable
from .commands import Autopilot, Command, Frame
from .mission import Home, MissionItem, VehicleMission, degrees_to_e7


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
                if item.has_position else (int(round(item.latitude_deg)), int(round(item.longitude_deg))))
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


def holds(planned_item: WireItem, vehicle_item: WireItem, autopilot: Autopilot) -> bool:
    """Whether the vehicle's item is the planned one: in the form the autopilot stores it, or
    exactly as sent (a vehicle that keeps items verbatim)."""
    got = comparable(vehicle_item, autopilot, sent=False)
    return got == comparable(planned_item, autopilot) or \
        got == comparable(planned_item, autopilot, sent=False)


def differences(planned: list[WireItem], on_vehicle: list[WireItem],
                autopilot: Autopilot, limit: int = 5) -> list[str]:
    """How the vehicle's mission differs from the plan, at most ``limit`` lines (empty if it
    holds exactly the plan)."""
    problems = []
    first = first_mission_seq(autopilot)
    if len(planned) != len(on_vehicle):
        problems.append(f"the vehicle holds {len(on_vehicle)} items, the plan has {len(planned)}")
    for planned_item, vehicle_item in zip(planned, on_vehicle):
        if planned_item.seq < first or holds(planned_item, vehicle_item, autopilot):
            continue
        expected = comparable(planned_item, autopilot)
        got = comparable(vehicle_item, autopilot, sent=False)
        changed = [name for name in COMPARED if getattr(expected, name) != getattr(got, name)]
        if changed:
            problems.append(f"item {planned_item.seq} differs in " + ", ".join(
                f"{name} ({getattr(vehicle_item, name)!r} instead of "
                f"{getattr(expected, name)!r})" for name in changed))
    if len(problems) > limit:
        problems = problems[:limit] + [f"... and {len(problems) - limit} more differences"]
    return problems


def describe_vehicle(on_vehicle: list[WireItem] | None, planned: list[WireItem],
                     autopilot: Autopilot, nothing_sent: bool = False) -> str:
    """One sentence on what the vehicle holds, for error messages: unknown, nothing, exactly
    the plan, its earlier mission (``nothing_sent``: the upload was refused before any item
    went out, so the vehicle kept it), the first k items of the plan (and what follows them),
    or another mission."""
    if on_vehicle is None:
        return "what the vehicle holds now is unknown (downloading it failed too)"
    first = first_mission_seq(autopilot)
    real = len(on_vehicle) - min(len(on_vehicle), first)
    if real == 0:
        return "the vehicle holds no mission now"
    if nothing_sent and differences(planned, on_vehicle, autopilot):
        return (f"no item of this mission was sent: the vehicle kept the mission it held "
                f"({real} items, downloaded after the refusal)")
    if not differences(planned, on_vehicle, autopilot):
        return "the vehicle holds exactly the planned mission"
    matching = 0
    for planned_item, vehicle_item in zip(planned[first:], on_vehicle[first:]):
        if not holds(planned_item, vehicle_item, autopilot):
            break
        matching += 1
    total = len(planned) - first
    if matching == 0:
        return (f"the vehicle holds a mission of {real} items that shares nothing with this one "
                "(its earlier mission, as far as this upload did not reach it): do not fly it "
                "before uploading again")
    rest = (f", followed by {real - matching} items left from its earlier mission"
            if real > matching else "")
    return (f"the vehicle holds the first {matching} of the {total} items of this mission{rest}: "
            "do not fly it before uploading again")


__all__ = ["COMPARED", "MISSION_TYPE_MISSION", "WireItem", "describe_vehicle", "differences",
           "first_mission_seq", "holds",
           "from_wire", "home_placeholder", "to_wire"]


def other_to_wire(items, mission_type: int) -> list[WireItem]:
    """Geofence or rally items (``mission_type`` 1 or 2) as sent: seq from 0, no home slot."""
    return [WireItem.normalised(seq, item.frame, item.command, 0, item.autocontinue,
                                *item.params, degrees_to_e7(item.latitude_deg),
                                degrees_to_e7(item.longitude_deg), item.altitude_m, mission_type)
            for seq, item in enumerate(items)]


#: Frames that mean the same for a geofence or rally item (integer and float forms).
_SAME_FRAME = {5: 0, 6: 3, 11: 10}


def other_differences(planned: list[WireItem], on_vehicle: list[WireItem],
                      limit: int = 5) -> list[str]:
    """How a downloaded geofence or rally list differs from the one sent (empty if equal):
    the same commands at the same positions (1e-7 deg), parameters as 32-bit floats, the
    altitude within the metre autopilots keep rally altitudes in."""
    problems = []
    if len(planned) != len(on_vehicle):
        problems.append(f"the vehicle holds {len(on_vehicle)} items, {len(planned)} were sent")
    for sent, held in zip(planned, on_vehicle):
        changed = [name for name in ("command", "x", "y") if getattr(sent, name) != getattr(held, name)]
        changed += [f"param{k}" for k in (1, 2) if abs(getattr(sent, f"param{k}")
                                                     - getattr(held, f"param{k}")) > 1e-3]
        # a return point keeps its position only (ArduPilot stores no altitude for it, its
        # FENCE_RET_ALT decides; PX4 gives it back in another frame)
        if sent.command == RALLY_POINT_COMMAND:
            if abs(sent.z - held.z) > 1.0:
                changed.append("z")
            if _SAME_FRAME.get(sent.frame, sent.frame) != _SAME_FRAME.get(held.frame, held.frame):
                changed.append("frame")
        if changed:
            problems.append(f"item {sent.seq} differs in " + ", ".join(
                f"{name} ({getattr(held, name)!r} instead of {getattr(sent, name)!r})"
                for name in changed))
    if len(problems) > limit:
        problems = problems[:limit] + [f"... and {len(problems) - limit} more differences"]
    return problems


RALLY_POINT_COMMAND = 5100
