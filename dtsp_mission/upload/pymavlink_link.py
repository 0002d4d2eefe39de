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
from pymavlink.dialects.v20.common import (MAV_AUTOPILOT_ARDUPILOTMEGA, MAV_AUTOPILOT_INVALID,
                                           MAV_CMD_REQUEST_MESSAGE, MAV_MISSION_DENIED,
                                           MAV_MISSION_ERROR, MAV_MISSION_INVALID_SEQUENCE,
                                           MAV_MISSION_OPERATION_CANCELLED, MAV_TYPE_GCS,
                                           MAVLINK_MSG_ID_HOME_POSITION)

from ..autopilot.parameters import parameter_name
from ..errors import LinkError
from ..autopilot.commands import Command
from .connection import check_host
from .datagrams import keep_only
from .base import (MIN_TIMEOUT_S, TIMEOUT_S, VEHICLE_GIVES_UP_S, Progress, Uploader, VehicleInfo,
                   transfer_timeout_s)
from .results import ITEM_RESULTS, NO_SPACE, result_text
from ..autopilot.storage import wire_item_from
from ..autopilot.wire import MISSION_TYPE_MISSION, WireItem

GCS_SYSTEM_ID = 255
GCS_COMPONENT_ID = 190          # MAV_COMP_ID_MISSIONPLANNER
#: A vehicle that never asks for an item in this long is not taking missions from us (it
#: ignores our messages: unsigned to a signing vehicle, another system id ...).
FIRST_ANSWER_S = 6.0
#: At most this many items past the awaited one are repeated to ArduPilot after a timeout.
PUSH_AHEAD = 8
#: Requests a download keeps outstanding from ArduPilot (it serves any seq, in any order).
DOWNLOAD_WINDOW = 8
#: How long the vehicle is asked for its home and parameters before an upload.
VEHICLE_INFO_S = 3.0
#: Fresh transfers (a new MISSION_COUNT) one upload may start before it gives up.
MAX_FRESH_STARTS = 20
#: Request timeouts in a row without any item before a download starts a new transfer.
DOWNLOAD_RESTART_AFTER = 4
HEARTBEAT_PERIOD_S = 1.0
#: Every message the uploader waits for: over UDP, datagrams with none of them are dropped
#: undecoded (:mod:`.datagrams`), so a vehicle's telemetry cannot crowd out a transfer.
LISTENS_TO = frozenset({"HEARTBEAT", "STATUSTEXT", "PARAM_VALUE", "HOME_POSITION", "WIND",
                        "MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK", "MISSION_COUNT",
                        "MISSION_ITEM_INT", "MISSION_ITEM"})


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


def _at_end(stream) -> bool:
    """Whether a (non-blocking) TCP socket's peer has closed or reset the connection."""
    import select
    import socket
    try:
        readable, _, _ = select.select([stream], [], [], 0)
        return bool(readable) and stream.recv(1, socket.MSG_PEEK) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True


