"""The aircraft as the planner sees it: turn radius, airspeed, autopilot."""

from __future__ import annotations

import math

from .errors import InputError

#: Standard gravity, m/s^2.
STANDARD_GRAVITY_M_S2 = 9.80665


def turn_radius_m(airspeed_m_s: float, max_bank_deg: float) -> float:
    """Radius of a coordinated level turn, ``v^2 / (g tan(bank))``: the smallest radius the
    aircraft flies at that airspeed without banking more than ``max_bank_deg``."""
    if not (math.isfinite(airspeed_m_s) and airspeed_m_s > 0):
        raise InputError(f"airspeed must be a number above 0 m/s, got {airspeed_m_s!r}")
    if not (math.isfinite(max_bank_deg) and 0 < max_bank_deg < 90):
        raise InputError(f"maximum bank must be between 0 and 90 degrees (exclusive), "
                         f"got {max_bank_deg!r}")
    return airspeed_m_s ** 2 / (STANDARD_GRAVITY_M_S2 * math.tan(math.radians(max_bank_deg)))


def bank_for_radius_deg(airspeed_m_s: float, rho_m: float) -> float:
    """Bank angle of a coordinated level turn of radius ``rho_m`` at ``airspeed_m_s``."""
    return math.degrees(math.atan(airspeed_m_s ** 2 / (STANDARD_GRAVITY_M_S2 * rho_m)))


def bearing_to_heading_rad(bearing_deg: float) -> float:
    """Compass bearing (degrees clockwise from north) as a heading of the local frame
    (radians counter-clockwise from east)."""
    return math.radians(90.0 - bearing_deg)


def heading_to_bearing_deg(heading_rad: float) -> float:
    """Inverse of :func:`bearing_to_heading_rad`, in [0, 360)."""
    return (90.0 - math.degrees(heading_rad)) % 360.0
