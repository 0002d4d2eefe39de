"""Uploading a mission to a vehicle over MAVLink, and proving it arrived.

Every uploader, built-in or third-party, registers in the ``dtsp_mission.uploaders``
entry-point group as an :class:`Uploader` subclass.  :func:`upload_mission` is the one place
that turns a mission into wire items (ArduPilot's home placeholder included), runs the
upload, downloads the mission back and compares it item by item, and says exactly what the
vehicle holds when anything fails.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

from ..autopilot import MAVLINK_MAX_ITEMS, Autopilot
from ..autopilot.parameters import NAMES, PX4_NAMES, PX4Parameters, VehicleParameters, parameters_of
from ..errors import InputError, LinkError
from ..autopilot.commands import Command
from ..autopilot.mission import VehicleMission
from pymavlink.dialects.v20.common import MAV_MISSION_UNSUPPORTED
from ..plugins import load_group, working
from .base import VEHICLE_GIVES_UP_S, Progress, Uploader, VehicleInfo
from ..autopilot.wire import WireItem, describe_vehicle, differences, to_wire

UPLOADER_GROUP = "dtsp_mission.uploaders"


def uploaders() -> dict[str, type[Uploader] | Exception]:
    """Installed uploaders by name; a plugin that fails to load maps to its error."""
    return load_group(UPLOADER_GROUP, lambda e: isinstance(e, type) and issubclass(e, Uploader),
                      "an Uploader subclass")


def get_uploader(name: str) -> type[Uploader]:
    available = working(uploaders())
    if name not in available:
        raise InputError(f"unknown uploader {name!r} (installed: {', '.join(sorted(available))})")
    return available[name]


@dataclass(frozen=True)
class UploadReport:
    """What an upload did: items on the wire (home placeholder included), time, resends, and
    whether the downloaded mission was compared with the plan and matched."""

    via: str
    items: int
    seconds: float
    resent: int
    verified: bool
    note: str = ""
    warnings: tuple[str, ...] = ()    # what the vehicle differs in from what the plan expects
    fresh_starts: int = 0             # uploads started again with a new MISSION_COUNT
    round_trip_s: float | None = None # the link's smoothed round trip, where measured
    transfer_s: float = 0.0           # the upload and its verification, without connecting
    #: the geofence and rally points of the plan, one line each: sent and verified, or why not
    parts: tuple[str, ...] = ()


#: A plan whose home is farther than this from the vehicle's is warned about.
HOME_WARNING_M = 1000.0
_AUTOPILOT_NAMES = {Autopilot.ARDUPILOTMEGA: "ArduPilot", Autopilot.PX4: "PX4"}


def _autopilot_name(value: int) -> str:
    return _AUTOPILOT_NAMES.get(value, f"MAV_AUTOPILOT {value}")


#: The vehicle's wind estimate is worth a warning when it differs from the design wind by more
#: than this much speed or direction.
WIND_WARNING_M_S = 2.0
WIND_WARNING_DEG = 30.0
#: How long an upload of a mission designed for a wind listens for ArduPilot's wind estimate
#: (streamed at 1 Hz or more on a ground station's link).
WIND_WAIT_S = 1.5


def designed_parameters(mission: VehicleMission,
                        designed_for: VehicleParameters | PX4Parameters | None = None
                        ) -> VehicleParameters | PX4Parameters:
    """The navigation parameters ``mission`` was designed for: ``designed_for`` if it is its
    autopilot's, else those the mission records (a .plan written by dtsp-mission), else that
    autopilot's stock values."""
    return parameters_of(mission.autopilot, designed_for if designed_for is not None
                         else mission.designed_for)


