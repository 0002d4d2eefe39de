"""The vehicle's half of the MAVLink mission protocol, as ArduPilot's ``MissionItemProtocol``
runs it, on the vehicle's :class:`~dtsp_mission.autopilot.storage.MissionStore`.

Upload: MISSION_COUNT (NO_SPACE beyond the slots; the same ground station may restart an
upload at any time, another one is DENIED), then the vehicle asks for item ``request_i``,
writes each item in sequence as it arrives, answers an item of another seq with a stray
MISSION_ACK INVALID_SEQUENCE (and nothing else), asks again after ``re_request_s`` of quiet and
gives up after ``upload_timeout_s`` with OPERATION_CANCELLED; MISSION_ACK ACCEPTED after the
last item, sent once.  An item that arrives when no upload runs gets MISSION_ERROR.  Download:
MISSION_REQUEST_LIST and either request form, any seq in any order, as often as asked; a seq
beyond the mission gets the count again and MISSION_ERROR; both are DENIED while an upload
runs.  ArduPilot asks with MISSION_REQUEST, PX4 with MISSION_REQUEST_INT.

The timings are ArduPilot's (``MissionItemProtocol.h``: 1 s re-request, 8 s upload timeout);
the server is driven by :meth:`MissionServer.handle` for every message and
:meth:`MissionServer.update` a few times per second.
"""

from __future__ import annotations

import time
from typing import Callable

from pymavlink.dialects.v20.common import (MAV_MISSION_DENIED, MAV_MISSION_INVALID_SEQUENCE,
                                           MAV_MISSION_OPERATION_CANCELLED, MAV_MISSION_UNSUPPORTED,
                                           MAV_SEVERITY_INFO, MAV_SEVERITY_WARNING)

from ..autopilot import Autopilot
from ..autopilot.storage import ACCEPTED, ERROR, MISSION_TYPE_MISSION, MissionStore, wire_item_from


#: ``send(build)``: run ``build(encoder)`` with the vehicle's pymavlink encoder, its source ids set.
Send = Callable[[Callable], None]

PROTOCOL_MESSAGES = {"MISSION_COUNT", "MISSION_ITEM_INT", "MISSION_ITEM", "MISSION_REQUEST_LIST",
                     "MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_CLEAR_ALL", "MISSION_ACK"}


