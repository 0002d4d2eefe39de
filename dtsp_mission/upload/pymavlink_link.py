"""The mission protocol over pymavlink, as the MAVLink spec and QGroundControl run it.

Upload: MISSION_COUNT; the vehicle asks for each item with MISSION_REQUEST_INT (or the older
MISSION_REQUEST, which ArduPilot still sends) and both get a MISSION_ITEM_INT; repeated
requests get the item again; MISSION_ACK ends it.  Download: MISSION_REQUEST_LIST,
MISSION_COUNT, one MISSION_REQUEST_INT per item, MISSION_ACK.  MAVLink 2 with
``mission_type``, optional MAVLink 2 signing.  Timeouts and retries: :mod:`.base`.
"""

from __future__ import annotations

import os
import time

from pymavlink import mavutil

from ..autopilot.parameters import parameter_name
from ..errors import LinkError
from ..mission import Command
from .connection import check_host
from .base import ITEM_TIMEOUT_S, RETRIES, TIMEOUT_S, Progress, Uploader, VehicleInfo
from .results import ITEM_RESULTS, NO_SPACE, result_text
from .wire import MISSION_TYPE_MISSION, WireItem

GCS_SYSTEM_ID = 255
GCS_COMPONENT_ID = 190          # MAV_COMP_ID_MISSIONPLANNER
MAV_TYPE_GCS = 6
MAV_AUTOPILOT_INVALID = 8
HEARTBEAT_PERIOD_S = 1.0
MAV_CMD_REQUEST_MESSAGE = 512
MAVLINK_MSG_ID_HOME_POSITION = 242


def use_mavlink2() -> None:
    """Switch pymavlink to MAVLink 2.  pymavlink keeps its wire protocol in a process-wide
    dialect module chosen from ``MAVLINK20``; the variable and the module are changed together
    so other pymavlink users in the process (``MAVWPLoader``) stay consistent."""
    if os.environ.get("MAVLINK20") != "1" or mavutil.mavlink.WIRE_PROTOCOL_VERSION != "2.0":
        os.environ["MAVLINK20"] = "1"
        mavutil.set_dialect(os.environ.get("MAVLINK_DIALECT", "ardupilotmega"))


def _command_name(command: int) -> str:
    try:
        return Command(command).name
    except ValueError:
        return f"command {command}"