def vehicle_warnings(mission: VehicleMission, info: VehicleInfo,
                     designed_for: VehicleParameters | PX4Parameters | None = None) -> list[str]:
    """What to tell before an upload: raises :class:`LinkError` if the vehicle runs another
    autopilot than the plan was made for; warns for each navigation parameter that differs
    from ``designed_for`` (the autopilot's stock values by default) and for a home far away."""
    if info.autopilot is not None and info.autopilot != int(mission.autopilot) and \
            info.autopilot in _AUTOPILOT_NAMES:
        raise LinkError(f"the plan was made for {_autopilot_name(mission.autopilot)}, but the "
                        f"vehicle runs {_autopilot_name(info.autopilot)}: plan again with "
                        f"`autopilot` {'px4' if info.autopilot == Autopilot.PX4 else 'ardupilot'}",
                        "nothing was sent; the vehicle keeps its mission")
    if info.vehicle_type is not None and info.vehicle_type not in FIXED_WING_TYPES:
        raise LinkError(f"the vehicle is {_vehicle_type_name(info.vehicle_type)} (MAV_TYPE "
                        f"{info.vehicle_type} in its heartbeat); these missions are for fixed "
                        "wings: is this the right vehicle?", "nothing was sent; the vehicle keeps "
                        "its mission")
    warnings = []
    if not info.checked:
        return ["the vehicle's parameters and home were not checked (this uploader cannot ask)"]
    unread = [name for name in info.asked if name not in info.parameters]
    if unread:
        warnings.append(f"could not read {', '.join(unread)} from the vehicle in time: "
                        "not compared with what the mission was designed for")
    if info.parameters:
        expected = designed_parameters(mission, designed_for)
        on_vehicle = expected.with_values(info.parameters)
        for name, ours, theirs in expected.differing(on_vehicle):
            warnings.append(f"the vehicle's {name} is {theirs:g}, the mission was designed for "
                            f"{ours:g}: it will fly differently than predicted")
    if info.wind is not None and mission.design_wind is not None:
        (speed, towards), (ours, our_dir) = info.wind, mission.design_wind
        turned = abs((towards - our_dir + 180.0) % 360.0 - 180.0)
        if abs(speed - ours) > WIND_WARNING_M_S or (max(speed, ours) >= 1.0 and turned > WIND_WARNING_DEG):
            warnings.append(f"the vehicle estimates a wind of {speed:.1f} m/s from {towards:.0f} deg; "
                            f"the mission was designed for {ours:g} m/s from {our_dir:g} deg: it "
                            "will fly differently than predicted (plan again with `wind` as the vehicle estimates it)")
    if info.home_deg is not None:
        from pyproj import Geod
        _, _, distance = Geod(ellps="WGS84").inv(mission.home.longitude_deg, mission.home.latitude_deg,
                                                 info.home_deg[1], info.home_deg[0])
        if distance > HOME_WARNING_M:
            warnings.append(f"the plan's home is {distance / 1000:.1f} km from the vehicle's home "
                            f"({info.home_deg[0]:.6f}, {info.home_deg[1]:.6f}): is this the right "
                            "vehicle and the right plan?")
    return warnings


#: MAV_TYPEs that fly fixed-wing missions: fixed wing and the VTOL types (19-25).
FIXED_WING_TYPES = {1, *range(19, 26)}


def _vehicle_type_name(value: int) -> str:
    from pymavlink.dialects.v20 import ardupilotmega
    entry = ardupilotmega.enums["MAV_TYPE"].get(value)
    name = entry.name.replace("MAV_TYPE_", "").replace("_", " ").lower() if entry else "unknown"
    return f"a {name}"


def read_vehicle(connection: str, signing_key: bytes | None = None,
                 heartbeat_timeout_s: float | None = None) -> VehicleInfo:
    """What a vehicle says of itself before a mission is designed for it: its autopilot and
    type (heartbeat), home (HOME_POSITION), the navigation parameters of its own autopilot
    (ArduPlane's or PX4's names) and, from ArduPilot, its wind estimate (WIND, listened for
    :data:`WIND_WAIT_S`).  :class:`LinkError` for a vehicle that does not answer, runs no
    autopilot this plans for, or is no fixed wing -- before anything is designed."""
    options = {} if heartbeat_timeout_s is None else {"heartbeat_timeout_s": heartbeat_timeout_s}
    uploader = get_uploader("pymavlink")(connection, signing_key=signing_key, **options)
    with uploader:
        autopilot = uploader._autopilot
        if autopilot not in _AUTOPILOT_NAMES:
            raise LinkError(f"the vehicle at {connection} runs {_autopilot_name(autopilot)}: "
                            "missions are planned for ArduPilot or PX4")
        names = NAMES if autopilot == Autopilot.ARDUPILOTMEGA else PX4_NAMES
        info = uploader.vehicle_info(names, WIND_WAIT_S if autopilot == Autopilot.ARDUPILOTMEGA
                                     else 0.0, autopilot)
    if info.vehicle_type is not None and info.vehicle_type not in FIXED_WING_TYPES:
        raise LinkError(f"the vehicle at {connection} is {_vehicle_type_name(info.vehicle_type)} "
                        f"(MAV_TYPE {info.vehicle_type}); missions are planned for fixed wings")
    return info


def _unstated_for_ardupilot(mission: VehicleMission) -> str:
    """The note for a mission file that does not say its autopilot, sent to an ArduPilot."""
    px4_only = sorted({int(i.command) for i in mission.items
                       if int(i.command) in (int(Command.DO_GIMBAL_MANAGER_PITCHYAW),
                                             int(Command.IMAGE_START_CAPTURE))})
    signs = (f": it holds commands only PX4 acts on ({', '.join(map(str, px4_only))}), so it was "
             "likely made for PX4" if px4_only else "")
    return ("the file does not say its autopilot (QGC WPL 110) and was sent as an ArduPilot "
            f"mission{signs}; check it was designed for ArduPilot (its waypoints are placed "
            "for the autopilot's guidance)")


