"""One real flight: start the SITL autopilot, upload the mission with the project's uploader
(verified by download), set AUTO, arm, and record GLOBAL_POSITION_INT until the mission's last
waypoint or loiter is reached; then measure each target's miss and, beside it, what the
flight model predicted for the same mission, aircraft and wind.

The miss of a target is the least horizontal distance from it to the recorded track (straight
segments between the 10 Hz samples of vehicle time) from the take-off item's completion to
the last waypoint's, as the recorded sets in the workplace measure it."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..autopilot import Autopilot, Command
from ..autopilot.mission import VehicleMission
from ..autopilot.navigation import CALM, Airframe, Wind, closest_approach_m, launch_heading_rad, local_items
from ..autopilot.wire import first_mission_seq, to_wire
from ..errors import LinkError
from ..frame import LocalFrame
from ..upload import UploadReport, upload_mission
from ..upload.datagrams import keep_only
from ..upload.pymavlink_link import GCS_COMPONENT_ID, GCS_SYSTEM_ID, use_mavlink2
from .binaries import SitlBinaries
from .processes import ArduPlaneSitl, Px4Sitl, SitlSettings

_FLOWN = (Command.NAV_WAYPOINT, Command.NAV_LOITER_TURNS, Command.NAV_LOITER_TIME)
ARDUPLANE_AUTO = 10
MAV_CMD_DO_SET_MODE, MAV_CMD_COMPONENT_ARM_DISARM, MAV_CMD_SET_MESSAGE_INTERVAL = 176, 400, 511
GLOBAL_POSITION_INT_ID = 33
ARMED_FLAG = 128
#: What is recorded after the last waypoint is reached (vehicle seconds).
AFTER_LAST_S = 10.0
#: What a flight's recorder reads (the rest of the vehicle's telemetry is dropped undecoded;
#: pymavlink's ``recv_match`` takes a list or a set, and reads a frozenset as one type name).
RECORDS = frozenset({"HEARTBEAT", "GLOBAL_POSITION_INT", "MISSION_ITEM_REACHED", "MISSION_CURRENT"})


@dataclass(frozen=True)
class RealFlight:
    """What the real autopilot flew: the track (rows: vehicle time s, x, y, height above home,
    in the local frame at home), when each vehicle seq was reached (vehicle time s), the seq
    of the take-off item and of the last waypoint, and the upload's report."""

    autopilot: str
    track: np.ndarray
    reached: dict[int, float]
    first_seq: int
    last_seq: int
    frame: LocalFrame
    upload: UploadReport
    wall_s: float

    def window(self) -> np.ndarray:
        """The track's (x, y) from the take-off item's completion to the last waypoint's."""
        return measured_span(self.track, self.reached, self.first_seq, self.last_seq)

    @property
    def completed(self) -> bool:
        return self.last_seq in self.reached

    @property
    def flight_time_s(self) -> float:
        """Vehicle time from the take-off item's completion to the last waypoint's (NaN if
        the last was not reached)."""
        if not self.completed or self.first_seq not in self.reached:
            return math.nan
        return self.reached[self.last_seq] - self.reached[self.first_seq]

    @property
    def flown_m(self) -> float:
        """Ground distance of :meth:`window`."""
        xy = self.window()
        return float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0


def measured_span(track: np.ndarray, reached: dict[int, float], first: int, last: int) -> np.ndarray:
    """(x, y) of the track rows (time, x, y, ...) from the reaching of ``first`` (the take-off
    item; the start if it was not reached) to that of ``last`` (the end if not reached)."""
    start = reached.get(first, track[0, 0] if len(track) else 0.0)
    end = reached.get(last, math.inf)
    keep = (track[:, 0] >= start) & (track[:, 0] <= end)
    return track[keep, 1:3]


def mission_seqs(mission: VehicleMission) -> tuple[int, int]:
    """The vehicle seq of the take-off item (the first mission item) and of the last
    waypoint or loiter."""
    wire = to_wire(mission)
    first = first_mission_seq(mission.autopilot)
    last = max((w.seq for w in wire if w.command in _FLOWN), default=first)
    return first, last


def launch_heading_deg(mission: VehicleMission) -> float:
    """Degrees true the aircraft stands facing at home: towards the first positioned item, as
    the flight model starts it."""
    frame = LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg)
    items = local_items(to_wire(mission), frame, mission.home.altitude_amsl_m)
    heading = launch_heading_rad(items, first_mission_seq(mission.autopilot))
    return (90.0 - math.degrees(heading)) % 360.0


#: ArduPlane's SITL is lock-stepped: a busy machine slows it, never changes its flight.  At 40 x
#: a flight differs from one at 20 x as one at 20 x differs from its own repeat (dense 100, calm:
#: per target median 0.07 / p95 0.39 / max 0.73 m at 40 x, 0.08 / 0.34 / 0.94 m repeated at
#: 20 x; the 400-target site's 6,074 s flight at 40 x: every 10 Hz position report arrived).
ARDUPLANE_SPEEDUP = 40.0


