"""Units of the aircraft's world: gravity, compass bearings and local headings.  (What radius
the aircraft turns at a bank is :meth:`dtsp_mission.autopilot.navigation.Airframe.turn_radius_m`.)"""

from __future__ import annotations

import math

#: Standard gravity, m/s^2.
STANDARD_GRAVITY_M_S2 = 9.80665


def bearing_to_heading_rad(bearing_deg: float) -> float:
    """Compass bearing (degrees clockwise from north) as a heading of the local frame
    (radians counter-clockwise from east)."""
    return math.radians(90.0 - bearing_deg)


def heading_to_bearing_deg(heading_rad: float) -> float:
    """Inverse of :func:`bearing_to_heading_rad`, in [0, 360)."""
    return (90.0 - math.degrees(heading_rad)) % 360.0
