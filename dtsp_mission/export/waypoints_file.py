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

from ..errors import FileFormatError
from ..files import read_text
from ..mission import Autopilot, Command, Frame, Home, Mission, MissionItem, VehicleMission
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

    readable = True

    def read(self, path) -> VehicleMission:
        """Line 0 is home (as QGroundControl, Mission Planner and MAVProxy read it, for every
        autopilot); the format does not say the autopilot, so the mission is ArduPilot's (the
        format's origin) until an uploader learns the vehicle's (``autopilot_stated`` False)."""
        lines = [line for line in read_text(path).splitlines() if line.strip()]
        if not lines or lines[0].strip() != HEADER:
            raise FileFormatError(f"{path}: not a QGC WPL 110 file (the first line must be {HEADER!r})")
        rows = []
        for number, line in enumerate(lines[1:], start=2):
            fields = line.split("\t")
            try:
                if len(fields) != 12:
                    raise ValueError(f"{len(fields)} tab-separated fields instead of 12")
                values = [float(f) for f in fields]
                if not all(map(np.isfinite, values)):
                    raise ValueError("a value is not a finite number")
            except ValueError as error:
                raise FileFormatError(f"{path}, line {number}: {error}") from None
            rows.append(values)
        if len(rows) < 2:
            raise FileFormatError(f"{path}: no mission items after the home line")
        home = rows[0]
        items = tuple(MissionItem(int(r[3]), int(r[2]), tuple(r[4:8]), r[8], r[9], r[10], bool(r[11]))
                      for r in rows[1:])
        read = VehicleMission(items, Home(home[8], home[9], home[10]), Autopilot.ARDUPILOTMEGA,
                              autopilot_stated=False)
        problems = read.problems()
        if problems:
            raise FileFormatError(f"{path}: " + "; ".join(problems[:3]))
        return read
