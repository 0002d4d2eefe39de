"""Checking a mission before a real flight: upload it to the simulated vehicle over loopback
UDP, fly it, and measure from the vehicle's own telemetry how close it passed each target.

Miss distances come from the GLOBAL_POSITION_INT stream a ground station receives (the
closest approach of the reported track to each target), not from the simulator's insides;
the flight time is the simulator's clock.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from pymavlink import mavutil

from ..errors import InputError, LinkError
from ..frame import LocalFrame
from ..targets.model import target_name
from ..autopilot.commands import Command
from ..autopilot.mission import VehicleMission
from ..upload import UploadReport, upload_mission
from ..upload.pymavlink_link import GCS_COMPONENT_ID, GCS_SYSTEM_ID, use_mavlink2
from ..autopilot.navigation import CALM, Airframe, Wind, closest_approach_m
from .vehicle import MAV_CMD_MISSION_START, SimulatedVehicle, VehicleSettings


@dataclass(frozen=True)
class Targets:
    """Where the targets are: degrees, altitude above home (NaN: not checked), names."""

    latitudes_deg: np.ndarray
    longitudes_deg: np.ndarray
    altitudes_m: np.ndarray
    names: tuple[str, ...]


def planned_targets(mission) -> Targets:
    """The targets of a planned :class:`~dtsp_mission.mission.Mission` themselves (not their
    waypoints, which the guidance design aims elsewhere), in visiting order, with the
    altitude of their waypoint and their names."""
    return _as_targets(mission.visited_targets())


def _as_targets(targets) -> Targets:
    return Targets(np.array([t.latitude_deg for t in targets], dtype=float),
                   np.array([t.longitude_deg for t in targets], dtype=float),
                   np.array([t.altitude_m for t in targets], dtype=float),
                   tuple(t.name for t in targets))


def targets_from(geodetic) -> Targets:
    """The targets of a targets file (:class:`~dtsp_mission.targets.GeoTargets`), in its
    order, named as ``plan`` names them; altitudes not given are not checked."""
    count = len(geodetic)
    altitudes = (np.full(count, np.nan) if geodetic.altitudes_m is None
                 else np.asarray(geodetic.altitudes_m, dtype=float))
    return Targets(np.asarray(geodetic.latitudes_deg), np.asarray(geodetic.longitudes_deg),
                   altitudes, tuple(target_name(geodetic.names, i) for i in range(count)))


#: A simulated vehicle that sends no telemetry for this long has stopped (s, wall clock).
SILENCE_S = 20.0
#: A target farther than this from every position of a mission was not planned with it.
FAR_FROM_MISSION_M = 5_000.0


def mission_places_m(mission: VehicleMission) -> tuple[LocalFrame, np.ndarray, list]:
    """The local frame around the mission's home; in it, home (row 0) and the positioned
    items; and those items."""
    frame = LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg)
    positioned = [i for i in mission.items if i.has_position]
    places = np.vstack([np.zeros((1, 2))] + ([frame.to_local([i.latitude_deg for i in positioned],
                                                             [i.longitude_deg for i in positioned])]
                                             if positioned else []))
    return frame, places, positioned


def estimated_flight_m(mission: VehicleMission, loiter_radius_m: float) -> float:
    """A quick estimate of the flight's length for a progress message (not a prediction):
    straight legs from home through the positioned items, the loiter circles' turns
    (``loiter_radius_m`` where an item gives none), and the way back home after a return."""
    _, places, positioned = mission_places_m(mission)
    length = float(np.hypot(*np.diff(places, axis=0).T).sum())
    for item in positioned:
        if item.command == Command.NAV_LOITER_TURNS:
            radius = abs(item.params[2]) or loiter_radius_m
            length += 2.0 * math.pi * radius * max(1.0, float(item.params[0]))
    if mission.items and mission.items[-1].command == Command.NAV_RETURN_TO_LAUNCH:
        length += float(np.hypot(*places[-1]))
    return length


#: The longest flight the simulator flies (s of simulated flight): a day.
MAX_SIMULATED_FLIGHT_S = 24 * 3600.0
#: Items an autopilot flies that the flight model does not, and why no flight of them is
#: "complete" in the simulator.
NOT_FLOWN = {
    int(Command.NAV_LOITER_UNLIM): "loiters until told otherwise: the flight never ends by itself",
    93: "waits (NAV_DELAY) before going on, which the flight model does not fly",
    177: "jumps back (DO_JUMP), which the flight model does not fly",
}


def estimated_flight_s(mission: VehicleMission, airframe: Airframe) -> float:
    """A quick estimate of the flight's duration (:func:`estimated_flight_m` at the airspeed,
    and the time NAV_LOITER_TIME items hold)."""
    held = sum(max(0.0, float(item.params[0])) for item in mission.items
               if item.command == Command.NAV_LOITER_TIME)
    return estimated_flight_m(mission, airframe.loiter_radius_m) / airframe.airspeed_m_s + held


def check_flyable(mission: VehicleMission, airframe: Airframe) -> None:
    """:class:`InputError` for a mission the simulator cannot fly as the autopilot would --
    an item it does not model (DO_JUMP, NAV_LOITER_UNLIM, NAV_DELAY, another navigation
    command), or a flight longer than :data:`MAX_SIMULATED_FLIGHT_S` -- so that no such
    flight is reported complete (or waited for for ever)."""
    from ..autopilot.navigation import NAV_COMMANDS
    for number, item in enumerate(mission.items, start=1):
        command = int(item.command)
        reason = NOT_FLOWN.get(command)
        if reason is None and command < 100 and command not in {int(c) for c in NAV_COMMANDS}:
            reason = "is a navigation command the flight model does not fly"
        if reason is not None:
            extra = ""
            if command == 177:
                extra = (f" (to item {item.params[0]:g}, "
                         + ("for ever" if item.params[1] < 0 else f"{item.params[1]:g} times")
                         + ")")
            raise InputError(f"item {number} (command {command}){extra} {reason}; the simulator "
                             "would report a flight the vehicle does not make, so it does not "
                             "fly this mission")
    flight_s = estimated_flight_s(mission, airframe)
    if not flight_s <= MAX_SIMULATED_FLIGHT_S:
        raise InputError(f"the mission would fly for about {flight_s / 3600:,.0f} h (its legs and "
                         "loiter times); the simulator flies at most "
                         f"{MAX_SIMULATED_FLIGHT_S / 3600:.0f} h: check the loiter times and the "
                         "positions")


def check_targets_near(mission: VehicleMission, targets: Targets, where: str) -> None:
    """:class:`InputError` when a target is more than :data:`FAR_FROM_MISSION_M` from every
    position of the mission (its home and items): they are not this mission's targets."""
    frame, places, _ = mission_places_m(mission)
    points = frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    gaps = np.array([np.hypot(*(places - point).T).min() for point in points])
    if len(gaps) and gaps.max() > FAR_FROM_MISSION_M:
        k = int(np.argmax(gaps))
        raise InputError(f"{where}: {targets.names[k]} is {gaps[k] / 1000:,.1f} km from the "
                         "mission's nearest waypoint and its home: these are not the targets "
                         "this mission was planned for")


