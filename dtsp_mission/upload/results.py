"""MAV_MISSION_RESULT values (pymavlink's) and what each means to the person uploading."""

from __future__ import annotations

from pymavlink.dialects.v20.common import MAV_MISSION_NO_SPACE, enums

#: What each result means, in the uploader's words (pymavlink gives the names and values).
_MEANINGS = {
    "MAV_MISSION_ACCEPTED": "accepted",
    "MAV_MISSION_ERROR": "the vehicle reported a generic error",
    "MAV_MISSION_UNSUPPORTED_FRAME": "the vehicle does not support the coordinate frame",
    "MAV_MISSION_UNSUPPORTED": "the vehicle does not support the command",
    "MAV_MISSION_NO_SPACE": "the vehicle has no room for this many items",
    "MAV_MISSION_INVALID": "an item has an invalid parameter",
    "MAV_MISSION_INVALID_PARAM1": "param1 is invalid",
    "MAV_MISSION_INVALID_PARAM2": "param2 is invalid",
    "MAV_MISSION_INVALID_PARAM3": "param3 is invalid",
    "MAV_MISSION_INVALID_PARAM4": "param4 is invalid",
    "MAV_MISSION_INVALID_PARAM5_X": "param5 (latitude) is invalid",
    "MAV_MISSION_INVALID_PARAM6_Y": "param6 (longitude) is invalid",
    "MAV_MISSION_INVALID_PARAM7": "param7 (altitude) is invalid",
    "MAV_MISSION_INVALID_SEQUENCE": "an item arrived out of sequence",
    "MAV_MISSION_DENIED": "the vehicle does not accept missions now (armed or busy?)",
    "MAV_MISSION_OPERATION_CANCELLED": "the operation was cancelled",
}

MISSION_RESULTS: dict[int, tuple[str, str]] = {
    value: (entry.name, _MEANINGS[entry.name])
    for value, entry in enums["MAV_MISSION_RESULT"].items() if entry.name in _MEANINGS}

#: The results that refuse one item (its frame, command or a parameter), not the upload.
ITEM_RESULTS = {value for value, (name, _) in MISSION_RESULTS.items()
                if name.startswith(("MAV_MISSION_UNSUPPORTED", "MAV_MISSION_INVALID"))
                and name != "MAV_MISSION_INVALID_SEQUENCE"}
NO_SPACE = MAV_MISSION_NO_SPACE


def result_text(result: int) -> str:
    """``NAME (meaning)`` for a MAV_MISSION_RESULT, also for values not in the table."""
    name, meaning = MISSION_RESULTS.get(result, (f"MAV_MISSION_RESULT {result}", "unknown result"))
    return f"{name}: {meaning}"
