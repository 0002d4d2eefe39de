"""Uploading a mission to a vehicle over MAVLink, and proving it arrived.

Every uploader, built-in or third-party, registers in the ``dtsp_mission.uploaders``
entry-point group as an :class:`Uploader` subclass.  :func:`upload_mission` is the one place
that turns a mission into wire items (ArduPilot's home placeholder included), runs the
upload, downloads the mission back and compares it item by item, and says exactly what the
vehicle holds when anything fails.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from ..errors import InputError, LinkError
from ..mission import VehicleMission
from ..plugins import load_group, working
from .base import Progress, Uploader
from .wire import WireItem, describe_vehicle, differences, to_wire

UPLOADER_GROUP = "dtsp_mission.uploaders"


def uploaders() -> dict[str, type[Uploader] | Exception]:
    """Installed uploaders by name; a plugin that fails to load maps to its error."""
    return load_group(UPLOADER_GROUP, lambda e: isinstance(e, type) and issubclass(e, Uploader),
                      "an Uploader subclass")


def get_uploader(name: str) -> type[Uploader]:
    available = working(uploaders())
    if name not in available:
        raise InputError(f"unknown uploader {name!r} (installed: {', '.join(sorted(available))})")
    return available[name]


@dataclass(frozen=True)
class UploadReport:
    """What an upload did: items on the wire (home placeholder included), time, resends, and
    whether the downloaded mission was compared with the plan and matched."""

    via: str
    items: int
    seconds: float
    resent: int
    verified: bool
    note: str = ""


def upload_mission(mission: VehicleMission, connection: str, via: str = "pymavlink",
                   verify: bool = True, signing_key: bytes | None = None,
                   progress: Progress | None = None,
                   heartbeat_timeout_s: float | None = None) -> UploadReport:
    """Upload ``mission`` and, with ``verify``, download it back and compare item by item.

    Returns only when the vehicle accepted the mission (and, with ``verify``, holds exactly
    it); otherwise raises :class:`LinkError` whose ``on_vehicle`` says what the vehicle holds.
    """
    uploader_class = get_uploader(via)
    if signing_key is not None and not uploader_class.supports_signing:
        raise InputError(f"the {via} uploader cannot sign MAVLink 2 messages; use --via pymavlink")
    options = {} if heartbeat_timeout_s is None else {"heartbeat_timeout_s": heartbeat_timeout_s}
    wire = to_wire(mission)
    started = time.perf_counter()
    with uploader_class(connection, signing_key=signing_key, **options) as uploader:
        try:
            uploader.upload(wire, progress)
        except LinkError as error:
            on_vehicle = _download_or_none(uploader) if verify else None
            if on_vehicle is not None and not differences(wire, on_vehicle, mission.autopilot):
                # The transfer broke off (typically the final ACK was lost), but the vehicle
                # demonstrably holds the plan: that is a verified upload.
                return UploadReport(via, len(wire), time.perf_counter() - started,
                                    uploader.resent, True,
                                    f"the transfer ended without an acknowledgement "
                                    f"({error.reason}), but the mission downloaded from the "
                                    "vehicle is exactly the plan")
            what = (describe_vehicle(on_vehicle, wire, mission.autopilot) if verify else
                    "the vehicle may hold part of this mission (not checked: --no-verify)")
            raise LinkError(f"upload failed: {error.reason}", what) from None
        if verify:
            try:
                on_vehicle = uploader.download()
            except LinkError as error:
                raise LinkError(f"the vehicle accepted the mission, but downloading it back to "
                                f"verify failed: {error.reason}",
                                "what the vehicle holds is not verified") from None
            problems = differences(wire, on_vehicle, mission.autopilot)
            if problems:
                raise LinkError("the vehicle accepted the upload, but the mission downloaded "
                                "from it differs from the plan: " + "; ".join(problems),
                                describe_vehicle(on_vehicle, wire, mission.autopilot))
        return UploadReport(via, len(wire), time.perf_counter() - started, uploader.resent,
                            verify)


def _download_or_none(uploader: Uploader) -> list[WireItem] | None:
    try:
        return uploader.download()
    except LinkError:
        return None


def download_mission(connection: str, via: str = "pymavlink",
                     signing_key: bytes | None = None) -> list[WireItem]:
    """The mission a vehicle holds, as wire items, seq 0 first."""
    with get_uploader(via)(connection, signing_key=signing_key) as uploader:
        return uploader.download()


__all__ = ["UPLOADER_GROUP", "UploadReport", "Uploader", "WireItem", "download_mission",
           "get_uploader", "to_wire", "upload_mission", "uploaders"]
