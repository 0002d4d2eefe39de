"""The uploader interface: one subclass per MAVLink implementation, registered as a plugin.

An uploader moves wire items to a vehicle and back.  Everything around that -- ArduPilot's
home placeholder, the comparison with the plan, what to say when it fails -- lives in
:func:`dtsp_mission.upload.upload_mission`, once for every uploader.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from ..autopilot.wire import WireItem

#: ``progress(done, total, resent)`` as a transfer advances: items through, items in all, and
#: messages sent again so far (0 from an uploader that cannot tell).
Progress = Callable[[int, int, int], None]

#: The spec's mission-protocol timeout: the longest any retry waits.
TIMEOUT_S = 1.5
#: The shortest: retries wait the measured round trip plus four deviations, at least this.
MIN_TIMEOUT_S = 0.003
#: ArduPilot gives an upload up after 8 s without an item (MissionItemProtocol.h); quiet for
#: longer than this, an uploader starts a fresh transfer.
VEHICLE_GIVES_UP_S = 8.5
HEARTBEAT_TIMEOUT_S = 5.0


def transfer_timeout_s(items: int) -> float:
    """The default bound on one upload or download of ``items`` items: 30 s plus 0.1 s per
    item (a clean loopback transfer takes about 1 ms per item, a 57,600 baud telemetry radio
    some 30-50 ms: the bound leaves room for a radio at the edge of its range)."""
    return 30.0 + 0.1 * items


@dataclass(frozen=True)
class VehicleInfo:
    """What a vehicle told about itself before an upload; ``None`` / empty when unknown."""

    autopilot: int | None = None                   # MAV_AUTOPILOT of its heartbeat
    home_deg: tuple[float, float] | None = None    # HOME_POSITION latitude, longitude
    parameters: dict[str, float] = field(default_factory=dict)
    checked: bool = False                          # whether the uploader could ask at all
    #: the vehicle's own wind estimate (ArduPilot's WIND: m/s, degrees it comes from), if it
    #: sent one while asked the rest
    wind: tuple[float, float] | None = None
    #: HOME_POSITION's altitude above mean sea level, m
    home_amsl_m: float | None = None
    #: MAV_TYPE of its heartbeat (1: fixed wing)
    vehicle_type: int | None = None
    #: the parameters asked for (those missing from ``parameters`` were not answered in time)
    asked: tuple[str, ...] = ()


class Uploader:
    """Uploads and downloads missions over one link.

    Subclasses set ``name``, ``description`` and ``supports_signing`` and implement
    :meth:`open`, :meth:`close`, :meth:`upload` and :meth:`download`.  Every failure is a
    :class:`~dtsp_mission.errors.LinkError` whose message a user understands.  Use as a
    context manager: the link is opened on entry and closed on exit.
    """

    name: str = ""
    description: str = ""
    supports_signing: bool = False

    def __init__(self, connection: str, signing_key: bytes | None = None,
                 heartbeat_timeout_s: float = HEARTBEAT_TIMEOUT_S,
                 timeout_s: float | None = None) -> None:
        self.connection = connection
        self.signing_key = signing_key
        self.heartbeat_timeout_s = heartbeat_timeout_s
        self.timeout_s = timeout_s   # per transfer; None: transfer_timeout_s(items)
        self.resent = 0              # items, counts and requests sent again after a timeout
        self.fresh_starts = 0        # uploads started again with a new MISSION_COUNT
        self.stray_acks = 0          # acknowledgements that ended nothing (old, or repeats')

    def open(self) -> None:
        """Open the link and wait for the vehicle's heartbeat."""
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def vehicle_info(self, parameter_names: tuple[str, ...] = (),
                     wind_wait_s: float = 0.0, names_autopilot: int | None = None) -> VehicleInfo:
        """The vehicle's autopilot, home and the named parameters -- names of
        ``names_autopilot`` (MAV_AUTOPILOT; ArduPilot's if None), asked only of a vehicle that
        runs it -- as far as this uploader can ask, and its wind estimate if it sends one
        within ``wind_wait_s`` (the default: nothing is known)."""
        return VehicleInfo()

    #: The MAV_MISSION_TYPE the next transfers carry (0 mission, 1 FENCE, 2 RALLY); an
    #: uploader that can only carry mission items leaves :attr:`mission_types` at (0,).
    mission_type: int = 0
    mission_types: tuple[int, ...] = (0,)

    def upload(self, items: list[WireItem], progress: Progress | None = None) -> None:
        """Send ``items`` (seq 0 first); returns when the vehicle accepted them."""
        raise NotImplementedError

    def download(self, progress: Progress | None = None) -> list[WireItem]:
        """The mission the vehicle holds, seq 0 first."""
        raise NotImplementedError

    def __enter__(self) -> "Uploader":
        self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()
