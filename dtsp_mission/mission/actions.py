"""The actions at the targets (:mod:`dtsp_mission.targets.actions`) as mission items, in the
forms each autopilot accepts in a mission.

| action        | ArduPilot                                   | PX4                                   |
|---------------|---------------------------------------------|---------------------------------------|
| photo         | DO_DIGICAM_CONTROL, x = 1 (shoot)           | IMAGE_START_CAPTURE, 1 image          |
| ROI           | DO_SET_ROI at the target (ground level)     | DO_SET_ROI_LOCATION at the target     |
| ROI off       | DO_SET_ROI at 0, 0, 0 (ArduPilot's "none")  | DO_SET_ROI_NONE                       |
| gimbal pitch  | DO_MOUNT_CONTROL (pitch, roll 0, yaw 0)     | DO_GIMBAL_MANAGER_PITCHYAW (pitch)    |
| loiter        | NAV_LOITER_TURNS, tangent exit              | NAV_LOITER_TIME (turns at airspeed)   |

Where they go: an autopilot starts the DO items that follow a navigation item when that item
completes, so the photo and the loiter follow the target's waypoint (taken when it is
overflown), and the ROI and gimbal pitch for a target follow the previous target (the camera
turns to it for the whole leg).  The ROI is switched off after the last target.  A loiter is
whole circles through the target, tangent to the tour there (centre one radius to the side
the path turns), so that the aircraft overflies it once per circle and the tour goes on where
it left it.
"""

from __future__ import annotations

import math

from ..autopilot.commands import MOUNT_MODE_MAVLINK_TARGETING, Autopilot, Command, Frame
from .model import MissionItem

#: Default loiter radius, in turn radii: ArduPlane's L1 loiter law holds a circle wider than
#: the tightest turn (the same margin the guidance design widens turns by).
LOITER_RADIUS_RHO = 1.3


def _do(command: int, params=(0.0, 0.0, 0.0, 0.0), x: float = 0.0, y: float = 0.0, z: float = 0.0,
        role: str = "action", target: int = -1) -> MissionItem:
    return MissionItem(int(command), Frame.MISSION, tuple(float(p) for p in params), float(x),
                       float(y), float(z), True, role, target)


def photo_item(autopilot: Autopilot, target: int) -> MissionItem:
    """One picture, now."""
    if autopilot == Autopilot.ARDUPILOTMEGA:
        return _do(Command.DO_DIGICAM_CONTROL, x=1.0, role="photo", target=target)
    return _do(Command.IMAGE_START_CAPTURE, (0.0, 0.0, 1.0, 0.0), role="photo", target=target)


def roi_item(autopilot: Autopilot, latitude_deg: float, longitude_deg: float,
             target: int) -> MissionItem:
    """Point the camera at this place (at home's ground level)."""
    command = Command.DO_SET_ROI if autopilot == Autopilot.ARDUPILOTMEGA else Command.DO_SET_ROI_LOCATION
    return MissionItem(int(command), Frame.GLOBAL_RELATIVE_ALT, (0.0, 0.0, 0.0, 0.0),
                       float(latitude_deg), float(longitude_deg), 0.0, True, "roi", target)


def roi_off_item(autopilot: Autopilot) -> MissionItem:
    """No region of interest any more (the mount returns to its default)."""
    if autopilot == Autopilot.ARDUPILOTMEGA:
        return MissionItem(int(Command.DO_SET_ROI), Frame.GLOBAL_RELATIVE_ALT, (0.0, 0.0, 0.0, 0.0),
                           0.0, 0.0, 0.0, True, "roi_off")
    return _do(Command.DO_SET_ROI_NONE, role="roi_off")


def gimbal_item(autopilot: Autopilot, pitch_deg: float, target: int) -> MissionItem:
    """The gimbal to this pitch (degrees, -90 straight down), yaw ahead."""
    if autopilot == Autopilot.ARDUPILOTMEGA:
        return _do(Command.DO_MOUNT_CONTROL, (pitch_deg, 0.0, 0.0, 0.0),
                   z=MOUNT_MODE_MAVLINK_TARGETING, role="gimbal", target=target)
    return _do(Command.DO_GIMBAL_MANAGER_PITCHYAW, (pitch_deg, 0.0, 0.0, 0.0), role="gimbal",
               target=target)


def loiter_turns_params(turns: int, radius_m: float, clockwise: bool) -> tuple[float, ...]:
    """NAV_LOITER_TURNS' param1-4: the turns, the radius signed by direction (positive
    clockwise), the tangent exit."""
    return (float(turns), 0.0, float(radius_m if clockwise else -radius_m), 1.0)


def loiter_item(autopilot: Autopilot, centre_deg: tuple[float, float], altitude_m: float,
                radius_m: float, clockwise: bool, turns: int, airspeed_m_s: float | None,
                target: int) -> MissionItem:
    """``turns`` circles of ``radius_m`` around ``centre_deg``, leaving along the tangent.  PX4
    takes no turn count: the time they take at ``airspeed_m_s``."""
    params = loiter_turns_params(turns, radius_m, clockwise)
    if autopilot == Autopilot.ARDUPILOTMEGA:
        command = Command.NAV_LOITER_TURNS
    else:        # the same with the turns as the seconds they take
        command = Command.NAV_LOITER_TIME
        params = (float(math.ceil(turns * 2 * math.pi * radius_m / airspeed_m_s)), *params[1:])
    return MissionItem(int(command), Frame.GLOBAL_RELATIVE_ALT, params,
                       float(centre_deg[0]), float(centre_deg[1]), float(altitude_m), True,
                       "loiter", target)


def loiter_radius_m(rho_m: float, given_m: float | None) -> float:
    """The loiter radius: ``given_m``, or :data:`LOITER_RADIUS_RHO` rho rounded up to what
    ArduPilot stores exactly (whole metres to 255 m, tens of metres above)."""
    if given_m is not None:
        return float(given_m)
    wanted = LOITER_RADIUS_RHO * rho_m
    return float(math.ceil(wanted)) if wanted <= 255 else float(10 * math.ceil(wanted / 10))