def _unstated_for_px4(mission: VehicleMission) -> str:
    """The warning for a mission file that does not say its autopilot, sent to a PX4."""
    ends = ""
    if mission.items and mission.items[-1].command == Command.NAV_RETURN_TO_LAUNCH:
        ends = (": it ends in a return to launch, which PX4 flies by its own RTL_TYPE and "
                "RTL_RETURN_ALT (not ArduPlane's RTL_ALTITUDE and loiter); check them")
    return ("the file does not say its autopilot (QGC WPL 110 is ArduPilot's format) and was "
            "sent as a PX4 mission" + (ends or "; check it was designed for PX4"))


def upload_mission(mission: VehicleMission, connection: str, via: str = "pymavlink",
                   verify: bool = True, signing_key: bytes | None = None,
                   progress: Progress | None = None,
                   heartbeat_timeout_s: float | None = None,
                   designed_for: VehicleParameters | PX4Parameters | None = None,
                   timeout_s: float | None = None) -> UploadReport:
    """Upload ``mission`` and, with ``verify``, download it back and compare item by item.

    Before anything is sent, the vehicle's autopilot is checked against the plan's (a
    mismatch is a :class:`LinkError`) and its navigation parameters and home against the
    plan's (``designed_for``; differences become the report's ``warnings``).  Returns only
    when the vehicle accepted the mission (and, with ``verify``, holds what it can hold of
    it); otherwise raises :class:`LinkError` whose ``on_vehicle`` says what the vehicle holds.
    ``timeout_s`` bounds each transfer (upload, verification download); default
    :func:`~.base.transfer_timeout_s` of the mission's size.
    """
    uploader_class = get_uploader(via)
    if signing_key is not None and not uploader_class.supports_signing:
        raise InputError(f"the {via} uploader cannot sign MAVLink 2 messages; use `via` pymavlink")
    options = {} if heartbeat_timeout_s is None else {"heartbeat_timeout_s": heartbeat_timeout_s}
    if timeout_s is not None:
        if not timeout_s > 0:
            raise InputError(f"the transfer timeout must be above 0 s, got {timeout_s:g}")
        options["timeout_s"] = timeout_s
    wire = to_wire(mission)
    if len(wire) > MAVLINK_MAX_ITEMS:
        raise InputError(f"the mission has {len(wire)} items (with the vehicle's home slot) but "
                         f"MAVLink addresses at most {MAVLINK_MAX_ITEMS}: nothing was sent")
    started = time.perf_counter()
    with uploader_class(connection, signing_key=signing_key, **options) as uploader:
        # the navigation parameters by the names of the autopilot the plan is for; a file
        # that does not say its autopilot is ArduPilot's until the vehicle says otherwise
        names = (NAMES if mission.autopilot == Autopilot.ARDUPILOTMEGA
                 else PX4_NAMES if mission.autopilot_stated else ())
        info = uploader.vehicle_info(names, WIND_WAIT_S if mission.design_wind is not None
                                     and mission.autopilot == Autopilot.ARDUPILOTMEGA else 0.0,
                                     int(mission.autopilot))
        unstated = []
        if not mission.autopilot_stated and info.autopilot in _AUTOPILOT_NAMES:
            # A .waypoints file does not say its autopilot: it is meant for this vehicle's.
            mission = replace(mission, autopilot=Autopilot(info.autopilot), autopilot_stated=True)
            wire = to_wire(mission)
            unstated.append(_unstated_for_px4(mission) if mission.autopilot == Autopilot.PX4
                            else _unstated_for_ardupilot(mission))
        warnings = tuple(unstated + vehicle_warnings(mission, info, designed_for))
        transfer_started = time.perf_counter()
        try:
            uploader.upload(wire, progress)
        except LinkError as error:
            on_vehicle = _download_or_none(uploader) if verify else None
            if on_vehicle is not None and not differences(wire, on_vehicle, mission.autopilot):
                # The transfer broke off (typically the final ACK was lost), but the vehicle
                # demonstrably holds the plan: that is a verified upload.
                return UploadReport(via, len(wire), time.perf_counter() - started,
                                    uploader.resent, True,
                                    f"the transfer ended without an acknowledgement "
                                    f"({error.reason}), but the mission downloaded from the "
                                    "vehicle is exactly the plan", warnings,
                                    uploader.fresh_starts, _round_trip(uploader),
                                    time.perf_counter() - transfer_started)
            what = (describe_vehicle(on_vehicle, wire, mission.autopilot, error.nothing_sent)
                    if verify else
                    "the vehicle may hold part of this mission (not checked: `verify=False`)")
            raise LinkError(f"upload failed: {error.reason}", what) from None
        if verify:
            try:
                on_vehicle = uploader.download()
            except LinkError as error:
                raise LinkError(f"the vehicle accepted the mission, but downloading it back to "
                                f"verify failed: {error.reason}",
                                "what the vehicle holds is not verified") from None
            problems = differences(wire, on_vehicle, mission.autopilot)
            if problems:
                raise LinkError("the vehicle accepted the upload, but the mission downloaded "
                                "from it differs from the plan: " + "; ".join(problems),
                                describe_vehicle(on_vehicle, wire, mission.autopilot))
        parts = _upload_fence_and_rally(uploader, mission, verify)
        return UploadReport(via, len(wire), time.perf_counter() - started, uploader.resent,
                            verify, warnings=warnings, fresh_starts=uploader.fresh_starts,
                            round_trip_s=_round_trip(uploader),
                            transfer_s=time.perf_counter() - transfer_started, parts=parts)


