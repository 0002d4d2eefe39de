"""The MAVLink enumeration values the mission uses, named as in the MAVLink common dialect.

Kept here (not imported from pymavlink) so the mission model stays free of the protocol
library; a test checks every value against pymavlink's generated dialect.
"""

from __future__ import annotations

from enum import IntEnum


class Command(IntEnum):
    """MAV_CMD values."""

    NAV_WAYPOINT = 16
    NAV_LOITER_UNLIM = 17
    NAV_LOITER_TURNS = 18
    NAV_LOITER_TIME = 19
    NAV_RETURN_TO_LAUNCH = 20
    NAV_LAND = 21
    NAV_TAKEOFF = 22
    DO_CHANGE_SPEED = 178
    DO_LAND_START = 189
    DO_SET_ROI_LOCATION = 195
    DO_SET_ROI_NONE = 197
    DO_SET_ROI = 201
    DO_DIGICAM_CONTROL = 203
    DO_MOUNT_CONTROL = 205
    DO_GIMBAL_MANAGER_PITCHYAW = 1000
    IMAGE_START_CAPTURE = 2000


#: MAV_MOUNT_MODE_MAVLINK_TARGETING: the mount follows the angles it is given.
MOUNT_MODE_MAVLINK_TARGETING = 2


class Frame(IntEnum):
    """MAV_FRAME values."""

    GLOBAL = 0
    MISSION = 2
    GLOBAL_RELATIVE_ALT = 3
    GLOBAL_INT = 5
    GLOBAL_RELATIVE_ALT_INT = 6
    GLOBAL_TERRAIN_ALT = 10
    GLOBAL_TERRAIN_ALT_INT = 11


class Autopilot(IntEnum):
    """MAV_AUTOPILOT values, as QGroundControl's ``firmwareType``."""

    ARDUPILOTMEGA = 3
    PX4 = 12


#: MAV_TYPE_FIXED_WING, QGroundControl's ``vehicleType`` for these missions.
VEHICLE_TYPE_FIXED_WING = 1

AUTOPILOTS = {"ardupilot": Autopilot.ARDUPILOTMEGA, "px4": Autopilot.PX4}
