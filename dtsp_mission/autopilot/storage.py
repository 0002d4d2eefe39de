"""What an autopilot keeps of a mission item, and how many it keeps.

A vehicle does not store the MISSION_ITEM_INT it was sent: ArduPilot packs every item into
15 bytes (``AP_Mission``) and hands back what it stored, PX4 keeps its own ``mission_item``
struct.  :func:`stored_item` gives, for an item sent to an autopilot, the item that autopilot
returns on download; the simulated vehicle stores that, and the uploader compares a download
with it, so a storage normalisation never looks like a corrupted upload while any real change
(a position, a command, a parameter beyond the storage resolution, an item missing) still
does.

ArduPilot's rules are the ones measured on ArduPlane 4.7 (``tests/data/arduplane-sitl/facts.md``
and every ``readback.json`` there are golden tests).  PX4's are the ones measured on PX4 v1.16.0
SITL (``tests/data/px4-sitl/storage_probe.json`` and its ``readback.json`` files, golden tests
too): global frames come back in their ``_INT`` form, NAV_TAKEOFF's param1 and NAV_WAYPOINT's
param3 are not kept, an item without a position (frame 2) keeps its x and y as 32-bit floats,
and NAV_LOITER_TURNS is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from pymavlink.dialects.v20.common import (MAV_MISSION_ACCEPTED, MAV_MISSION_ERROR,
                                           MAV_MISSION_NO_SPACE, MAV_MISSION_UNSUPPORTED,
                                           MAV_MISSION_UNSUPPORTED_FRAME)

from .commands import Autopilot, Command, Frame

MISSION_TYPE_MISSION = 0
#: Mission slots of a stock vehicle: ArduPlane SITL answers MISSION_COUNT 656 with NO_SPACE
#: ("Only 655 items are supported", home at seq 0 included); PX4's default dataman holds 500.
CAPACITY = {Autopilot.ARDUPILOTMEGA: 655, Autopilot.PX4: 500}
#: MAVLink's sequence numbers are 16 bits: no vehicle can take more items than this.
MAVLINK_MAX_ITEMS = 65535


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


def wire_item_from(message, current: int | None = None) -> WireItem:
    """The WireItem of a received MISSION_ITEM_INT or MISSION_ITEM (the old message with float
    degrees, brought to 1e-7 degrees); ``current`` overrides the message's."""
    x, y = message.x, message.y
    if message.get_type() == "MISSION_ITEM":
        x, y = round(x * 1e7), round(y * 1e7)
    return WireItem.normalised(message.seq, message.frame, message.command,
                               message.current if current is None else current,
                               message.autocontinue, message.param1, message.param2,
                               message.param3, message.param4, x, y, message.z, MISSION_TYPE_MISSION)


# -- ArduPilot ---------------------------------------------------------------------------------

#: Commands ArduPilot stores with a location, and commands it stores without one (these come
#: back in frame 0 with no position); any other command is compared as the wire carries it.
_AP_LOCATION_COMMANDS = {Command.NAV_WAYPOINT, Command.NAV_LOITER_UNLIM, Command.NAV_LOITER_TURNS,
                         Command.NAV_LOITER_TIME, Command.NAV_LAND, Command.NAV_TAKEOFF,
                         Command.DO_LAND_START, Command.DO_SET_ROI}
_AP_NO_LOCATION_COMMANDS = {Command.NAV_RETURN_TO_LAUNCH, Command.DO_CHANGE_SPEED,
                            Command.DO_MOUNT_CONTROL}
#: Commands ArduPilot stores without a location but with MISSION_ITEM_INT's x and y as plain
#: numbers (AP_Mission passes them through unscaled): they come back in frame 0 with x and y.
_AP_RAW_XY_COMMANDS = {Command.DO_DIGICAM_CONTROL}
#: The frames ArduPilot keeps as a flag: the ``_INT`` forms come back in their plain form.
_AP_FRAMES = {Frame.GLOBAL_INT: Frame.GLOBAL, Frame.GLOBAL_RELATIVE_ALT_INT: Frame.GLOBAL_RELATIVE_ALT,
              Frame.GLOBAL_TERRAIN_ALT_INT: Frame.GLOBAL_TERRAIN_ALT}


def _byte(value: float) -> int:
    """A parameter stored in one unsigned byte (truncated, clamped to 0..255)."""
    return int(min(max(math.trunc(value), 0), 255)) if math.isfinite(value) else 0