#: The parts of a plan beside its mission items: (MAV_MISSION_TYPE, name, mission field).
OTHER_PARTS = ((1, "geofence", "fence"), (2, "rally points", "rally"))


def _upload_fence_and_rally(uploader: Uploader, mission: VehicleMission,
                            verify: bool) -> tuple[str, ...]:
    """Send the plan's geofence and rally points (MAV_MISSION_TYPE_FENCE, _RALLY), each
    downloaded back and compared with ``verify``: one line per part sent.  :class:`LinkError`
    naming the part when the vehicle refuses it (no fence support) or it does not arrive as
    sent; the mission items are on the vehicle and verified by then, and the message says so."""
    from ..autopilot.wire import other_differences, other_to_wire
    done = []
    for kind, name, field in OTHER_PARTS:
        items = getattr(mission, field)
        if not items:
            continue
        held = "the mission items are on the vehicle" + (" and verified" if verify else "")
        if kind not in uploader.mission_types:
            raise LinkError(f"the plan holds {name} ({len(items)} items), which the "
                            f"{uploader.name} uploader cannot send (mission items only): use "
                            "`via` pymavlink", held + f"; its {name} were not sent")
        wire = other_to_wire(items, kind)
        uploader.mission_type = kind
        try:
            try:
                uploader.upload(wire)
            except LinkError as error:
                refused = getattr(uploader, "last_refusal", None) == MAV_MISSION_UNSUPPORTED
                reason = ("the vehicle does not keep them (MAV_MISSION_UNSUPPORTED: no "
                          f"{'fence' if kind == 1 else 'rally'} support)" if refused
                          else error.reason)
                raise LinkError(f"the {name} were not accepted: {reason}",
                                held + f"; what {name} it holds is unknown") from None
            if verify:
                problems = other_differences(wire, uploader.download())
                if problems:
                    raise LinkError(f"the vehicle accepted the {name}, but they downloaded back "
                                    "differently: " + "; ".join(problems),
                                    held + f"; do not rely on its {name}")
        finally:
            uploader.mission_type = 0
        done.append(f"{name}: {len(wire)} items sent" + (", downloaded back equal" if verify else ""))
    return tuple(done)


def _round_trip(uploader: Uploader) -> float | None:
    timer = getattr(uploader, "_timer", None)
    return getattr(timer, "srtt_s", None)


#: After a failed upload, what the vehicle holds is asked for this long at least: ArduPilot
#: refuses downloads (DENIED) until it gives the broken upload up itself, after 8 s.
AFTER_FAILURE_S = VEHICLE_GIVES_UP_S + 4.0


def _download_or_none(uploader: Uploader) -> list[WireItem] | None:
    """The vehicle's mission after a failure, or None if it cannot be had either."""
    if uploader.timeout_s is not None:
        uploader.timeout_s = max(uploader.timeout_s, AFTER_FAILURE_S)
    try:
        return uploader.download()
    except LinkError:
        return None


def download_mission(connection: str, via: str = "pymavlink",
                     signing_key: bytes | None = None) -> list[WireItem]:
    """The mission a vehicle holds, as wire items, seq 0 first."""
    with get_uploader(via)(connection, signing_key=signing_key) as uploader:
        return uploader.download()


__all__ = ["UPLOADER_GROUP", "UploadReport", "Uploader", "VehicleInfo", "WireItem", "download_mission",
           "read_vehicle",
           "get_uploader", "to_wire", "upload_mission", "uploaders", "vehicle_warnings"]