def fly_real(mission: VehicleMission, binaries: SitlBinaries, parameters: dict[str, float] | None = None,
             wind: Wind = CALM, speedup: float | None = None, instance: int = 0,
             progress: Callable[[str], None] | None = None,
             timeout_s: float | None = None) -> RealFlight:
    """Fly ``mission`` in the real autopilot it was made for (ArduPlane or PX4 SITL, stock
    but for ``parameters``) in ``wind``; raises :class:`LinkError` where the autopilot is
    missing, refuses the mission or does not finish within ``timeout_s`` of wall time
    (default: twice the flight's estimate at the speed-up, plus two minutes)."""
    px4 = mission.autopilot == Autopilot.PX4
    kind = "px4" if px4 else "ardupilot"
    why = binaries.missing(kind)
    if why:
        raise LinkError(f"cannot fly in the real {kind}: {why}")
    speedup = speedup or (8.0 if px4 else ARDUPLANE_SPEEDUP)
    home = mission.home
    settings = SitlSettings(home.latitude_deg, home.longitude_deg, home.altitude_amsl_m,
                            launch_heading_deg(mission), dict(parameters or {}), wind, speedup,
                            instance)
    sitl = Px4Sitl(binaries.px4, settings) if px4 else ArduPlaneSitl(binaries.arduplane, settings)
    first, last = mission_seqs(mission)
    started = time.monotonic()
    say = progress or (lambda _m: None)
    with sitl:
        say(f"{kind} SITL started")
        _wait_ready(sitl.connection)
        report = upload_mission(mission, sitl.connection, heartbeat_timeout_s=60.0)
        say(f"uploaded {report.items} items, verified: {report.verified}")
        from ..sim.fly import estimated_flight_m
        # the flight's length straight through the items, at a slow 15 m/s (loiters at 80 m)
        estimate_s = estimated_flight_m(mission, 80.0) / 15.0
        budget = timeout_s or 120.0 + 2.0 * estimate_s / speedup
        track, reached = _fly(sitl.connection, px4, first, last, budget, say)
    frame = LocalFrame(home.latitude_deg, home.longitude_deg)
    rows = np.array(track, dtype=float).reshape(-1, 4)
    if len(rows):
        rows[:, 1:3] = frame.to_local(rows[:, 1], rows[:, 2])
    return RealFlight(kind, rows, reached, first, last, frame, report, time.monotonic() - started)


def _link(connection: str, listens_to: frozenset[str]):
    """A pymavlink link to the SITL that decodes only datagrams with ``listens_to`` messages
    (PX4 sends thousands of telemetry messages a second to the ground station's port)."""
    use_mavlink2()
    from pymavlink import mavutil
    deadline = time.monotonic() + 30.0
    while True:
        try:
            link = mavutil.mavlink_connection(connection, source_system=GCS_SYSTEM_ID,
                                              source_component=GCS_COMPONENT_ID, autoreconnect=False)
            keep_only(link, listens_to)
            return link
        except OSError:
            if time.monotonic() > deadline:
                raise LinkError(f"could not connect to the SITL at {connection}") from None
            time.sleep(0.2)


def _vehicle_heartbeat(link, timeout_s: float):
    """The next HEARTBEAT of the autopilot (component 1), or None."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        message = link.recv_match(type="HEARTBEAT", blocking=True, timeout=0.5)
        if message is not None and message.get_srcComponent() == 1 and message.type != 6:
            return message
    return None


def _wait_ready(connection: str) -> None:
    """Until the autopilot's heartbeat says STANDBY (booted, calibrated)."""
    link = _link(connection, frozenset({"HEARTBEAT"}))
    try:
        deadline = time.monotonic() + 90.0
        while time.monotonic() < deadline:
            link.mav.heartbeat_send(6, 8, 0, 0, 0)
            beat = _vehicle_heartbeat(link, 2.0)
            if beat is not None and beat.system_status >= 3:
                return
        raise LinkError("the SITL autopilot did not reach STANDBY within 90 s")
    finally:
        link.close()


