"""A simulated fixed-wing vehicle that speaks MAVLink: the mission protocol is served by the
vehicle's own code as ArduPilot runs it (:mod:`.mission_server`, on the autopilot's
:class:`~dtsp_mission.autopilot.storage.MissionStore`: items written in place as they arrive,
what it downloads is what it flies), :class:`~dtsp_mission.autopilot.navigation.MissionFlight`
flies and the vehicle's encoder reports its positions (MAVSDK supplies the heartbeat,
AUTOPILOT_VERSION and the home position).

Why not MAVSDK's ``mission_raw_server``: it accepts a mission only as a whole and hands it
over after its final ACK, so after an upload that broke off it cannot hold what an ArduPilot
holds (the first items of the new mission), and under 5 % loss with duplicates and
reordering 4 of 5 verification downloads from it stalled (measured for the upload issue).

MAVSDK runs on a ``raw://`` connection; this module owns the link (:mod:`.transport`: UDP,
TCP or a pseudo-terminal) and sits between it and the ground station, adding a heartbeat as a
fixed wing of the chosen autopilot, parameters and home on request, MAVLink 2 signing,
MAV_CMD_MISSION_START, MISSION_CURRENT / MISSION_ITEM_REACHED while flying, and a restart
(fault injection).
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field, fields

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega
from pymavlink.dialects.v20 import common as mavlink2
from pymavlink.dialects.v20.common import (MAVLINK_MSG_ID_HOME_POSITION, MAV_CMD_MISSION_START,
                                           MAV_MISSION_UNSUPPORTED,
                                           MAV_CMD_REQUEST_MESSAGE, MAV_MODE_FLAG_AUTO_ENABLED,
                                           MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
                                           MAV_MODE_FLAG_SAFETY_ARMED, MAV_PARAM_TYPE_REAL32,
                                           MAV_RESULT_ACCEPTED, MAV_RESULT_DENIED,
                                           MAV_STATE_ACTIVE, MAV_STATE_STANDBY,
                                           MAV_TYPE_FIXED_WING)

from ..autopilot.navigation import (CALM, MODEL_STEP_S, Airframe, LocalItem, MissionFlight, Wind,
                                    launch_heading_rad, local_items)
from ..autopilot.parameters import PX4Parameters, VehicleParameters, parameter_name, parameters_of
from ..autopilot.storage import MISSION_TYPE_MISSION, MissionStore, stored_item
from ..frame import LocalFrame
from ..mavsdk_log import quiet_mavsdk_log
from ..autopilot.commands import Autopilot
from ..autopilot.mission import Home, degrees_to_e7
from ..autopilot.wire import WireItem, first_mission_seq, home_placeholder
from .mission_server import PROTOCOL_MESSAGES, MissionServer

#: MAV_MISSION_TYPE of the geofence and of the rally points.
MISSION_TYPE_FENCE, MISSION_TYPE_RALLY = 1, 2
#: Fence vertices and rally points the simulated vehicle keeps (ArduPlane's FENCE_TOTAL and
#: RALLY_TOTAL ceilings are larger; enough for any fence a plan carries).
FENCE_SLOTS, RALLY_SLOTS = 200, 20
FENCE_COMMANDS, RALLY_COMMANDS = frozenset(range(5000, 5005)), frozenset({5100})
from .transport import Transport, UdpTransport, open_transport
from ..vehicle import heading_to_bearing_deg

SIGNING_EPOCH_S = 1420070400     # MAVLink 2 signing timestamps count from 2015-01-01


#: With speedup 0 the flight runs as fast as a ground station can take its position
#: reports: at most this many per wall second (beyond it, UDP drops them and the track has
#: holes; ``fly`` checks for them).
FASTEST_TELEMETRY_PER_S = 1500.0


@dataclass(frozen=True)
class VehicleSettings:
    """The simulated vehicle: where it stands, how it flies, and the faults it shows."""

    home: Home
    autopilot: Autopilot = Autopilot.ARDUPILOTMEGA
    airframe: Airframe = Airframe()
    speedup: float = 50.0             # simulated seconds per wall second; 0: as fast as the
                                      # telemetry is carried (FASTEST_TELEMETRY_PER_S)
    step_s: float = MODEL_STEP_S
    telemetry_hz: float = 10.0        # position messages per simulated second
    max_items: int | None = None      # mission slots (home included on ArduPilot); None: a
                                      # stock vehicle's (ArduPlane 655, PX4 500)
    signing_key: bytes | None = None
    autostart: bool = False           # fly as soon as a mission arrives
    restart_at_item: int | None = None   # fault: reboot when this item arrives in an upload
    restart_s: float = 1.0            # how long a reboot keeps it silent (wall seconds)
    upload_timeout_s: float = 8.0     # an upload without an item this long is cancelled
                                      # (ArduPilot's MissionItemProtocol: 8 s)
    #: what it answers PARAM_REQUEST_READ with (by their names; None: its autopilot's stock ones)
    parameters: VehicleParameters | PX4Parameters | None = None
    wind: Wind = CALM                 # the steady wind it flies in
    #: MAV_TYPE its heartbeat claims (fixed wing; another type tests the uploader's check)
    mav_type: int = MAV_TYPE_FIXED_WING
    #: whether it keeps a geofence and rally points (MISSION_TYPE_FENCE, _RALLY)
    fence_support: bool = True


@dataclass
class FlightLog:
    """What the vehicle flew: samples (simulated time, x, y, altitude above home) in the
    local frame centred on home, and the items it completed."""

    samples: list[tuple[float, float, float, float]] = field(default_factory=list)
    reached: list[tuple[int, float]] = field(default_factory=list)


class _Sender:
    """pymavlink's output file: datagrams to the current ground station."""

    def __init__(self, vehicle: "SimulatedVehicle") -> None:
        self.vehicle = vehicle

    def write(self, data: bytes) -> None:
        self.vehicle._send_datagram(bytes(data))