def targets_in(mission: VehicleMission, names: tuple[str, ...] | None = None) -> Targets:
    """The mission's targets in visiting order: those it carries (a plan file written by
    dtsp-mission, a planned mission), else its ``target`` items (named from ``names`` by target
    index), or -- for items read from a file that carries no targets and no roles -- every
    NAV_WAYPOINT with an acceptance radius (how dtsp-mission writes targets)."""
    if mission.targets:
        return _as_targets(mission.targets)
    chosen = [item for item in mission.items if item.role == "target"]
    if chosen:
        labels = tuple(target_name(names, i.target) for i in chosen)
    else:
        numbered = [(seq, item) for seq, item in enumerate(mission.items, start=1)
                    if item.command == Command.NAV_WAYPOINT and item.params[1] > 0]
        chosen = [item for _, item in numbered]
        # A file carries the targets' waypoints, not the targets: named by their visit.
        labels = tuple(f"target waypoint {k} (item {seq})"
                       for k, (seq, _) in enumerate(numbered, start=1))
    return Targets(np.array([i.latitude_deg for i in chosen]),
                   np.array([i.longitude_deg for i in chosen]),
                   np.array([i.altitude_m for i in chosen]), labels)


@dataclass(frozen=True)
class FlightCheck:
    """What the simulated flight showed."""

    upload: UploadReport
    completed: bool
    flight_time_s: float
    items_reached: int
    items: int
    miss_m: np.ndarray                 # per target, horizontal closest approach
    altitude_error_m: np.ndarray       # per target, reported minus planned, at closest approach
    names: tuple[str, ...]
    min_turn_radius_m: float           # smallest radius seen in the telemetry (1 s windows)
    samples: int
    airframe: Airframe
    #: position reports the vehicle sent that did not arrive (gaps in their vehicle time):
    #: where this is not 0 the misses are measured on a track with holes
    lost_reports: int = 0

    @property
    def max_miss_m(self) -> float:
        return float(self.miss_m.max()) if len(self.miss_m) else 0.0