def _ap_loiter_radius(radius_m: float) -> float:
    """A loiter radius in ArduPilot's byte: whole metres to 255 m, 10 m steps to 2550 m; the
    sign (direction) kept."""
    size = abs(radius_m)
    kept = _byte(size) if size <= 255 else min(math.trunc(size / 10.0), 255) * 10
    return float(-kept if radius_m < 0 else kept)


def _ap_turns(turns: float) -> float:
    """LOITER_TURNS' count: below one turn in 1/256 turn, else whole turns up to 255."""
    if 0 < turns < 1:
        return math.trunc(turns * 256) / 256.0
    return float(_byte(turns))


def _ap_altitude(z_m: float) -> float:
    """Altitude kept as int32 centimetres (float32 arithmetic, truncated), returned in metres."""
    centimetres = math.trunc(float(np.float32(z_m) * np.float32(100.0)))
    return float(np.float32(centimetres) * np.float32(0.01))


def _ardupilot(item: WireItem) -> WireItem:
    command = item.command
    if command in _AP_NO_LOCATION_COMMANDS:
        return replace(item, frame=int(Frame.GLOBAL), **_ap_params(item), x=0, y=0, z=0.0)
    if command in _AP_RAW_XY_COMMANDS:
        return replace(item, frame=int(Frame.GLOBAL), **_ap_params(item), x=_byte(item.x),
                       y=_byte(item.y), z=0.0)
    if command not in _AP_LOCATION_COMMANDS:
        return item
    frame = int(_AP_FRAMES.get(item.frame, item.frame))
    return replace(item, frame=frame, **_ap_params(item), z=_ap_altitude(item.z))


def _ap_params(item: WireItem) -> dict[str, float]:
    p1, p2, p3, p4 = item.param1, item.param2, item.param3, item.param4
    command = item.command
    if command == Command.NAV_WAYPOINT:      # acceptance and pass radius in a byte each
        return dict(param1=0.0, param2=float(_byte(p2)), param3=float(_byte(p3)), param4=0.0)
    if command == Command.NAV_LOITER_TURNS:
        return dict(param1=_ap_turns(p1), param2=0.0, param3=_ap_loiter_radius(p3),
                    param4=1.0 if p4 > 0 else 0.0)
    if command == Command.NAV_LOITER_UNLIM:
        return dict(param1=0.0, param2=0.0, param3=_ap_loiter_radius(p3), param4=0.0)
    if command == Command.NAV_LOITER_TIME:   # the time in seconds; of the radius only its sign
        return dict(param1=float(min(max(math.trunc(p1), 0), 65535)), param2=0.0,
                    param3=-1.0 if p3 < 0 else 1.0, param4=1.0 if p4 > 0 else 0.0)
    if command == Command.NAV_TAKEOFF:       # the pitch in whole degrees
        return dict(param1=float(_byte(p1)), param2=0.0, param3=0.0, param4=0.0)
    if command == Command.NAV_RETURN_TO_LAUNCH:
        return dict(param1=0.0, param2=0.0, param3=0.0, param4=0.0)
    if command == Command.DO_CHANGE_SPEED:   # speed type in a byte, speed and throttle as floats
        return dict(param1=float(_byte(p1)), param2=_f32(p2), param3=_f32(p3), param4=0.0)
    if command == Command.DO_SET_ROI:        # the ROI mode in 16 bits; the location is the ROI
        return dict(param1=float(min(max(math.trunc(p1), 0), 65535)) if math.isfinite(p1) else 0.0,
                    param2=0.0, param3=0.0, param4=0.0)
    if command == Command.DO_MOUNT_CONTROL:  # pitch, roll, yaw as floats; the mode is not kept
        return dict(param1=_f32(p1), param2=_f32(p2), param3=_f32(p3), param4=0.0)
    if command == Command.DO_DIGICAM_CONTROL:    # session, zoom, zoom step, focus in bytes
        step = int(min(max(math.trunc(p3), -128), 127)) if math.isfinite(p3) else 0
        return dict(param1=float(_byte(p1)), param2=float(_byte(p2)), param3=float(step),
                    param4=float(_byte(p4)))
    return dict(param1=_f32(p1), param2=_f32(p2), param3=_f32(p3), param4=_f32(p4))


# -- PX4 ---------------------------------------------------------------------------------------

