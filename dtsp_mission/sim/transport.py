"""The links a simulated vehicle listens on: UDP (as ArduPilot's ``udpin``), a TCP server (as
ArduPilot SITL's ``tcp:5760``) and a pseudo-terminal that ground stations open as a serial
device (``/dev/pts/N,57600``), so every link an uploader supports can be tested without
hardware.

A transport moves bytes; framing is MAVLink's (the vehicle's parser keeps partial frames
across reads of a stream).
"""

from __future__ import annotations

import os
import select
import socket

LISTEN_FORMS = "udp:HOST:PORT, tcp:HOST:PORT or pty"


class Transport:
    """``receive(timeout_s)`` -> bytes or None; ``send(data)``; ``close()``; ``describe()``
    says how a ground station connects (a connection string)."""

    def receive(self, timeout_s: float) -> bytes | None:
        raise NotImplementedError

    def send(self, data: bytes) -> None:
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def describe(self) -> str:
        raise NotImplementedError


class UdpTransport(Transport):
    """Listens on ``host:port`` (0: a free port); replies go to whoever spoke last, or to
    ``gcs`` before anyone did."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0,
                 gcs: tuple[str, int] | None = None) -> None:
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._socket.bind((host, port))
        self.host, self.port = self._socket.getsockname()
        self._peer = gcs

    def receive(self, timeout_s: float) -> bytes | None:
        readable, _, _ = select.select([self._socket], [], [], timeout_s)
        if not readable:
            return None
        data, self._peer = self._socket.recvfrom(65535)
        return data

    def send(self, data: bytes) -> None:
        if self._peer is not None:
            try:
                self._socket.sendto(data, self._peer)
            except OSError:
                pass

    def close(self) -> None:
        self._socket.close()

    def describe(self) -> str:
        return f"udpout:{self.host}:{self.port}"


class TcpTransport(Transport):
    """A TCP server on ``host:port``; one ground station at a time (a new one replaces the
    old, as SITL's serial-over-TCP does)."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0) -> None:
        self._server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._server.bind((host, port))
        self._server.listen(1)
        self.host, self.port = self._server.getsockname()
        self._client: socket.socket | None = None

    def receive(self, timeout_s: float) -> bytes | None:
        sockets = [self._server] + ([self._client] if self._client is not None else [])
        readable, _, _ = select.select(sockets, [], [], timeout_s)
        if self._server in readable:
            client, _ = self._server.accept()
            client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            if self._client is not None:
                self._client.close()
            self._client = client
            return None
        if self._client is None or self._client not in readable:
            return None
        try:
            data = self._client.recv(65536)
        except OSError:
            data = b""
        if not data:                       # the ground station hung up
            self._client.close()
            self._client = None
            return None
        return data

    def send(self, data: bytes) -> None:
        if self._client is not None:
            try:
                self._client.sendall(data)
            except OSError:
                pass

    def close(self) -> None:
        if self._client is not None:
            self._client.close()
        self._server.close()

    def describe(self) -> str:
        return f"tcp:{self.host}:{self.port}"


class PtyTransport(Transport):
    """A pseudo-terminal: the vehicle holds the master side, a ground station opens
    :attr:`device` as a serial port (any baud rate)."""

    def __init__(self) -> None:
        import tty
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)            # bytes pass unchanged: no echo, no line editing
        tty.setraw(self._master)
        self.device = os.ttyname(self._slave)

    def receive(self, timeout_s: float) -> bytes | None:
        readable, _, _ = select.select([self._master], [], [], timeout_s)
        if not readable:
            return None
        try:
            return os.read(self._master, 65536)
        except OSError:
            return None

    def send(self, data: bytes) -> None:
        try:
            os.write(self._master, data)
        except OSError:
            pass

    def close(self) -> None:
        for fd in (self._master, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass

    def describe(self) -> str:
        return f"{self.device},57600"


def open_transport(listen: str, gcs: tuple[str, int] | None = None) -> Transport:
    """The transport for ``udp:HOST:PORT`` (or plain ``HOST:PORT``), ``tcp:HOST:PORT`` or
    ``pty``; ValueError for anything else, OSError if it cannot be opened."""
    if listen == "pty":
        return PtyTransport()
    scheme, _, rest = listen.partition(":")
    if scheme not in ("udp", "tcp"):
        scheme, rest = "udp", listen
    host, _, port = rest.rpartition(":")
    if not host or not port.isdigit() or int(port) > 65535:
        raise ValueError(f"{listen!r} is not one of {LISTEN_FORMS}")
    if scheme == "tcp":
        return TcpTransport(host, int(port))
    return UdpTransport(host, int(port), gcs)