def fly_mission(mission: VehicleMission, targets: Targets, airframe: Airframe,
                via: str = "pymavlink", speedup: float = 50.0, telemetry_hz: float = 10.0,
                progress: Callable[[str, int, int], None] | None = None,
                timeout_s: float | None = None, max_items: int | None = None,
                wind: Wind = CALM) -> FlightCheck:
    """Upload ``mission`` to a simulated vehicle with ``airframe`` and ``max_items`` mission
    slots (None: a stock vehicle's), fly it in ``wind``, and measure."""
    settings = VehicleSettings(mission.home, mission.autopilot, airframe, speedup,
                               telemetry_hz=telemetry_hz, max_items=max_items, wind=wind)
    with SimulatedVehicle(settings) as vehicle:
        connection = f"udpout:127.0.0.1:{vehicle.port}"
        report = upload_mission(mission, connection, via=via,
                                progress=(lambda d, t, _resent: progress("upload", d, t)) if progress else None)
        track, reached = _watch(vehicle, connection, mission, speedup, progress, timeout_s)
        flight_time = vehicle.log.reached[-1][1] if vehicle.log.reached else 0.0
        items = len(vehicle.mission)
    local_track = vehicle.frame.to_local(track[:, 0], track[:, 1]) if len(track) else np.zeros((0, 2))
    local_targets = vehicle.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    if len(local_track) >= 2:
        miss = closest_approach_m(local_track, local_targets)
        # The altitude error where the track comes closest in 3-D: a target under the
        # climb-out is overflown low first and at altitude later.
        # A target without an altitude (NaN) has no altitude error.
        nearest = np.array([int(np.argmin(np.hypot(np.hypot(*(local_track - p).T),
                                                   track[:, 2] - z if np.isfinite(z) else 0.0)))
                            for p, z in zip(local_targets, targets.altitudes_m)], dtype=np.int64)
        altitude_error = track[nearest, 2] - targets.altitudes_m
    else:
        miss = np.full(len(local_targets), np.inf)
        altitude_error = np.full(len(local_targets), np.nan)
    return FlightCheck(report, reached == items - 1, flight_time, reached + 1, items, miss,
                       altitude_error, targets.names, _min_turn_radius(local_track, track[:, 3:5],
                                                                       telemetry_hz),
                       len(track), airframe, lost_reports(track[:, 5], telemetry_hz))