#: PX4 returns a global frame in its ``_INT`` form (sent 3, returned 6).
_PX4_INT_FRAMES = {Frame.GLOBAL: Frame.GLOBAL_INT, Frame.GLOBAL_RELATIVE_ALT: Frame.GLOBAL_RELATIVE_ALT_INT,
                   Frame.GLOBAL_TERRAIN_ALT: Frame.GLOBAL_TERRAIN_ALT_INT}
#: PX4's frame for items without a position (MAV_FRAME_MISSION).
PX4_NO_POSITION_FRAME = 2
#: Commands PX4 stores with a position (in a global frame); any other it takes only in frame 2
#: and answers MAV_MISSION_UNSUPPORTED in a global frame (measured for DO_CHANGE_SPEED,
#: DO_SET_CAM_TRIGG_DIST, IMAGE_START_CAPTURE, DO_SET_ROI_NONE, DO_GIMBAL_MANAGER_PITCHYAW,
#: DO_LAND_START); the position commands measured are 16, 17, 19, 21, 22 and 201, the VTOL
#: and loiter-to-altitude ones (31, 84, 85) and DO_SET_ROI_LOCATION (195) as its mission
#: manager takes them.
PX4_POSITION_COMMANDS = frozenset({Command.NAV_WAYPOINT, Command.NAV_LOITER_UNLIM,
                                   Command.NAV_LOITER_TIME, Command.NAV_LAND, Command.NAV_TAKEOFF,
                                   Command.DO_SET_ROI, 31, 84, 85, 195})
#: Commands PX4's mission refuses whatever the frame (MAV_MISSION_UNSUPPORTED).
PX4_REFUSED_COMMANDS = frozenset({Command.NAV_LOITER_TURNS})


def _px4(item: WireItem) -> WireItem:
    """The item as PX4 v1.16 stores it (measured: ``storage_probe.json``)."""
    if item.frame == PX4_NO_POSITION_FRAME:
        item = replace(item, x=int(np.float32(item.x)), y=int(np.float32(item.y)))
    else:
        item = replace(item, frame=int(_PX4_INT_FRAMES.get(item.frame, item.frame)))
    if item.command == Command.NAV_TAKEOFF:
        item = replace(item, param1=0.0)          # the minimum pitch is not kept
    elif item.command == Command.NAV_WAYPOINT:
        item = replace(item, param3=0.0)          # the pass radius is not kept
    return item


def px4_refusal(item: WireItem) -> int | None:
    """The MAV_MISSION_RESULT with which PX4 refuses ``item``, or None if it takes it."""
    if item.command in PX4_REFUSED_COMMANDS:
        return UNSUPPORTED
    if item.frame != PX4_NO_POSITION_FRAME and item.command not in PX4_POSITION_COMMANDS:
        return UNSUPPORTED
    return None


def stored_item(item: WireItem, autopilot: Autopilot) -> WireItem:
    """What ``autopilot`` returns on download for ``item`` sent to it (``seq`` and
    ``current`` unchanged)."""
    item = WireItem.normalised(**item.__dict__)
    return _ardupilot(item) if autopilot == Autopilot.ARDUPILOTMEGA else _px4(item)


def comparable(item: WireItem, autopilot: Autopilot, sent: bool = True) -> WireItem:
    """The item as it must come back from ``autopilot``: a ``sent`` item in its stored form,
    a downloaded one as it is.  (The stored form is not applied twice: storing truncates, so
    a download stored again would lose another centimetre.)"""
    return stored_item(item, autopilot) if sent else WireItem.normalised(**item.__dict__)


def capacity(autopilot: Autopilot) -> int:
    """Mission slots of a stock vehicle of this autopilot (ArduPilot's home slot included)."""
    return CAPACITY[autopilot]


# -- how a vehicle writes an upload --------------------------------------------------------------

#: MAV_MISSION_RESULT values the store answers with (pymavlink's).
ACCEPTED, ERROR, NO_SPACE = MAV_MISSION_ACCEPTED, MAV_MISSION_ERROR, MAV_MISSION_NO_SPACE
UNSUPPORTED_FRAME, UNSUPPORTED = MAV_MISSION_UNSUPPORTED_FRAME, MAV_MISSION_UNSUPPORTED

#: The MAV_CMD values a mission takes (ArduPilot's AP_Mission converts these; what else it is
#: sent it answers MAV_MISSION_UNSUPPORTED): navigation, conditions, DO_ and camera commands.
MISSION_COMMANDS = frozenset(
    {16, 17, 18, 19, 20, 21, 22, 30, 31, 42, 82, 83, 84, 85, 92, 93, 94, 112, 114, 115}
    | set(range(176, 225)) | {300, 2000, 2001, 2003, 2004, 2500, 2501, 3000, 42600, 42702, 42703}
    | {int(c) for c in Command})
