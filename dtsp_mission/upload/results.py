"""MAV_MISSION_RESULT values and what each means to the person uploading."""

from __future__ import annotations

MISSION_RESULTS: dict[int, tuple[str, str]] = {
    0: ("MAV_MISSION_ACCEPTED", "accepted"),
    1: ("MAV_MISSION_ERROR", "the vehicle reported a generic error"),
    2: ("MAV_MISSION_UNSUPPORTED_FRAME", "the vehicle does not support the coordinate frame"),
    3: ("MAV_MISSION_UNSUPPORTED", "the vehicle does not support the command"),
    4: ("MAV_MISSION_NO_SPACE", "the vehicle has no room for this many items"),
    5: ("MAV_MISSION_INVALID", "an item has an invalid parameter"),
    6: ("MAV_MISSION_INVALID_PARAM1", "param1 is invalid"),
    7: ("MAV_MISSION_INVALID_PARAM2", "param2 is invalid"),
    8: ("MAV_MISSION_INVALID_PARAM3", "param3 is invalid"),
    9: ("MAV_MISSION_INVALID_PARAM4", "param4 is invalid"),
    10: ("MAV_MISSION_INVALID_PARAM5_X", "param5 (latitude) is invalid"),
    11: ("MAV_MISSION_INVALID_PARAM6_Y", "param6 (longitude) is invalid"),
    12: ("MAV_MISSION_INVALID_PARAM7", "param7 (altitude) is invalid"),
    13: ("MAV_MISSION_INVALID_SEQUENCE", "an item arrived out of sequence"),
    14: ("MAV_MISSION_DENIED", "the vehicle does not accept missions now (armed or busy?)"),
    15: ("MAV_MISSION_OPERATION_CANCELLED", "the operation was cancelled"),
}

ITEM_RESULTS = {2, 3, 5, 6, 7, 8, 9, 10, 11, 12}
NO_SPACE = 4


def result_text(result: int) -> str:
    """``NAME (meaning)`` for a MAV_MISSION_RESULT, also for values not in the table."""
    name, meaning = MISSION_RESULTS.get(result, (f"MAV_MISSION_RESULT {result}", "unknown result"))
    return f"{name}: {meaning}"