class SimulatedVehicle:
    """The vehicle, listening on UDP ``host:port`` (port 0 picks a free one; ground stations
    connect with ``udpout:HOST:PORT``, replies go to whoever spoke last, or to ``gcs`` (host,
    port) before anyone did), or on ``listen`` (``udp:HOST:PORT``, ``tcp:HOST:PORT``, ``pty``;
    :attr:`connection` is how a ground station reaches it).  Use as a context manager or call
    :meth:`start` and :meth:`stop`."""

    def __init__(self, settings: VehicleSettings, port: int = 0, host: str = "127.0.0.1",
                 gcs: tuple[str, int] | None = None, listen: str | None = None) -> None:
        self.settings = settings
        self.frame = LocalFrame(settings.home.latitude_deg, settings.home.longitude_deg)
        self._transport: Transport = (open_transport(listen, gcs) if listen is not None
                                      else UdpTransport(host, port, gcs))
        self.host = getattr(self._transport, "host", "")
        self.port = getattr(self._transport, "port", 0)
        self.connection = self._transport.describe()
        # _lock: the flight and every call into MAVSDK from our threads.  _link_lock: the
        # pymavlink parser and encoder, used from MAVSDK's send callback, which therefore
        # never waits for _lock (MAVSDK's destroy joins that callback's thread).
        self._lock = threading.RLock()
        self._link_lock = threading.Lock()
        self._start_requested = False
        self._stop = threading.Event()
        self.finished = threading.Event()
        home = stored_item(home_placeholder(settings.home), settings.autopilot)
        self.store = MissionStore(settings.autopilot, settings.max_items, home)
        self.server = MissionServer(self.store, self._emit, before_item=self._before_item,
                                    on_stored=self._mission_stored,
                                    upload_timeout_s=settings.upload_timeout_s)
        # The geofence and the rally points: their own mission types and stores (taken whole,
        # as ArduPilot's fence loader and PX4 store them); a vehicle without fence support
        # answers them MAV_MISSION_UNSUPPORTED.
        self.fence_store = MissionStore(Autopilot.PX4, FENCE_SLOTS, commands=FENCE_COMMANDS)
        self.rally_store = MissionStore(Autopilot.PX4, RALLY_SLOTS, commands=RALLY_COMMANDS)
        self.other_servers = {kind: MissionServer(store, self._emit, mission_type=kind,
                                                  upload_timeout_s=settings.upload_timeout_s)
                              for kind, store in ((MISSION_TYPE_FENCE, self.fence_store),
                                                  (MISSION_TYPE_RALLY, self.rally_store))
                              if settings.fence_support}
        self.restarts = 0
        self.log = FlightLog()
        self.flight: MissionFlight | None = None
        self._mavsdk = None
        self._restarting = False
        self._restart_done = False
        self._parser_in = mavlink2.MAVLink(None)
        self._parser_out = mavlink2.MAVLink(None)
        self._encoder = mavlink2.MAVLink(_Sender(self), srcSystem=1, srcComponent=1)
        if settings.signing_key is not None:
            self._parser_in.signing.secret_key = settings.signing_key
            self._encoder.signing.secret_key = settings.signing_key
            self._encoder.signing.sign_outgoing = True
            self._encoder.signing.timestamp = int((time.time() - SIGNING_EPOCH_S) * 1e5)
        self._threads: list[threading.Thread] = []

    # -- life cycle --------------------------------------------------------------------------

    def start(self) -> "SimulatedVehicle":
        self._boot()
        for target in (self._receive_loop, self._flight_loop):
            thread = threading.Thread(target=target, daemon=True, name=f"sim-{target.__name__}")
            thread.start()
            self._threads.append(thread)
        return self

    def stop(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(timeout=5)
        with self._lock:                         # a reboot in progress boots no more
            pass
        self._shutdown_mavsdk()
        self._transport.close()

    def __enter__(self) -> "SimulatedVehicle":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    @property
    def mission(self) -> list[WireItem]:
        """What the vehicle holds now, as it stores it: what a download returns and what it
        flies (on ArduPilot, its home at seq 0 even without a mission)."""
        return list(self.store.items)

    @mission.setter
    def mission(self, items: list[WireItem]) -> None:
        with self._lock:
            self.store.replace(items)

    def _serve_mission_protocol(self, message) -> bool:
        """Answer a mission-protocol message with the server of its mission type (a type it
        does not keep: MAV_MISSION_UNSUPPORTED); True if it was one."""
        if message.get_type() not in PROTOCOL_MESSAGES:
            return False
        kind = getattr(message, "mission_type", MISSION_TYPE_MISSION)
        server = self.server if kind == MISSION_TYPE_MISSION else self.other_servers.get(kind)
        if server is not None:
            return server.handle(message)
        if message.get_type() != "MISSION_ACK":
            source = (message.get_srcSystem(), message.get_srcComponent())
            self._emit(lambda e: e.mission_ack_send(*source, MAV_MISSION_UNSUPPORTED, kind))
        return True

    @property
    def fence(self) -> list[WireItem]:
        """The geofence items it holds (MISSION_TYPE_FENCE)."""
        return list(self.fence_store.items)

    @property
    def rally(self) -> list[WireItem]:
        """The rally points it holds (MISSION_TYPE_RALLY)."""
        return list(self.rally_store.items)

    @property
    def uploads(self) -> int:
        """Uploads completed since the vehicle was created."""
        return self.server.counts["uploads"]

    def _boot(self) -> None:
        from mavsdk import ComponentType, Configuration, Mavsdk
        from mavsdk.plugins.mission_raw_server import MissionRawServer
        from mavsdk.plugins.telemetry_server import Position, TelemetryServer
        quiet_mavsdk_log()
        mavsdk = Mavsdk(Configuration.create_with_component_type(ComponentType.AUTOPILOT))
        mavsdk.add_any_connection("raw://")
        mavsdk.subscribe_raw_bytes_to_be_sent(self._from_mavsdk)
        server = mavsdk.server_component()
        # Instantiated only so that MAVSDK announces MAV_PROTOCOL_CAPABILITY_MISSION_INT in
        # AUTOPILOT_VERSION (MAVSDK ground stations refuse _INT transfers without it); every
        # mission message is answered by self.server and never reaches this plugin.
        self._mission_capability = MissionRawServer(server)
        self._telemetry = TelemetryServer(server)
        home = self.settings.home
        self._telemetry.publish_home(Position(home.latitude_deg, home.longitude_deg,
                                              home.altitude_amsl_m, 0.0))
        self._mavsdk = mavsdk

    def _shutdown_mavsdk(self) -> None:
        """Destroy MAVSDK without holding a lock its callbacks might wait for."""
        with self._lock:
            mavsdk, self._mavsdk = self._mavsdk, None
        if mavsdk is not None:
            mavsdk.destroy()

    def restart(self) -> None:
        """Reboot: silent for ``restart_s``, then up again with what its storage kept (an
        upload in progress is over; ArduPilot keeps the items it had written)."""
        self._restarting = True
        self.restarts += 1
        self._shutdown_mavsdk()
        with self._lock:
            for server in (self.server, *self.other_servers.values()):
                server.reset()
        if self._stop.wait(self.settings.restart_s):
            return                               # stopped while rebooting: stay down
        with self._lock:
            if self._stop.is_set():
                return
            self._boot()
            self._restarting = False

    # -- the link ----------------------------------------------------------------------------

    def _send_datagram(self, data: bytes) -> None:
        if not self._stop.is_set():
            self._transport.send(data)

    def _emit(self, build) -> None:
        """Send what ``build(encoder)`` encodes, from the autopilot (system 1, component 1)."""
        if self._restarting:
            return
        with self._link_lock:
            self._encoder.srcSystem, self._encoder.srcComponent = 1, 1
            build(self._encoder)

    def _from_mavsdk(self, data: bytes) -> None:
        """Bytes MAVSDK sends: heartbeats become a fixed wing's; with signing, every message
        is signed."""
        if self._restarting or self._stop.is_set():
            return
        signing = self.settings.signing_key is not None
        heartbeat = (data[:1] == b"\xfd" and data[7:10] == b"\x00\x00\x00") or \
            (data[:1] == b"\xfe" and data[5:6] == b"\x00")        # msgid 0 is HEARTBEAT
        if not signing and not heartbeat:
            self._send_datagram(data)
            return
        with self._link_lock:
            messages = self._parser_out.parse_buffer(data) or []
            for message in messages:
                if message.get_type() == "BAD_DATA":
                    continue
                if message.get_type() == "HEARTBEAT":
                    self._as_fixed_wing(message)
                elif not signing:
                    self._send_datagram(message.get_msgbuf())
                    continue
                self._encoder.srcSystem = message.get_srcSystem()
                self._encoder.srcComponent = message.get_srcComponent()
                self._encoder.send(message)
                if (message.get_type() == "HEARTBEAT"
                        and self.settings.autopilot == Autopilot.ARDUPILOTMEGA):
                    self._publish_wind()        # ArduPilot streams its wind estimate

    def _as_fixed_wing(self, heartbeat) -> None:
        flying = self.flight is not None and not self.finished.is_set()
        heartbeat.type = self.settings.mav_type
        heartbeat.autopilot = int(self.settings.autopilot)
        heartbeat.base_mode = MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | (
            MAV_MODE_FLAG_AUTO_ENABLED | MAV_MODE_FLAG_SAFETY_ARMED if flying else 0)
        heartbeat.system_status = MAV_STATE_ACTIVE if flying else MAV_STATE_STANDBY

    def _receive_loop(self) -> None:
        while not self._stop.is_set():
            try:
                data = self._transport.receive(0.05)
            except (OSError, ValueError):
                return
            if not self._restarting:
                with self._lock:
                    for server in (self.server, *self.other_servers.values()):
                        server.update()
            if data is None or self._restarting:
                continue
            with self._lock:
                try:
                    messages = self._parser_in.parse_buffer(data) or []
                except mavlink2.MAVError:       # a bad signature: drop the datagram
                    signing = self._parser_in.signing
                    self._parser_in = mavlink2.MAVLink(None)
                    self._parser_in.signing = signing
                    continue
            for message in messages:
                if message.get_type() == "BAD_DATA":
                    continue       # a wrong signature, or no signature while signing: ignored
                with self._lock:
                    if self._restarting:
                        break
                    if self._serve_mission_protocol(message):
                        continue
                if not self._handled_here(message):
                    with self._lock:
                        if self._mavsdk is not None and not self._restarting:
                            self._mavsdk.pass_received_raw_bytes(bytes(message.get_msgbuf()))

    def _handled_here(self, message) -> bool:
        """Answer what the plugins cannot; True when the message must not reach them."""
        kind = message.get_type()
        settings = self.settings
        if kind == "PARAM_REQUEST_READ":
            self._answer_parameter(message)
            return True
        if kind == "COMMAND_LONG" and message.command == MAV_CMD_REQUEST_MESSAGE \
                and int(message.param1) == MAVLINK_MSG_ID_HOME_POSITION:
            home = settings.home
            with self._link_lock:
                self._encoder.srcSystem, self._encoder.srcComponent = 1, 1
                self._encoder.command_ack_send(MAV_CMD_REQUEST_MESSAGE, MAV_RESULT_ACCEPTED, 0, 0,
                                               message.get_srcSystem(), message.get_srcComponent())
                self._encoder.home_position_send(
                    degrees_to_e7(home.latitude_deg), degrees_to_e7(home.longitude_deg),
                    round(home.altitude_amsl_m * 1000), 0.0, 0.0, 0.0, [1.0, 0.0, 0.0, 0.0],
                    0.0, 0.0, 0.0)
            return True
        if kind == "COMMAND_LONG" and message.command == MAV_CMD_MISSION_START:
            started = self.start_mission()
            with self._link_lock:
                self._encoder.srcSystem, self._encoder.srcComponent = 1, 1
                self._encoder.command_ack_send(
                    MAV_CMD_MISSION_START, MAV_RESULT_ACCEPTED if started else MAV_RESULT_DENIED,
                    0, 0, message.get_srcSystem(), message.get_srcComponent())
            return True
        return False

    def _answer_parameter(self, message) -> None:
        """PARAM_VALUE for a navigation parameter the vehicle has (by name or index: ArduPlane's
        or PX4's, as its autopilot); like a real vehicle it stays silent for a name it does not
        know."""
        parameters = parameters_of(self.settings.autopilot, self.settings.parameters)
        names = [f.name for f in fields(parameters)]
        name = parameter_name(message.param_id)
        if message.param_index >= 0 and not name:
            name = names[message.param_index] if message.param_index < len(names) else ""
        if name not in names:
            return
        with self._link_lock:
            self._encoder.srcSystem, self._encoder.srcComponent = 1, 1
            self._encoder.param_value_send(name.encode(), float(getattr(parameters, name)),
                                           MAV_PARAM_TYPE_REAL32, len(names), names.index(name))

    # -- the mission ---------------------------------------------------------------------------

    def _before_item(self, seq: int) -> bool:
        """Fault injection: reboot instead of storing item ``restart_at_item``."""
        if seq == self.settings.restart_at_item and not self._restart_done:
            self._restart_done = True
            self._restarting = True
            threading.Thread(target=self.restart, daemon=True).start()
            return False
        return True

    def _mission_stored(self) -> None:
        if self.settings.autostart and len(self.store.items) > first_mission_seq(self.settings.autopilot):
            self._start_requested = True     # the flight loop starts it

    def local_items(self) -> list[LocalItem]:
        """The mission in the local frame (altitudes above home)."""
        return local_items(self.mission, self.frame, self.settings.home.altitude_amsl_m)

    def start_mission(self) -> bool:
        """Take off and fly the mission from its first item; False without a mission or
        while flying."""
        with self._lock:
            first = first_mission_seq(self.settings.autopilot)
            items = self.local_items()
            if len(items) <= first or (self.flight is not None and not self.finished.is_set()):
                return False
            heading = launch_heading_rad(items, first)
            self.log = FlightLog()
            self.finished.clear()
            self._completed = 0
            self.flight = MissionFlight(items, self.settings.airframe, heading, first,
                                        self.settings.wind)
            return True

    def _flight_loop(self) -> None:
        settings = self.settings
        publish_every = max(1, round(1.0 / (settings.telemetry_hz * settings.step_s)))
        steps = 0
        paced_from = None
        while not self._stop.is_set():
            if self._start_requested:
                self._start_requested = False
                self.start_mission()
            flight = self.flight
            if flight is None or self.finished.is_set() or self._restarting:
                paced_from = None
                time.sleep(0.01)
                continue
            if paced_from is None:
                paced_from = (time.monotonic(), flight.state.time_s)
            with self._lock:
                flight.step(settings.step_s)
                steps += 1
                state = flight.state
                self.log.samples.append((state.time_s, state.x_m, state.y_m, state.alt_m))
                for seq, at in flight.reached_since(self._completed):
                    self.log.reached.append((seq, at))
                    self._completed += 1
                    self._emit(lambda e, seq=seq: e.mission_item_reached_send(seq))
                    self._emit(lambda e, seq=seq: e.mission_current_send(seq + 1))
                if steps % publish_every == 0 or flight.finished:
                    self._publish(state, flight.ground_velocity_m_s)
                if flight.finished:
                    self.finished.set()
            pace = settings.speedup if settings.speedup > 0 else \
                FASTEST_TELEMETRY_PER_S / settings.telemetry_hz
            if pace > 0:
                ahead = (state.time_s - paced_from[1]) / pace \
                    - (time.monotonic() - paced_from[0])
                if ahead > 0.002:
                    time.sleep(ahead)

    def _publish_wind(self) -> None:
        """ArduPilot's WIND message (its estimate; here the wind it flies in); called with the
        link lock held."""
        wind = self.settings.wind
        self._encoder.srcSystem, self._encoder.srcComponent = 1, 1
        self._encoder.send(ardupilotmega.MAVLink_wind_message(float(wind.from_deg),
                                                              float(wind.speed_m_s), 0.0))

    def _publish(self, state, ground_velocity_m_s: tuple[float, float]) -> None:
        """GLOBAL_POSITION_INT, from the vehicle's own encoder: in order with
        MISSION_ITEM_REACHED (MAVSDK's telemetry server queues positions and, at a high
        speed-up, delivers them after the mission's last item was reported)."""
        latitude, longitude = self.frame.to_geodetic(np.array([[state.x_m, state.y_m]]))
        east, north = ground_velocity_m_s
        home = self.settings.home
        bearing = heading_to_bearing_deg(state.heading_rad)
        self._emit(lambda e: e.global_position_int_send(
            int(state.time_s * 1000) & 0xFFFFFFFF, degrees_to_e7(float(latitude[0])),
            degrees_to_e7(float(longitude[0])), round((home.altitude_amsl_m + state.alt_m) * 1000),
            round(state.alt_m * 1000), round(100 * north), round(100 * east), 0,
            round(bearing * 100) % 36000))