class PymavlinkUploader(Uploader):
    """Mission upload and download with pymavlink (MAVLink 2, optional signing)."""

    name = "pymavlink"
    description = "the MAVLink mission protocol over pymavlink (MAVLink 2, signing)"
    supports_signing = True
    mission_types = (0, 1, 2)

    def open(self) -> None:
        use_mavlink2()
        check_host(self.connection)
        try:
            self._link = mavutil.mavlink_connection(
                self.connection, source_system=GCS_SYSTEM_ID, source_component=GCS_COMPONENT_ID,
                autoreconnect=False)
        except Exception as error:  # pymavlink raises OSError, ValueError, serial errors ...
            raise LinkError(f"cannot open the connection {self.connection!r}: {error}") from None
        keep_only(self._link, LISTENS_TO)
        self._guard_link()
        if self.signing_key is not None:
            self._link.setup_signing(self.signing_key, sign_outgoing=True)
        self._last_heartbeat = 0.0
        self._bad_signatures = 0
        self._unsigned = 0
        self._status_texts: list[str] = []
        self._wait_for_vehicle()

    def _guard_link(self) -> None:
        """Make a link that closes under us (a TCP vehicle killed, a serial cable pulled) a
        :class:`LinkError` saying so, wherever it is read or written."""
        link = self._link
        raw_write, raw_recv = link.write, link.recv

        def closed(error: OSError) -> LinkError:
            return LinkError(f"the link to the vehicle at {self.connection} closed "
                             f"({error.strerror or error.__class__.__name__})")

        def write(buffer):
            try:
                return raw_write(buffer)
            except LinkError:
                raise
            except OSError as error:
                raise closed(error) from None

        stream = link.port if isinstance(link, mavutil.mavtcp) else None

        def recv(*args, **kwargs):
            try:
                data = raw_recv(*args, **kwargs)
            except LinkError:
                raise
            except OSError as error:
                raise closed(error) from None
            if not data and stream is not None and _at_end(stream):
                # pymavlink reads a TCP peer's end (or reset) as "no data yet"
                raise LinkError(f"the link to the vehicle at {self.connection} closed (the "
                                "vehicle ended the TCP connection)")
            return data
        link.write, link.recv = write, recv

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
        """The next message of ``types`` (all in :data:`LISTENS_TO`) from the vehicle, or None
        after ``timeout_s``."""
        assert types <= LISTENS_TO, types - LISTENS_TO
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
                    if raw[:1] == b"\xfe" or (raw[:1] == b"\xfd" and len(raw) > 2
                                               and not raw[2] & 0x01):
                        self._unsigned += 1          # MAVLink 1, or MAVLink 2 without signature
                    else:
                        self._bad_signatures += 1
                continue
            if hasattr(self, "_target") and (message.get_srcSystem(), message.get_srcComponent()) != self._target:
                continue
            if kind == "STATUSTEXT":
                self._status_texts = (self._status_texts + [message.text.rstrip("\0")])[-5:]
            if kind in types and getattr(message, "mission_type", MISSION_TYPE_MISSION) == self.mission_type:
                return message

    def _wait_for_vehicle(self) -> None:
        deadline = time.monotonic() + self.heartbeat_timeout_s
        while time.monotonic() < deadline:
            message = self._receive({"HEARTBEAT"}, deadline - time.monotonic())
            if message is not None and message.type != MAV_TYPE_GCS \
                    and message.autopilot != MAV_AUTOPILOT_INVALID:
                self._target = (message.get_srcSystem(), message.get_srcComponent())
                self._autopilot = int(message.autopilot)
                self._vehicle_type = int(message.type)
                raw = bytes(message.get_msgbuf())
                self._vehicle_signs = raw[:1] == b"\xfd" and bool(raw[2] & 0x01)   # signed flag
                return
        if self._unsigned and self._unsigned >= self._bad_signatures:
            raise LinkError(f"the vehicle at {self.connection} answers, but it does not sign its "
                            "messages: upload without `signing_key`, or set up MAVLink 2 signing "
                            "on the vehicle with this key first")
        if self._bad_signatures:
            raise LinkError(f"the vehicle at {self.connection} answers, but its messages fail the "
                            "MAVLink 2 signature check: wrong `signing_key` (or the vehicle signs "
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
            hint = ": the vehicle signs its messages and may ignore unsigned ones; give `signing_key`"
        return LinkError(f"the vehicle stopped answering ({what}){hint}")

    # -- what the vehicle is ---------------------------------------------------------------------

    def vehicle_info(self, parameter_names: tuple[str, ...] = (),
                     wind_wait_s: float = 0.0, names_autopilot: int | None = None) -> VehicleInfo:
        """Its autopilot (heartbeat), home (HOME_POSITION, asked with MAV_CMD_REQUEST_MESSAGE)
        and the named parameters (PARAM_REQUEST_READ; names of ``names_autopilot``, ArduPilot's
        if None, so of a vehicle running it only): what is still missing is asked again
        every 0.1 s (or the measured retry timeout, once known; longer after a round without
        any answer), for :data:`VEHICLE_INFO_S` at most (a vehicle stays
        silent for a parameter it does not have).  The first answer measures the link's round
        trip for the transfers that follow.  ArduPilot's WIND (its wind estimate, streamed,
        never asked for) is kept if it comes meanwhile, or within ``wind_wait_s``."""
        system, component = self._target
        if self._autopilot != (MAV_AUTOPILOT_ARDUPILOTMEGA if names_autopilot is None
                               else names_autopilot):
            parameter_names = ()         # another autopilot's names: it would stay silent
        timer = self._timer = getattr(self, "_timer", None) or RetransmitTimer()
        values: dict[str, float] = {}
        home = wind = home_amsl = None
        started = time.monotonic()
        deadline = started + VEHICLE_INFO_S
        interval, rounds = 0.1, 0
        wind_until = started + min(wind_wait_s, VEHICLE_INFO_S)
        while ((missing := [n for n in parameter_names if n not in values]) or home is None
               or (wind is None and time.monotonic() < wind_until)):
            now = time.monotonic()
            if now >= deadline:
                break
            rounds += 1
            for name in missing:
                self._link.mav.param_request_read_send(system, component, name.encode(), -1)
            if home is None:
                self._link.mav.command_long_send(system, component, MAV_CMD_REQUEST_MESSAGE, 0,
                                                 MAVLINK_MSG_ID_HOME_POSITION, 0, 0, 0, 0, 0, 0)
            until = min(deadline, now + interval)
            answered = False
            while (remaining := until - time.monotonic()) > 0:
                message = self._receive({"PARAM_VALUE", "HOME_POSITION", "WIND"}, remaining)
                if message is None:
                    continue
                if message.get_type() == "WIND":          # streamed, never asked for
                    wind = (float(message.speed), float(message.direction) % 360.0)
                    continue
                answered = True
                if rounds == 1 and timer.srtt_s is None:
                    timer.sample(time.monotonic() - now)
                if message.get_type() == "HOME_POSITION":
                    home = (message.latitude / 1e7, message.longitude / 1e7)
                    home_amsl = message.altitude / 1e3
                elif (name := parameter_name(message.param_id)) in parameter_names:
                    values[name] = float(message.param_value)
                if home is not None and len(values) == len(parameter_names) and (
                        wind is not None or time.monotonic() >= wind_until):
                    break
            interval = (min(1.0, interval * 2) if not answered else
                        max(0.05, 2 * timer.timeout_s) if timer.srtt_s is not None else 0.1)
        return VehicleInfo(self._autopilot, home, values, True, wind,
                           home_amsl if home is not None else None,
                           getattr(self, "_vehicle_type", None), tuple(parameter_names))

    # -- the mission protocol ------------------------------------------------------------------

    def _send_item(self, item: WireItem) -> None:
        system, component = self._target
        self._link.mav.mission_item_int_send(
            system, component, item.seq, item.frame, item.command, item.current,
            item.autocontinue, item.param1, item.param2, item.param3, item.param4, item.x,
            item.y, item.z, self.mission_type)

    def _transfer_deadline(self, count: int) -> float:
        return time.monotonic() + (self.timeout_s if self.timeout_s is not None
                                   else transfer_timeout_s(count))

    def upload(self, items: list[WireItem], progress: Progress | None = None) -> None:
        """Runs transfers until the vehicle acknowledges the whole mission or the deadline
        passes: a fresh MISSION_COUNT whenever the vehicle gave up its side (it cancelled, or
        said nothing for longer than it waits)."""
        count = len(items)
        deadline = self._transfer_deadline(count)
        self._timer = getattr(self, "_timer", None) or RetransmitTimer()
        self._ever_answered = False
        attempts = 0
        while True:
            attempts += 1
            outcome = self._upload_once(items, progress, deadline)
            if outcome == "done":
                return
            self.fresh_starts += 1
            if time.monotonic() >= deadline or attempts > MAX_FRESH_STARTS:
                started = f"{attempts} transfers started, the last one" if attempts > 1 else "it"
                raise self._no_answer(f"{outcome}; {started} reached item {self._reached} of "
                                      f"{count}, {time.monotonic() - deadline + self._budget(count):.0f} "
                                      "s in all")

    def _budget(self, count: int) -> float:
        return self.timeout_s if self.timeout_s is not None else transfer_timeout_s(count)

    def _upload_once(self, items: list[WireItem], progress: Progress | None, deadline: float) -> str:
        """One transfer: ``"done"``, or why a fresh one is needed.

        The vehicle asks for each item and every request is answered at once.  When neither
        a new request nor the final ACK comes within the retry timeout (the measured round
        trip, not the vehicle's own 1 s re-request), the count (before any request) or the
        awaited item goes out again -- and to ArduPilot, which writes any item whose seq is the
        one it waits for, requested or not, also the items after it up to one beyond the
        highest sent so far, since the lost messages may have been its requests for them.
        (Sending ahead all the time was measured slower: on a link with jitter the items
        overtake each other and ArduPilot drops those out of order.)"""
        system, component = self._target
        count = len(items)
        timer = self._timer
        ardupilot = self._autopilot == MAV_AUTOPILOT_ARDUPILOTMEGA
        max_sent = -1
        kinds = {"MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"}
        self._link.mav.mission_count_send(system, component, count, self.mission_type)
        first_sent = {-1: time.monotonic()}   # seq -> first send (-1: the count)
        last_sent: dict[int, float] = {}
        resent: set[int] = set()              # Karn's rule: no round-trip sample from these
        highest = -1                          # the highest seq the vehicle asked for
        self._reached = 0
        progress_at = time.monotonic()
        retry_at = progress_at + timer.timeout_s   # stray answers do not put this off
        answered = False                      # whether anything answered since the last retry

        def send(seq: int, now: float) -> None:
            nonlocal max_sent
            if seq >= count:
                return
            max_sent = max(max_sent, seq)
            if seq in last_sent:
                resent.add(seq)
                self.resent += 1
            first_sent.setdefault(seq, now)
            last_sent[seq] = now
            self._send_item(items[seq])

        while True:
            now = time.monotonic()
            if now >= deadline:
                return "the time allowed ran out"
            message = self._receive(kinds, max(0.0, min(retry_at, deadline) - now))
            now = time.monotonic()
            if message is None:
                if now < retry_at:
                    continue
                if highest < 0 and not self._ever_answered and now - first_sent[-1] > FIRST_ANSWER_S:
                    raise self._no_answer(f"no request for the first item in {FIRST_ANSWER_S:g} s")
                if now - progress_at > VEHICLE_GIVES_UP_S:
                    return "the vehicle went quiet"
                if not answered:
                    timer.back_off()            # nothing at all came back: the link is slower
                answered = False
                retry_at = now + timer.timeout_s
                if highest < 0:
                    self._link.mav.mission_count_send(system, component, count, self.mission_type)
                    resent.add(-1)
                    self.resent += 1
                    continue
                last = min(max_sent + 1, highest + PUSH_AHEAD) if ardupilot else highest
                for seq in range(highest, last + 1):
                    send(seq, now)
                continue
            if message.get_type() == "MISSION_ACK":
                result = message.type
                if result == 0 and count - 1 in last_sent:
                    if progress is not None:
                        progress(count, count, self.resent)
                    return "done"
                if result in (0, MAV_MISSION_INVALID_SEQUENCE):
                    self.stray_acks += 1        # an old ACCEPTED, or the answer to a copy
                    answered = True
                    continue
                if result == MAV_MISSION_OPERATION_CANCELLED:
                    return "the vehicle cancelled the transfer"
                if result == MAV_MISSION_ERROR:
                    if count - 1 in last_sent and highest >= count - PUSH_AHEAD:
                        # The vehicle is done with this transfer and its ACCEPTED was lost:
                        # upload_mission downloads the mission to see what arrived.
                        raise LinkError("the vehicle's final acknowledgement was lost")
                    if highest < 0:
                        continue                # an answer to an item of an earlier transfer
                    return "the vehicle was no longer in the transfer (MAV_MISSION_ERROR)"
                raise self._rejection(result, items, highest, count)
            seq = message.seq
            if not 0 <= seq < count:
                continue                        # a request from another transfer
            self._ever_answered = True
            if seq > highest:
                if seq - 1 not in resent and seq - 1 in first_sent:
                    timer.sample(now - first_sent[seq - 1])
                timer.settle()
                highest, progress_at = seq, now
                retry_at = now + timer.timeout_s
                self._reached = seq
                if progress is not None:
                    progress(seq, count, self.resent)
            send(seq, now)

    def _rejection(self, result: int, items: list[WireItem], highest: int, count: int) -> LinkError:
        self.last_refusal = result
        said = f" (the vehicle said: {' / '.join(self._status_texts)})" if self._status_texts else ""
        if result == NO_SPACE:
            return LinkError(f"the vehicle has no room for {count} mission slots "
                             f"({result_text(result)}){said}: lower `max_items` and plan again",
                             nothing_sent=highest < 0)
        if result in ITEM_RESULTS and highest >= 0:
            item = items[highest]
            return LinkError(f"the vehicle rejected item {item.seq} ({_command_name(item.command)}"
                             f", frame {item.frame}): {result_text(result)}{said}")
        if result == MAV_MISSION_DENIED:
            return LinkError(f"the vehicle refused the mission: {result_text(result)}{said} "
                             "(is another ground station uploading?)")
        return LinkError(f"the vehicle refused the mission: {result_text(result)}{said}")

    def _request_list(self, deadline: float) -> int:
        """Start a download transfer; the number of items the vehicle holds.  A vehicle still
        busy with an upload (it DENIES downloads until it gives that up) is asked again."""
        system, component = self._target
        timer = self._timer
        started = answered = time.monotonic()
        while (now := time.monotonic()) < deadline:
            if now - answered > FIRST_ANSWER_S:
                break
            self._link.mav.mission_request_list_send(system, component, self.mission_type)
            asked = time.monotonic()
            message = self._receive({"MISSION_COUNT", "MISSION_ACK"},
                                    min(timer.timeout_s, max(0.0, deadline - asked)))
            if message is not None and message.get_type() == "MISSION_COUNT":
                timer.sample(time.monotonic() - asked)
                return message.count
            if message is not None:
                answered = time.monotonic()
                if message.type == MAV_MISSION_DENIED:   # busy with an upload: ask again later
                    time.sleep(min(0.25, max(0.0, deadline - time.monotonic())))
            self.resent += 1
            timer.back_off()
        raise self._no_answer(f"no MISSION_COUNT for the download in {time.monotonic() - started:.0f} s")

    def download(self, progress: Progress | None = None) -> list[WireItem]:
        """Asks for the missing items only -- to ArduPilot, which serves any seq, several at a
        time; to others one at a time, in order -- each again after the retry timeout.  When
        the vehicle stops serving an item (a transfer it dropped after lost or repeated
        messages, or a vehicle that serves only in order and lost its place), starts a new
        transfer from item 0.  Bounded by the transfer deadline."""
        system, component = self._target
        self._timer = getattr(self, "_timer", None) or RetransmitTimer()
        timer = self._timer
        window = DOWNLOAD_WINDOW if self._autopilot == MAV_AUTOPILOT_ARDUPILOTMEGA else 1
        started = time.monotonic()
        count = self._request_list(started + self._budget(0))
        deadline = started + self._budget(count)
        items: dict[int, WireItem] = {}
        asked: dict[int, float] = {}          # outstanding requests: seq -> last sent
        tries: dict[int, int] = {}
        restarts = cursor = quiet = 0         # quiet: expiries in a row without any item
        kinds = {"MISSION_ITEM_INT", "MISSION_ITEM", "MISSION_COUNT"}
        while len(items) < count:
            now = time.monotonic()
            if now >= deadline:
                raise self._no_answer(f"the download got {len(items)} of {count} items in "
                                      f"{now - started:.0f} s, {restarts} restarts")
            while cursor in items:
                cursor += 1
            seq = cursor
            while len(asked) < window and seq < count:       # fill the window
                if seq not in items and seq not in asked:
                    self._link.mav.mission_request_int_send(system, component, seq,
                                                            self.mission_type)
                    asked[seq] = now
                    tries[seq] = tries.get(seq, 0) + 1
                    if tries[seq] > 1:
                        self.resent += 1
                seq += 1
            oldest = min(asked.values())
            message = self._receive(kinds, max(0.0, min(oldest + timer.timeout_s, deadline) - now))
            now = time.monotonic()
            if message is None:                               # the oldest request expired
                if now < oldest + timer.timeout_s:
                    continue
                timer.back_off()
                quiet += 1
                for late in [k for k, t in asked.items() if now - t >= timer.timeout_s / 2]:
                    del asked[late]                   # asked again when the window refills
                if quiet >= DOWNLOAD_RESTART_AFTER:
                    # The vehicle stopped serving: a new transfer, and from item 0 for a
                    # vehicle that serves only in order.
                    restarts += 1
                    quiet = 0
                    if self._request_list(deadline) != count:
                        raise LinkError("the vehicle's mission changed during the download")
                    asked.clear()
                    if window == 1:
                        items.clear()
                        cursor = 0
                continue
            if message.get_type() == "MISSION_COUNT":
                if message.count != count:            # ArduPilot's answer to a seq beyond it
                    raise LinkError("the vehicle's mission changed during the download")
                continue
            got = message.seq
            if got in items or not 0 <= got < count:
                continue                              # a duplicate, or a stale answer
            if got in asked and tries.get(got) == 1:
                timer.sample(now - asked[got])
            timer.settle()
            quiet = 0
            asked.pop(got, None)
            items[got] = wire_item_from(message)
            if progress is not None:
                progress(len(items), count, self.resent)
        self._link.mav.mission_ack_send(system, component, 0, self.mission_type)
        return [items[seq] for seq in range(count)]

class RetransmitTimer:
    """The retransmission timeout of a link, from its measured round trips (RFC 6298: smoothed
    round trip plus four deviations, doubled per unanswered retry, never below
    :data:`MIN_TIMEOUT_S` nor above the spec's :data:`TIMEOUT_S`)."""

    def __init__(self) -> None:
        self.srtt_s: float | None = None
        self.rttvar_s = 0.0
        self._base = TIMEOUT_S
        self.timeout_s = TIMEOUT_S

    def sample(self, rtt_s: float) -> None:
        if self.srtt_s is None:
            self.srtt_s, self.rttvar_s = rtt_s, rtt_s / 2
        else:
            self.rttvar_s = 0.75 * self.rttvar_s + 0.25 * abs(self.srtt_s - rtt_s)
            self.srtt_s = 0.875 * self.srtt_s + 0.125 * rtt_s
        self._base = min(TIMEOUT_S, max(MIN_TIMEOUT_S, self.srtt_s + 4 * self.rttvar_s))
        self.timeout_s = self._base

    def back_off(self) -> None:
        self.timeout_s = min(TIMEOUT_S, 2 * self.timeout_s)

    def settle(self) -> None:
        """An answer came: back to the measured timeout."""
        self.timeout_s = self._base
