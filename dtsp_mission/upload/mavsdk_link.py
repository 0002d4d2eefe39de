"""Mission upload and download through MAVSDK's ``mission_raw`` plugin (PyPI ``mavsdk`` 4.x)."""

from __future__ import annotations

import threading

from ..errors import LinkError
from ..mavsdk_log import quiet_mavsdk_log
from .base import Progress, Uploader
from .connection import mavsdk_url
from ..autopilot.wire import WireItem

#: What each failing MissionRawResult means to the user.
_RESULTS = {
    "TOO_MANY_MISSION_ITEMS": "the vehicle has no room for this many mission items "
                              "(MAV_MISSION_NO_SPACE): lower `max_items` and plan again",
    "TIMEOUT": "the vehicle stopped answering (MAVSDK timed out)",
    "NO_SYSTEM": "the vehicle is gone (no heartbeat)",
    "DENIED": "the vehicle does not accept missions now (MAV_MISSION_DENIED; armed or busy?)",
    "BUSY": "another mission transfer is running",
    "UNSUPPORTED": "the vehicle rejected an item: command or frame not supported",
    "INVALID_ARGUMENT": "the vehicle rejected an item: invalid parameter",
    "INVALID_SEQUENCE": "the transfer went out of sequence (MAV_MISSION_INVALID_SEQUENCE)",
    "PROTOCOL_ERROR": "the vehicle broke the mission protocol",
    "NO_MISSION_AVAILABLE": "the vehicle holds no mission",
    "TRANSFER_CANCELLED": "the transfer was cancelled",
    "INT_MESSAGES_NOT_SUPPORTED": "the vehicle does not support MISSION_ITEM_INT",
}


def _error(result) -> LinkError:
    name = getattr(result, "name", str(result))
    return LinkError(_RESULTS.get(name, f"MAVSDK reported {name}"))


class MavsdkUploader(Uploader):
    """Mission upload and download with MAVSDK's ``mission_raw`` (no signing)."""

    name = "mavsdk"
    description = "MAVSDK's mission_raw plugin (the native mavsdk 4.x binding)"
    supports_signing = False

    def open(self) -> None:
        from mavsdk import ComponentType, Configuration, ConnectionResult, Mavsdk
        from mavsdk.plugins.mission_raw import MissionRaw
        if self.signing_key is not None:
            raise LinkError("MAVLink signing is not available through MAVSDK's Python binding; "
                            "use `via` pymavlink with `signing_key`")
        url = mavsdk_url(self.connection)
        quiet_mavsdk_log()
        self._mavsdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
        result = self._mavsdk.add_any_connection(url)
        if result != ConnectionResult.SUCCESS:
            self.close()
            raise LinkError(f"cannot open the connection {self.connection!r} ({url}): "
                            f"{getattr(result, 'name', result)}")
        system = self._mavsdk.first_autopilot(self.heartbeat_timeout_s)
        if system is None:
            self.close()
            raise LinkError(f"no heartbeat from a vehicle at {self.connection} within "
                            f"{self.heartbeat_timeout_s:g} s: is it on, and is the connection "
                            "right?")
        self._mission_raw = MissionRaw(system)

    def close(self) -> None:
        mavsdk = getattr(self, "_mavsdk", None)
        if mavsdk is not None:
            self._mission_raw = None
            mavsdk.destroy()
            self._mavsdk = None

    def upload(self, items: list[WireItem], progress: Progress | None = None) -> None:
        from mavsdk.plugins.mission_raw import MissionItem, MissionPlan, MissionRawResult
        plan = MissionPlan([MissionItem(**item.__dict__) for item in items])
        finished = threading.Event()
        outcome = []

        def report(result, data, _user_data) -> None:
            if result == MissionRawResult.NEXT:
                if progress is not None and data.progress == data.progress:   # not NaN
                    progress(round(data.progress * len(items)), len(items), 0)
                return
            outcome.append(result)
            finished.set()

        self._mission_raw.upload_mission_with_progress_async(plan, report)
        if not finished.wait(60.0 + 0.5 * len(items)):
            self._mission_raw.cancel_mission_upload()
            raise LinkError("the upload through MAVSDK did not finish in time")
        if outcome[0] != MissionRawResult.SUCCESS:
            raise _error(outcome[0])

    def download(self, progress=None) -> list[WireItem]:
        from mavsdk.plugins.mission_raw import MissionRawError
        try:
            downloaded = self._mission_raw.download_mission()
        except MissionRawError as error:
            if error.result.name == "NO_MISSION_AVAILABLE":
                return []
            raise _error(error.result) from None
        return [WireItem.normalised(i.seq, i.frame, i.command, i.current, i.autocontinue,
                                    i.param1, i.param2, i.param3, i.param4, i.x, i.y, i.z,
                                    i.mission_type) for i in downloaded]
