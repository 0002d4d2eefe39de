"""QGC WPL 110 text files (``.waypoints``), read by Mission Planner, MAVProxy, QGroundControl
and pymavlink's ``MAVWPLoader``.

Line 1 is ``QGC WPL 110``; then one line per item with exactly 12 tab-separated fields:
``INDEX CURRENT FRAME COMMAND P1 P2 P3 P4 LAT LON ALT AUTOCONTINUE``.  Line 0 (index 0) is
home (frame GLOBAL, altitude above mean sea level), as all these readers expect; the mission
items follow from index 1.  Latitudes and longitudes are written in the shortest decimal that
reads back as the same double (a reader rounding to MISSION_ITEM_INT's 1e-7 degrees gets what
we would send); other numbers carry 6 decimals.
"""

from __future__ import annotations

import numpy as np

from ..mission import Command, Frame, Mission
from .base import Exporter

HEADER = "QGC WPL 110"


def _exact(degrees: float) -> str:
    """Shortest positional decimal that reads back as the same double (no exponent)."""
    return np.format_float_positional(float(degrees), unique=True, trim="-")


def _line(index: int, current: int, frame: int, command: int, params, latitude: float,
          longitude: float, altitude: float, autocontinue: bool) -> str:
    fields = [str(index), str(current), str(int(frame)), str(int(command)),
              *(f"{p:.6f}" for p in params), _exact(latitude), _exact(longitude),
              f"{altitude:.6f}", "1" if autocontinue else "0"]
    return "\t".join(fields)


def waypoints_text(mission: Mission) -> str:
    """The mission as QGC WPL 110 text, home first."""
    home = mission.home
    lines = [HEADER, _line(0, 1, Frame.GLOBAL, Command.NAV_WAYPOINT, (0.0, 0.0, 0.0, 0.0),
                           home.latitude_deg, home.longitude_deg, home.altitude_amsl_m, True)]
    for index, item in enumerate(mission.items, start=1):
        lines.append(_line(index, 0, item.frame, item.command, item.params, item.latitude_deg,
                           item.longitude_deg, item.altitude_m, item.autocontinue))
    return "\n".join(lines) + "\n"


class WaypointsExporter(Exporter):
    """QGC WPL 110 (``.waypoints``)."""

    name = "waypoints"
    extensions = (".waypoints",)
    description = "QGC WPL 110 .waypoints file"

    def render(self, mission: Mission) -> str:
        return waypoints_text(mission)