#: The frames a mission item's position may be given in (global, relative, terrain; their _INT
#: forms; MAV_FRAME_MISSION for items without a position).
MISSION_FRAMES = frozenset({0, 2, 3, 5, 6, 10, 11})


class MissionStore:
    """The mission slots of one vehicle, written the way its autopilot writes an upload.

    ArduPilot (``AP_Mission`` behind ``MissionItemProtocol``) is not atomic: MISSION_COUNT
    truncates the stored mission to the new count, every item is written in place as it
    arrives (replacing the old item at its seq, or appended), and seq 0 is always its own
    home.  So an upload that breaks off after k items leaves the first k items of the new
    mission followed by what is left of the old one, up to the new count -- and that is what
    it downloads and what it flies.  PX4 receives into a second buffer and switches to it only
    when the whole mission has arrived: a broken upload leaves the old mission.

    Guarantees: :attr:`items` is at every moment exactly what a download returns and what a
    MISSION_START would fly (items as :func:`stored_item` keeps them).
    """

    def __init__(self, autopilot: Autopilot, slots: int | None = None,
                 home: WireItem | None = None, commands: frozenset[int] | None = None) -> None:
        self.autopilot = autopilot
        #: the commands it takes (a mission's by default; a geofence's or rally list's: theirs)
        self.commands = MISSION_COMMANDS if commands is None else commands
        self.slots = capacity(autopilot) if slots is None else slots
        self.home = home
        self.in_place = autopilot == Autopilot.ARDUPILOTMEGA
        self.items: list[WireItem] = self._empty()
        self._staged: list[WireItem] | None = None

    def _empty(self) -> list[WireItem]:
        return [self.home] if self.in_place and self.home is not None else []

    def clear(self) -> None:
        """MISSION_CLEAR_ALL: no mission (ArduPilot keeps its home slot)."""
        self.items = self._empty()
        self._staged = None

    def replace(self, items: list[WireItem]) -> None:
        """Hold exactly ``items`` (as sent; stored as the autopilot stores them)."""
        self.begin(len(items))
        for item in items:
            self.write(item)
        self.complete()

    def begin(self, count: int) -> int:
        """A MISSION_COUNT of ``count`` items: NO_SPACE beyond the slots (nothing changes),
        else ACCEPTED, with ArduPilot's mission truncated to ``count`` (never below its home)."""
        if count > self.slots:
            return NO_SPACE
        if self.in_place:
            self.items = self.items[:max(count, 1 if self.home is not None else 0)]
        else:
            self._staged = []
        return ACCEPTED

    def write(self, item: WireItem) -> int:
        """Item ``item.seq`` of the upload begun last: ACCEPTED; UNSUPPORTED for a command the
        autopilot's mission does not know, UNSUPPORTED_FRAME for a position in a frame it does
        not take (home's placeholder at seq 0 aside); ERROR for a seq beyond the end of what is
        stored (ArduPilot) or out of order (PX4)."""
        if item.seq > 0 or self.home is None:
            if item.command not in self.commands:
                return UNSUPPORTED
            if item.frame not in MISSION_FRAMES:
                return UNSUPPORTED_FRAME
            if (self.commands is MISSION_COMMANDS and self.autopilot == Autopilot.PX4
                    and px4_refusal(item) is not None):
                return px4_refusal(item)
        stored = (replace(stored_item(item, self.autopilot), current=0)
                  if self.commands is MISSION_COMMANDS else replace(item, current=0))
        if not self.in_place:
            if self._staged is None or item.seq != len(self._staged):
                return ERROR
            self._staged.append(stored)
            return ACCEPTED
        if item.seq == 0 and self.home is not None:
            stored = self.home                     # ArduPilot keeps its own home at seq 0
        if item.seq < len(self.items):
            self.items[item.seq] = stored
        elif item.seq == len(self.items):
            self.items.append(stored)
        else:
            return ERROR
        return ACCEPTED

    def complete(self) -> None:
        """The last item arrived: PX4 switches to the new mission."""
        if not self.in_place and self._staged is not None:
            self.items = self._staged
        self._staged = None

    def abort(self) -> None:
        """The upload broke off: PX4 drops the partial mission; ArduPilot keeps what it wrote."""
        self._staged = None
