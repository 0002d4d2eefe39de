"""Datagrams dropped undecoded on a UDP link (dtsp_mission.upload.datagrams): the MAVLink
headers are read right for every packet kind pymavlink writes, and over a real loopback
socket a link buried under telemetry still gets every message it listens to."""

from __future__ import annotations

import socket
import time

from pymavlink import mavutil
from pymavlink.dialects.v10 import ardupilotmega as mavlink1
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from conftest import free_udp_port
from dtsp_mission.upload.datagrams import keep_only, message_ids
from dtsp_mission.upload.pymavlink_link import LISTENS_TO, use_mavlink2


class _Buffer:
    def __init__(self) -> None:
        self.data = b""

    def write(self, data: bytes) -> None:
        self.data += bytes(data)


def _packets(signed: bool = False):
    """Packets as pymavlink writes them: a telemetry message, a mission count (its zero
    tail cut off, as MAVLink 2 sends it), a status text."""
    sent = _Buffer()
    mav = mavlink2.MAVLink(sent, srcSystem=1, srcComponent=1)
    if signed:
        mav.signing.secret_key = bytes(range(32))
        mav.signing.link_id = 0
        mav.signing.timestamp = 1
        mav.signing.sign_outgoing = True
    packets = []
    for send in (lambda: mav.attitude_send(1, 0.1, 0.2, 0.3, 0, 0, 0),
                 lambda: mav.mission_count_send(255, 190, 3, 0),
                 lambda: mav.statustext_send(6, b"hello")):
        sent.data = b""
        send()
        packets.append(sent.data)
    return packets


def test_the_headers_of_every_packet_kind_are_read():
    attitude, count, text = _packets()
    assert message_ids(attitude) == [30]
    assert message_ids(count) == [44]
    assert message_ids(attitude + count + text) == [30, 44, 253]     # several in one datagram
    signed = _packets(signed=True)
    assert signed[1][2] & 0x01                                       # really signed
    assert message_ids(b"".join(signed)) == [30, 44, 253]
    version1 = _Buffer()
    mavlink1.MAVLink(version1, srcSystem=1, srcComponent=1).heartbeat_send(1, 3, 0, 0, 0)
    assert version1.data[0] == 0xFE and message_ids(version1.data) == [0]


def test_what_is_not_plain_mavlink_is_never_dropped():
    attitude, count, _ = _packets()
    assert message_ids(b"") == []
    assert message_ids(b"hello") is None                             # no start byte
    assert message_ids(attitude[:-3]) is None                        # cut short
    assert message_ids(attitude + b"\x00") is None                   # something after it
    assert message_ids(count[:5]) is None                            # a header cut short


def test_a_link_under_a_flood_of_telemetry_gets_every_message_it_listens_to():
    use_mavlink2()
    port = free_udp_port()
    link = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255,
                                      source_component=190)
    try:
        assert keep_only(link, LISTENS_TO)
        link.port.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
        attitude, count, text = _packets()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as vehicle:
            flood = 2000
            for i in range(flood):
                vehicle.sendto(attitude, ("127.0.0.1", port))
                if i % 500 == 250:
                    vehicle.sendto(count, ("127.0.0.1", port))
            vehicle.sendto(attitude + text, ("127.0.0.1", port))     # a wanted one in company
            vehicle.sendto(b"not mavlink", ("127.0.0.1", port))
            got, started = [], time.monotonic()
            while time.monotonic() - started < 10 and len(got) < 7:
                message = link.recv_match(blocking=True, timeout=0.5)
                if message is not None:
                    got.append(message.get_type())
        # the four counts, the status text's datagram whole, and the stranger for pymavlink
        assert got == ["MISSION_COUNT"] * 4 + ["ATTITUDE", "STATUSTEXT", "BAD_DATA"]
    finally:
        link.close()


def test_links_that_are_byte_streams_are_left_alone():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as server:
        server.bind(("127.0.0.1", 0))
        server.listen(1)
        link = mavutil.mavlink_connection(f"tcp:127.0.0.1:{server.getsockname()[1]}")
        try:
            assert not keep_only(link, LISTENS_TO)
        finally:
            link.close()
