"""A loopback UDP proxy that damages traffic on purpose: drops, duplicates, reorders and
delays datagrams at set rates, from a seed.

The ground station sends to the proxy's port; the proxy forwards to the vehicle from a
socket of its own and sends the vehicle's answers back to the ground station.  Both
directions get the same treatment.
"""

from __future__ import annotations

import heapq
import itertools
import random
import select
import socket
import threading
import time
from dataclasses import dataclass


@dataclass(frozen=True)
class Faults:
    """Rates per datagram, each direction: ``drop``, ``duplicate``, ``reorder`` (held back
    behind the next one) and an extra delay drawn uniformly from [0, ``delay_s``]."""

    drop: float = 0.0
    duplicate: float = 0.0
    reorder: float = 0.0
    delay_s: float = 0.0
    seed: int = 0


class FaultProxy:
    """Forwards between ``udpout:127.0.0.1:PORT`` (its :attr:`port`) and the vehicle at
    ``vehicle`` (host, port), damaging datagrams as ``faults`` say.  Counts what it did in
    :attr:`counts`."""

    REORDER_HOLD_S = 0.05

    def __init__(self, vehicle: tuple[str, int], faults: Faults, host: str = "127.0.0.1") -> None:
        self.vehicle = vehicle
        self.faults = faults
        self._random = random.Random(faults.seed)
        self._front = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._front.bind((host, 0))
        self._back = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._back.bind((host, 0))
        self.port = self._front.getsockname()[1]
        self._gcs: tuple[str, int] | None = None
        self._queue: list[tuple[float, int, socket.socket, tuple[str, int], bytes]] = []
        self._order = itertools.count()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True, name="fault-proxy")
        self.counts = {"forwarded": 0, "dropped": 0, "duplicated": 0, "reordered": 0}

    def __enter__(self) -> "FaultProxy":
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self._front.close()
        self._back.close()

    def _schedule(self, sock: socket.socket, destination: tuple[str, int], data: bytes) -> None:
        faults, draw = self.faults, self._random.random
        if draw() < faults.drop:
            self.counts["dropped"] += 1
            return
        copies = 2 if draw() < faults.duplicate else 1
        if copies == 2:
            self.counts["duplicated"] += 1
        now = time.monotonic()
        for _ in range(copies):
            when = now + draw() * faults.delay_s
            if draw() < faults.reorder:
                when += self.REORDER_HOLD_S
                self.counts["reordered"] += 1
            heapq.heappush(self._queue, (when, next(self._order), sock, destination, data))

    def _run(self) -> None:
        while not self._stop.is_set():
            now = time.monotonic()
            while self._queue and self._queue[0][0] <= now:
                _, _, sock, destination, data = heapq.heappop(self._queue)
                try:
                    sock.sendto(data, destination)
                    self.counts["forwarded"] += 1
                except OSError:
                    pass
            wait = min(0.05, self._queue[0][0] - now) if self._queue else 0.05
            readable, _, _ = select.select([self._front, self._back], [], [], max(wait, 0.0))
            for sock in readable:
                try:
                    data, address = sock.recvfrom(65535)
                except OSError:
                    continue
                if sock is self._front:
                    self._gcs = address
                    self._schedule(self._back, self.vehicle, data)
                elif self._gcs is not None:
                    self._schedule(self._front, self._gcs, data)
