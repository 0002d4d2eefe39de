"""The uploader interface: one subclass per MAVLink implementation, registered as a plugin.

An uploader moves wire items to a vehicle and back.  Everything around that -- ArduPilot's
home placeholder, the comparison with the plan, what to say when it fails -- lives in
:func:`dtsp_mission.upload.upload_mission`, once for every uploader.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from .wire import WireItem

#: ``progress(done, total)`` after every item that went out.
Progress = Callable[[int, int], None]

#: Spec timings (MAVLink mission protocol, as QGroundControl uses them).
TIMEOUT_S = 1.5          # for the first answer (count, list request, final ack)
ITEM_TIMEOUT_S = 0.25    # between items
RETRIES = 5
HEARTBEAT_TIMEOUT_S = 5.0


@dataclass(frozen=True)
class VehicleInfo:
    """What a vehicle told about itself before an upload; ``None`` / empty when unknown."""

    autopilot: int | None = None                   # MAV_AUTOPILOT of its heartbeat
    home_deg: tuple[float, float] | None = None    # HOME_POSITION latitude, longitude
    parameters: dict[str, float] = field(default_factory=dict)
    checked: bool = False                          # whether the uploader could ask at all


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
                 heartbeat_timeout_s: float = HEARTBEAT_TIMEOUT_S) -> None:
        self.connection = connection
        self.signing_key = signing_key
        self.heartbeat_timeout_s = heartbeat_timeout_s
        self.resent = 0   # items, counts and requests sent again after a timeout

    def open(self) -> None:
        """Open the link and wait for the vehicle's heartbeat."""
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def vehicle_info(self, parameter_names: tuple[str, ...] = ()) -> VehicleInfo:
        """The vehicle's autopilot, home and the named parameters, as far as this uploader
        can ask (the default: nothing is known)."""
        return VehicleInfo()

    def upload(self, items: list[WireItem], progress: Progress | None = None) -> None:
        """Send ``items`` (seq 0 first); returns when the vehicle accepted them."""
        raise NotImplementedError

    def download(self) -> list[WireItem]:
        """The mission the vehicle holds, seq 0 first."""
        raise NotImplementedError

    def __enter__(self) -> "Uploader":
        self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()