class PymavlinkUploader(Uploader):
    """Mission upload and download with pymavlink (MAVLink 2, optional signing)."""

    name = "pymavlink"
    description = "the MAVLink mission protocol over pymavlink (MAVLink 2, signing)"
    supports_signing = True

    def open(self) -> None:
        use_mavlink2()
        check_host(self.connection)
        try:
            self._link = mavutil.mavlink_connection(
                self.connection, source_system=GCS_SYSTEM_ID, source_component=GCS_COMPONENT_ID,
                autoreconnect=False)
        except Exception as error:  # pymavlink raises OSError, ValueError, serial errors ...
            raise LinkError(f"cannot open the connection {self.connection!r}: {error}") from None
        if self.signing_key is not None:
            self._link.setup_signing(self.signing_key, sign_outgoing=True)
        self._last_heartbeat = 0.0
        self._bad_signatures = 0
        self._unsigned = 0
        self._status_texts: list[str] = []
        self._wait_for_vehicle()

    def close(self) -> None:
        link = getattr(self, "_link", None)
        if link is not None:
            link.close()
            self._link = None

    # -- receiving ---------------------------------------------------------------------------

    def _heartbeat(self) -> None:
        now = time.monotonic()
        if now - self._last_heartbeat >= HEARTBEAT_PERIOD_S:
            self._link.mav.heartbeat_send(MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID, 0, 0, 0)
            self._last_heartbeat = now

    def _receive(self, types: set[str], timeout_s: float):
        """The next message of ``types`` from the vehicle, or None after ``timeout_s``."""
        deadline = time.monotonic() + timeout_s
        while True:
            self._heartbeat()
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            message = self._link.recv_match(blocking=True, timeout=min(remaining, 0.2))
            if message is None:
                continue
            kind = message.get_type()
            if kind == "BAD_DATA":
                if "signature" in str(getattr(message, "reason", "")).lower():
                    raw = bytes(getattr(message, "data", b"") or b"")
                    if raw[:1] == b"\xfd" and len(raw) > 2 and not raw[2] & 0x01:
                        self._unsigned += 1          # a MAVLink 2 message without signature
                    else:
                        self._bad_signatures += 1
                continue
            if hasattr(self, "_target") and (message.get_srcSystem(), message.get_srcComponent()) != self._target:
                continue
            if kind == "STATUSTEXT":
                self._status_texts = (self._status_texts + [message.text.rstrip("\0")])[-5:]
            if kind in types and getattr(message, "mission_type", MISSION_TYPE_MISSION) == MISSION_TYPE_MISSION:
                return message

    def _wait_for_vehicle(self) -> None:
        deadline = time.monotonic() + self.heartbeat_timeout_s
        while time.monotonic() < deadline:
            message = self._receive({"HEARTBEAT"}, deadline - time.monotonic())
            if message is not None and message.type != MAV_TYPE_GCS \
                    and message.autopilot != MAV_AUTOPILOT_INVALID:
                self._target = (message.get_srcSystem(), message.get_srcComponent())
                self._autopilot = int(message.autopilot)
                raw = bytes(message.get_msgbuf())
                self._vehicle_signs = raw[:1] == b"\xfd" and bool(raw[2] & 0x01)   # signed flag
                return
        if self._unsigned and not self._bad_signatures:
            raise LinkError(f"the vehicle at {self.connection} answers, but it does not sign its "
                            "messages: upload without --signing-key, or set up MAVLink 2 signing "
                            "on the vehicle with this key first")
        if self._bad_signatures:
            raise LinkError(f"the vehicle at {self.connection} answers, but its messages fail the "
                            "MAVLink 2 signature check: wrong --signing-key (or the vehicle signs "
                            "with another key)")
        if self.signing_key is not None:
            raise LinkError(f"no signed heartbeat from a vehicle at {self.connection} within "
                            f"{self.heartbeat_timeout_s:g} s: is it on, is signing set up with "
                            "this key, and is the connection right?")
        raise LinkError(f"no heartbeat from a vehicle at {self.connection} within "
                        f"{self.heartbeat_timeout_s:g} s: is it on, and is the connection right "
                        "(udpout:HOST:PORT to send to it, udpin:0.0.0.0:PORT to listen)?")

    def _no_answer(self, what: str) -> LinkError:
        hint = ""
        if getattr(self, "_vehicle_signs", False) and self.signing_key is None:
            hint = ": the vehicle signs its messages and may ignore unsigned ones; give --signing-key"
        return LinkError(f"the vehicle stopped answering ({what}; {RETRIES} retries, "
                         f"timeouts {TIMEOUT_S:g} s / {ITEM_TIMEOUT_S:g} s){hint}")

    # -- what the vehicle is ---------------------------------------------------------------------

    def vehicle_info(self, parameter_names: tuple[str, ...] = ()) -> VehicleInfo:
        """Its autopilot (heartbeat), home (HOME_POSITION, asked with MAV_CMD_REQUEST_MESSAGE)
        and the named parameters (PARAM_REQUEST_READ, asked twice at most)."""
        system, component = self._target
        values: dict[str, float] = {}
        for _ in range(2):
            missing = [n for n in parameter_names if n not in values]
            if not missing:
                break
            for name in missing:
                self._link.mav.param_request_read_send(system, component, name.encode(), -1)
            deadline = time.monotonic() + TIMEOUT_S
            while (remaining := deadline - time.monotonic()) > 0 and len(values) < len(parameter_names):
                message = self._receive({"PARAM_VALUE"}, remaining)
                if message is not None:
                    name = parameter_name(message.param_id)
                    if name in parameter_names:
                        values[name] = float(message.param_value)
        home = None
        self._link.mav.command_long_send(system, component, MAV_CMD_REQUEST_MESSAGE, 0,
                                         MAVLINK_MSG_ID_HOME_POSITION, 0, 0, 0, 0, 0, 0)
        message = self._receive({"HOME_POSITION"}, TIMEOUT_S)
        if message is not None:
            home = (message.latitude / 1e7, message.longitude / 1e7)
        return VehicleInfo(self._autopilot, home, values, True)

    # -- the mission protocol ------------------------------------------------------------------

    def _send_item(self, item: WireItem) -> None:
        system, component = self._target
        self._link.mav.mission_item_int_send(
            system, component, item.seq, item.frame, item.command, item.current,
            item.autocontinue, item.param1, item.param2, item.param3, item.param4, item.x,
            item.y, item.z, item.mission_type)

    def upload(self, items: list[WireItem], progress: Progress | None = None) -> None:
        system, component = self._target
        count = len(items)
        self._link.mav.mission_count_send(system, component, count, MISSION_TYPE_MISSION)
        highest = -1            # highest seq the vehicle asked for
        retries = 0             # quiet periods of TIMEOUT_S without progress
        quiet_since = time.monotonic()
        kinds = {"MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"}
        while True:
            # Wait in ITEM_TIMEOUT_S steps; after TIMEOUT_S of quiet send the count or the
            # last item again (one retry).  Resending faster only restarts the vehicle's own
            # request timer, which is what re-asks for a lost item.
            message = self._receive(kinds, ITEM_TIMEOUT_S)
            if message is None:
                if time.monotonic() - quiet_since < TIMEOUT_S:
                    continue
                retries += 1
                self.resent += 1
                quiet_since = time.monotonic()
                if retries > RETRIES:
                    raise self._no_answer("no request for the first item" if highest < 0
                                          else f"after item {highest} of {count}")
                if highest < 0:
                    self._link.mav.mission_count_send(system, component, count, MISSION_TYPE_MISSION)
                else:
                    self._send_item(items[highest])
                continue
            if message.get_type() == "MISSION_ACK":
                if message.type == 0:
                    if highest == count - 1:
                        return
                    continue        # an old acknowledgement; this transfer is not done yet
                raise self._rejection(message.type, items, highest, count)
            seq = message.seq
            if not 0 <= seq < count:
                continue            # a request from another transfer
            self._send_item(items[seq])
            if seq > highest:
                highest, retries, quiet_since = seq, 0, time.monotonic()
                if progress is not None:
                    progress(seq + 1, count)

    def _rejection(self, result: int, items: list[WireItem], highest: int, count: int) -> LinkError:
        said = f" (the vehicle said: {' / '.join(self._status_texts)})" if self._status_texts else ""
        if result == NO_SPACE:
            return LinkError(f"the vehicle has no room for {count} mission items "
                             f"({result_text(result)}){said}: lower --max-items and plan again")
        if result in ITEM_RESULTS and highest >= 0:
            item = items[highest]
            return LinkError(f"the vehicle rejected item {item.seq} ({_command_name(item.command)}"
                             f", frame {item.frame}): {result_text(result)}{said}")
        return LinkError(f"the vehicle refused the mission: {result_text(result)}{said}")

    def _request_list(self) -> int:
        """Start a download transfer; the number of items the vehicle holds."""
        system, component = self._target
        for _ in range(RETRIES + 1):
            self._link.mav.mission_request_list_send(system, component, MISSION_TYPE_MISSION)
            message = self._receive({"MISSION_COUNT"}, TIMEOUT_S)
            if message is not None:
                return message.count
            self.resent += 1
        raise self._no_answer("no MISSION_COUNT for the download")

    def download(self) -> list[WireItem]:
        """Requests items in order; when the vehicle stops serving one (a transfer it dropped
        after lost or repeated messages), starts a new transfer and goes on from there."""
        system, component = self._target
        count = self._request_list()
        items: list[WireItem] = []
        restarts = 0
        while len(items) < count:
            seq = len(items)
            message = None
            for _ in range(RETRIES + 1):
                self._link.mav.mission_request_int_send(system, component, seq, MISSION_TYPE_MISSION)
                message = self._receive_item(seq)
                if message is not None:
                    break
                self.resent += 1
            if message is None:
                restarts += 1
                if restarts > RETRIES:
                    raise self._no_answer(f"no item {seq} of {count} in the download")
                if self._request_list() != count:
                    raise LinkError("the vehicle's mission changed during the download")
                continue
            restarts = 0
            items.append(message)
        self._link.mav.mission_ack_send(system, component, 0, MISSION_TYPE_MISSION)
        return items

    def _receive_item(self, seq: int) -> WireItem | None:
        deadline = time.monotonic() + ITEM_TIMEOUT_S
        while (remaining := deadline - time.monotonic()) > 0:
            message = self._receive({"MISSION_ITEM_INT", "MISSION_ITEM"}, remaining)
            if message is None or message.seq != seq:
                continue
            x, y = message.x, message.y
            if message.get_type() == "MISSION_ITEM":     # float degrees: the old message
                x, y = round(x * 1e7), round(y * 1e7)
            return WireItem.normalised(message.seq, message.frame, message.command,
                                       message.current, message.autocontinue, message.param1,
                                       message.param2, message.param3, message.param4, x, y,
                                       message.z, MISSION_TYPE_MISSION)
        return None
