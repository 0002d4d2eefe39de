"""Connection strings and signing keys, read once for every uploader.

Users write pymavlink-style connections (``udpout:127.0.0.1:14550``, ``udpin:0.0.0.0:14550``,
``tcp:HOST:PORT``, ``/dev/ttyACM0,57600``); :func:`mavsdk_url` gives MAVSDK's form of the same.
"""

from __future__ import annotations

import hashlib
import os
import re
import socket

from ..errors import InputError, LinkError
from ..files import read_bytes

DEFAULT_BAUD = 57600


def mavsdk_url(connection: str) -> str:
    """MAVSDK's connection URL for a pymavlink-style connection string (URLs pass unchanged)."""
    if "://" in connection:
        return connection
    scheme, _, rest = connection.partition(":")
    if scheme == "udpout" and rest:
        return f"udpout://{rest}"
    if scheme in ("udpin", "udp") and rest:
        return f"udpin://{rest}"
    if scheme in ("tcp", "tcpout") and rest:
        return f"tcpout://{rest}"
    if scheme == "tcpin" and rest:
        return f"tcpin://{rest}"
    device, _, baud = connection.partition(",")
    if device.startswith("/dev/") or re.fullmatch(r"COM\d+", device):
        return f"serial://{device}:{baud or DEFAULT_BAUD}"
    raise InputError(f"cannot read the connection {connection!r}: use udpout:HOST:PORT, "
                     "udpin:HOST:PORT, tcp:HOST:PORT or a serial device like /dev/ttyACM0,57600")


def check_host(connection: str) -> None:
    """For ``udp*:HOST:PORT`` and ``tcp*:HOST:PORT``: raise :class:`LinkError` unless HOST
    resolves and PORT is a port number."""
    url = mavsdk_url(connection)
    scheme, _, rest = url.partition("://")
    if not scheme.startswith(("udp", "tcp")):
        return
    host, _, port = rest.rpartition(":")
    if not port.isdigit():
        raise InputError(f"cannot read the connection {connection!r}: the port must be a number "
                         f"from 1 to 65535, got {port!r}")
    if not 1 <= int(port) <= 65535:
        raise InputError(f"cannot read the connection {connection!r}: port {int(port)} is not "
                         "a port number (1 to 65535)")
    try:
        socket.getaddrinfo(host or "0.0.0.0", int(port))
    except socket.gaierror as error:
        raise LinkError(f"cannot open the connection {connection!r}: host {host!r} is unknown "
                        f"({error.strerror})") from None


def read_signing_key(path: str | os.PathLike) -> bytes:
    """The 32-byte MAVLink 2 signing key in ``path``: 32 raw bytes, 64 hex digits, or else a
    passphrase whose SHA-256 is the key (as MAVProxy and Mission Planner derive it)."""
    data = read_bytes(path)
    if len(data) == 32:
        return data
    try:
        text = data.decode("utf-8").strip()
    except UnicodeDecodeError:
        raise InputError(f"{path}: a signing key file holds 32 raw bytes, 64 hex digits or a "
                         f"passphrase; this holds {len(data)} bytes of binary data") from None
    if re.fullmatch(r"[0-9a-fA-F]{64}", text):
        return bytes.fromhex(text)
    if not text:
        raise InputError(f"{path}: the signing key file is empty")
    return hashlib.sha256(text.encode("utf-8")).digest()