def _watch(vehicle: SimulatedVehicle, connection: str, mission: VehicleMission, speedup: float,
           progress, timeout_s: float | None) -> tuple[np.ndarray, int]:
    """Start the mission with MAV_CMD_MISSION_START and record the telemetry until the last
    item is reached; returns rows (lat, lon, relative alt, v_north, v_east, vehicle time s)
    and the highest seq reached."""
    use_mavlink2()
    link = mavutil.mavlink_connection(connection, source_system=GCS_SYSTEM_ID,
                                      source_component=GCS_COMPONENT_ID)
    _widen_receive_buffer(link)
    rows = []
    highest = -1
    last_seq = len(vehicle.mission) - 1
    try:
        link.mav.heartbeat_send(6, 8, 0, 0, 0)
        link.mav.command_long_send(1, 1, MAV_CMD_MISSION_START, 0, 0, 0, 0, 0, 0, 0, 0)
        ack = link.recv_match(type="COMMAND_ACK", blocking=True, timeout=5)
        if ack is None or ack.result != 0:
            raise LinkError("the simulated vehicle did not start the mission")
        airframe = vehicle.settings.airframe
        flight_s = estimated_flight_s(mission, airframe)
        # Twice the estimated flight (at least 4 h of it) at the speed-up, and time to start.
        budget = timeout_s or (60.0 + 2 * max(flight_s, 7200.0) / max(speedup, 1.0)
                               + len(mission.items))
        deadline = time.monotonic() + budget
        last_heartbeat, last_heard = 0.0, time.monotonic()
        while highest < last_seq:
            now = time.monotonic()
            if now > deadline:
                raise LinkError(f"the simulated flight did not finish within {budget:.0f} s "
                                f"(reached item {highest} of {last_seq})")
            if now - last_heard > SILENCE_S:
                raise LinkError(f"the simulated vehicle sent nothing for {SILENCE_S:g} s "
                                f"(reached item {highest} of {last_seq})")
            if time.monotonic() - last_heartbeat > 1.0:
                link.mav.heartbeat_send(6, 8, 0, 0, 0)
                last_heartbeat = time.monotonic()
            message = link.recv_match(type=["GLOBAL_POSITION_INT", "MISSION_ITEM_REACHED"],
                                      blocking=True, timeout=0.5)
            if message is None:
                continue
            last_heard = time.monotonic()
            if message.get_type() == "GLOBAL_POSITION_INT":
                rows.append((message.lat / 1e7, message.lon / 1e7, message.relative_alt / 1e3,
                             message.vx / 100.0, message.vy / 100.0, message.time_boot_ms / 1e3))
            elif message.seq > highest:
                highest = message.seq
                if progress is not None:
                    progress("flight", highest, last_seq)
    finally:
        link.close()
    return np.array(rows).reshape(-1, 6), highest


def lost_reports(times_s: np.ndarray, rate_hz: float) -> int:
    """How many reports sent every ``1 / rate_hz`` s of vehicle time are missing from
    ``times_s`` (received, in order)."""
    if len(times_s) < 2:
        return 0
    gaps = np.diff(np.asarray(times_s, dtype=float)) * rate_hz
    return int(np.maximum(np.round(gaps) - 1.0, 0.0).sum())


def _widen_receive_buffer(link) -> None:
    """Room for a few seconds of telemetry in the socket, so that a ground station busy for a
    moment loses nothing (the kernel caps what it grants)."""
    import socket
    port = getattr(link, "port", None)
    if isinstance(port, socket.socket):
        try:
            port.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
        except OSError:
            pass


def _min_turn_radius(track_m: np.ndarray, velocity_ne: np.ndarray, rate_hz: float) -> float:
    """Smallest radius over 1 s windows: distance flown over heading change, from positions
    and the reported velocity (turns of less than 3 degrees in a window are straight)."""
    window = max(2, int(round(rate_hz)))
    if len(track_m) <= window:
        return math.inf
    heading = np.unwrap(np.arctan2(velocity_ne[:, 0], velocity_ne[:, 1]))
    step = np.hypot(*np.diff(track_m, axis=0).T)
    flown = np.convolve(step, np.ones(window), "valid")
    turned = np.abs(heading[window:] - heading[:-window])
    turning = turned > math.radians(3)
    return float((flown[turning] / turned[turning]).min()) if turning.any() else math.inf
