"""Only the datagrams worth decoding, from a MAVLink link over UDP.

A vehicle on UDP sends its whole telemetry to the ground station's port: PX4's SITL sends
some 6,000 messages a second there (ATTITUDE, LOCAL_POSITION_NED ... at hundreds of hertz).
pymavlink decodes every one in Python; on a busy machine it falls behind, the socket's
buffer fills and the kernel drops datagrams -- among them the few a mission transfer waits
for (measured: 4,000 datagrams a second dropped with five busy processes on two cores, and
MISSION_COUNT never arrived within 6 s).  Reading a datagram's MAVLink headers takes a few
microseconds; :func:`keep_only` has the link skip, undecoded, every datagram whose messages
are none of those asked for, so the transfer's own messages keep up however much else comes.
"""

from __future__ import annotations

from collections.abc import Iterable

from pymavlink import mavutil

MAVLINK1_START, MAVLINK2_START = 0xFE, 0xFD
#: Datagrams skipped in a row before the link reports "nothing yet" (so its caller checks
#: its clock and sends its heartbeat even while telemetry keeps coming).
MAX_SKIPPED_IN_A_ROW = 256


def message_ids(datagram: bytes) -> list[int] | None:
    """The message ids of the MAVLink 1 and 2 packets a datagram holds, in order; None when
    it holds anything else (bytes that start no packet, a packet cut short): such a
    datagram is never skipped -- pymavlink sees it and says what is wrong with it."""
    ids: list[int] = []
    at, size = 0, len(datagram)
    while at < size:
        start = datagram[at]
        if start == MAVLINK2_START and at + 10 <= size:
            length, flags = datagram[at + 1], datagram[at + 2]
            ids.append(datagram[at + 7] | datagram[at + 8] << 8 | datagram[at + 9] << 16)
            at += 10 + length + 2 + (13 if flags & 0x01 else 0)     # signed: 13 bytes more
        elif start == MAVLINK1_START and at + 6 <= size:
            ids.append(datagram[at + 5])
            at += 6 + datagram[at + 1] + 2
        else:
            return None
    return ids if at == size else None


def ids_of(names: Iterable[str]) -> frozenset[int]:
    """The MAVLink message ids of message names (``"MISSION_COUNT"`` ...)."""
    return frozenset(getattr(mavutil.mavlink, f"MAVLINK_MSG_ID_{name}") for name in names)


def keep_only(link, names: Iterable[str]) -> bool:
    """Make a pymavlink UDP link (``udpin:``, ``udpout:``, ``udpbcast:``) pass on only the
    datagrams holding at least one message named in ``names``, or anything that is not
    plain MAVLink; the rest are read and dropped undecoded.  Links of other kinds (TCP,
    serial: byte streams, where packets are not aligned with reads) are left alone.
    Returns whether the link now filters."""
    if not isinstance(link, mavutil.mavudp):
        return False
    wanted = ids_of(names)
    raw_recv = link.recv

    def recv(*args, **kwargs):
        for _ in range(MAX_SKIPPED_IN_A_ROW):
            data = raw_recv(*args, **kwargs)
            if not data:
                return data
            ids = message_ids(data)
            if ids is None or not wanted.isdisjoint(ids):
                return data
        return ""                       # as pymavlink says "nothing yet"

    link.recv = recv
    return True