class MissionServer:
    """Serves uploads into and downloads from ``store``; ``on_stored()`` is called after every
    completed upload or clear, ``before_item(seq)`` before an item is written (fault
    injection: returning False drops it)."""

    def __init__(self, store: MissionStore, send: Send, *, re_request_s: float = 1.0,
                 upload_timeout_s: float = 8.0, on_stored: Callable[[], None] | None = None,
                 before_item: Callable[[int], bool] | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 mission_type: int = MISSION_TYPE_MISSION) -> None:
        self.store = store
        #: the MAV_MISSION_TYPE it serves (mission, FENCE 1, RALLY 2): each has its own store
        self.mission_type = mission_type
        self._send = send
        self.re_request_s = re_request_s
        self.upload_timeout_s = upload_timeout_s
        self._on_stored = on_stored or (lambda: None)
        self._before_item = before_item or (lambda seq: True)
        self._clock = clock
        self.receiving = False
        self._request_i = 0
        self._count = 0
        self._partner: tuple[int, int] = (0, 0)
        self._last_receive = self._last_request = 0.0
        self.counts = {"uploads": 0, "cancelled": 0, "invalid_sequence": 0, "requests_sent": 0}

    # -- messages ---------------------------------------------------------------------------

    def handle(self, message) -> bool:
        """Answer ``message`` if it belongs to the mission protocol; True if it did."""
        kind = message.get_type()
        if kind not in PROTOCOL_MESSAGES:
            return False
        source = (message.get_srcSystem(), message.get_srcComponent())
        if kind == "MISSION_COUNT":
            self._count_received(source, message.count)
        elif kind in ("MISSION_ITEM_INT", "MISSION_ITEM"):
            self._item_received(source, message)
        elif kind == "MISSION_REQUEST_LIST":
            if self.receiving:
                self._ack(source, MAV_MISSION_DENIED)
            else:
                self._send(lambda e: e.mission_count_send(*source, len(self.store.items),
                                                          self.mission_type))
        elif kind in ("MISSION_REQUEST_INT", "MISSION_REQUEST"):
            self._serve(source, message.seq, kind == "MISSION_REQUEST")
        elif kind == "MISSION_CLEAR_ALL":
            if self.receiving:
                self._ack(source, ERROR)
            else:
                self.store.clear()
                self._on_stored()
                self._ack(source, ACCEPTED)
        return True                        # MISSION_ACK from a ground station: nothing to do

    def _ack(self, target: tuple[int, int], result: int) -> None:
        kind = self.mission_type
        self._send(lambda e: e.mission_ack_send(*target, result, kind))

    def _count_received(self, source: tuple[int, int], count: int) -> None:
        if self.receiving and source != self._partner:
            self._ack(source, MAV_MISSION_DENIED)       # someone else is uploading
            return
        if self.receiving:
            self.store.abort()                          # the same station starts again
            self.receiving = False
        if self.store.begin(count) != ACCEPTED:
            slots = self.store.slots
            self._send(lambda e: e.statustext_send(MAV_SEVERITY_WARNING,
                                                   f"Only {slots} items are supported".encode()))
            self._ack(source, 4)                        # MAV_MISSION_NO_SPACE
            return
        if count == 0:
            self.store.complete()
            self._on_stored()
            self._ack(source, ACCEPTED)
            return
        self.receiving, self._partner = True, source
        self._request_i, self._count = 0, count
        self._last_receive = self._clock()
        self._request()

    def _request(self) -> None:
        seq, (system, component) = self._request_i, self._partner
        self._last_request = self._clock()
        self.counts["requests_sent"] += 1
        if self.store.autopilot == Autopilot.ARDUPILOTMEGA:
            self._send(lambda e: e.mission_request_send(system, component, seq, self.mission_type))
        else:
            self._send(lambda e: e.mission_request_int_send(system, component, seq, self.mission_type))

    def _item_received(self, source: tuple[int, int], message) -> None:
        if not self.receiving:
            self._ack(source, ERROR)
            return
        if message.seq != self._request_i:
            self.counts["invalid_sequence"] += 1
            self._ack(source, MAV_MISSION_INVALID_SEQUENCE)
            return
        if source != self._partner:
            self._ack(source, MAV_MISSION_DENIED)
            return
        if not self._before_item(message.seq):
            return
        result = self.store.write(wire_item_from(message, current=0))
        if result != ACCEPTED:
            self.store.abort()
            self.receiving = False
            self._ack(source, result)
            return
        self._last_receive = self._clock()
        self._request_i += 1
        if self._request_i >= self._count:
            self.store.complete()
            self.receiving = False
            self.counts["uploads"] += 1
            self._on_stored()
            if self.mission_type == MISSION_TYPE_MISSION:
                self._send(lambda e: e.statustext_send(MAV_SEVERITY_INFO, b"Flight plan received"))
            self._ack(source, ACCEPTED)
            return
        self._request()

    def _serve(self, source: tuple[int, int], seq: int, float_form: bool) -> None:
        if self.receiving:
            self._ack(source, MAV_MISSION_DENIED)
            return
        items = self.store.items
        if not 0 <= seq < len(items):
            count = len(items)
            self._send(lambda e: e.mission_count_send(*source, count, self.mission_type))
            self._ack(source, ERROR)
            return
        i = items[seq]
        if float_form:
            self._send(lambda e: e.mission_item_send(
                *source, i.seq, i.frame, i.command, 0, i.autocontinue, i.param1, i.param2,
                i.param3, i.param4, i.x / 1e7, i.y / 1e7, i.z, self.mission_type))
        else:
            self._send(lambda e: e.mission_item_int_send(
                *source, i.seq, i.frame, i.command, 0, i.autocontinue, i.param1, i.param2,
                i.param3, i.param4, i.x, i.y, i.z, self.mission_type))

    # -- time -------------------------------------------------------------------------------

    def update(self) -> None:
        """Ask again for the awaited item after ``re_request_s`` of quiet; cancel the upload
        after ``upload_timeout_s`` without an item."""
        if not self.receiving:
            return
        now = self._clock()
        if now - self._last_receive > self.upload_timeout_s:
            self.receiving = False
            self.store.abort()
            self.counts["cancelled"] += 1
            partner = self._partner
            self._send(lambda e: e.statustext_send(MAV_SEVERITY_WARNING, b"Mission upload timeout"))
            self._ack(partner, MAV_MISSION_OPERATION_CANCELLED)
            return
        if now - self._last_request > self.re_request_s:
            self._request()

    def reset(self) -> None:
        """A reboot: no upload runs any more (the store keeps what it holds)."""
        if self.receiving:
            self.store.abort()
        self.receiving = False