def _fly(connection: str, px4: bool, first: int, last: int, budget_s: float, say) -> tuple[list, dict[int, float]]:
    """Set AUTO until it holds, arm, and record until ``last`` is reached (plus
    :data:`AFTER_LAST_S`); returns rows (time, lat, lon, height) and reach times by seq."""
    link = _link(connection, RECORDS)
    records = list(RECORDS)
    rows: list[tuple[float, float, float, float]] = []
    reached: dict[int, float] = {}
    now_s = 0.0
    try:
        link.mav.heartbeat_send(6, 8, 0, 0, 0)
        beat = _vehicle_heartbeat(link, 20.0)
        if beat is None:
            raise LinkError("the SITL autopilot sent no heartbeat after the upload")
        target = beat.get_srcSystem()
        link.mav.command_long_send(target, 1, MAV_CMD_SET_MESSAGE_INTERVAL, 0,
                                   GLOBAL_POSITION_INT_ID, 100_000, 0, 0, 0, 0, 0)
        deadline = time.monotonic() + budget_s
        held, away, armed, last_command, last_heartbeat, done_at = 0, 0, False, 0.0, 0.0, None
        while True:
            wall = time.monotonic()
            if wall > deadline:
                raise LinkError(f"the real flight did not finish within {budget_s:.0f} s of wall "
                                f"time (reached seq {max(reached, default=-1)} of {last})")
            if wall - last_heartbeat > 0.5:
                link.mav.heartbeat_send(6, 8, 0, 0, 0)
                last_heartbeat = wall
            if not armed and wall - last_command > 0.5:
                if held < 3:
                    if px4:
                        link.mav.command_long_send(target, 1, MAV_CMD_DO_SET_MODE, 0, 1, 4, 4,
                                                   0, 0, 0, 0)
                    else:
                        link.mav.command_long_send(target, 1, MAV_CMD_DO_SET_MODE, 0, 1,
                                                   ARDUPLANE_AUTO, 0, 0, 0, 0, 0)
                else:
                    link.mav.command_long_send(target, 1, MAV_CMD_COMPONENT_ARM_DISARM, 0, 1,
                                               0, 0, 0, 0, 0, 0)
                last_command = wall
            message = link.recv_match(type=records, blocking=True, timeout=0.5)
            if message is None:
                continue
            kind = message.get_type()
            if kind == "HEARTBEAT":
                if message.get_srcComponent() != 1 or message.type == 6:
                    continue
                in_mode = (message.custom_mode == ARDUPLANE_AUTO if not px4 else
                           (message.custom_mode >> 16) & 0xFF == 4           # AUTO, and
                           and (message.custom_mode >> 24) in (2, 4))      # TAKEOFF or MISSION
                held = held + 1 if in_mode else 0
                away = 0 if in_mode else away + 1
                if message.base_mode & ARMED_FLAG and not armed:
                    armed = True
                    say("armed in AUTO")
                if armed and away >= 2 and done_at is None:
                    # ArduPlane switches to RTL as the mission's last item, sometimes before
                    # the last waypoint's MISSION_ITEM_REACHED arrives: record a little more
                    done_at = now_s
                    say(f"left AUTO (mode {message.custom_mode}) at {now_s:.0f} s")
            elif kind == "GLOBAL_POSITION_INT":
                now_s = message.time_boot_ms / 1000.0
                if armed:
                    rows.append((now_s, message.lat / 1e7, message.lon / 1e7,
                                 message.relative_alt / 1000.0))
                if done_at is not None and now_s >= done_at + AFTER_LAST_S:
                    break
            elif kind == "MISSION_CURRENT":
                # a take-off's completion is not always reported as reached: an item the
                # autopilot has moved past was reached when the next became current
                if armed:
                    for seq in range(first, message.seq):
                        reached.setdefault(seq, now_s)
            elif kind == "MISSION_ITEM_REACHED":
                if message.seq not in reached:
                    reached[message.seq] = now_s
                    if message.seq >= last and done_at is None:
                        done_at = now_s
                        say(f"last waypoint (seq {last}) reached at {now_s:.0f} s")
    finally:
        link.close()
    return rows, reached


@dataclass(frozen=True)
class TargetReport:
    """Per target (visiting order): the real miss, the model's predicted miss, the names,
    and the flown lengths (real, model) of the measured window."""

    names: tuple[str, ...]
    real_miss_m: np.ndarray
    model_miss_m: np.ndarray
    real_flown_m: float
    model_flown_m: float
    real_time_s: float
    model_time_s: float


def compare_with_model(mission: VehicleMission, flight: RealFlight, airframe: Airframe,
                       wind: Wind = CALM, targets=None) -> TargetReport:
    """Each target's real miss beside the flight model's for the same mission, ``airframe``
    and ``wind``; ``targets`` (:class:`~dtsp_mission.sim.fly.Targets`) default to those the
    mission carries."""
    from ..sim.fly import targets_in
    from ..sim.predict import predict_flight
    targets = targets if targets is not None else targets_in(mission)
    points = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    real = closest_approach_m(flight.window(), points)
    predicted = predict_flight(mission, airframe, wind=wind)
    model_xy = measured_span(predicted.track, predicted.reached, flight.first_seq, flight.last_seq)
    model = closest_approach_m(model_xy, points)
    model_flown = float(np.hypot(*np.diff(model_xy, axis=0).T).sum()) if len(model_xy) > 1 else 0.0
    model_time = (predicted.reached[flight.last_seq] - predicted.reached.get(flight.first_seq, 0.0)
                  if flight.last_seq in predicted.reached else math.nan)
    return TargetReport(targets.names, real, model, flight.flown_m, model_flown,
                        flight.flight_time_s, model_time)
