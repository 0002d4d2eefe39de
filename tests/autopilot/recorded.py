"""A real SITL flight kept in ``tests/data``: its mission, track and reach events."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from dtsp_mission.autopilot.commands import Command
from dtsp_mission.export import read_mission
from dtsp_mission.frame import LocalFrame


def read_recorded(directory: Path):
    """(mission, track rows (time s, east m, north m), {seq: first reach time s}) of the flight
    in ``directory`` (``mission.plan``, ``track.csv``, ``reached.csv``)."""
    mission = read_mission(str(directory / "mission.plan"), None)
    with (directory / "track.csv").open() as handle:
        track = np.array([[float(r["time_s"]), float(r["east_m"]), float(r["north_m"])]
                          for r in csv.DictReader(handle)])
    with (directory / "reached.csv").open() as handle:
        reached = {int(r["seq"]): float(r["time_s"]) for r in csv.DictReader(handle)}
    return mission, track, reached


def waypoints_m(mission) -> np.ndarray:
    """The positions (local frame at the mission's home, m) of its NAV_WAYPOINT items, in order."""
    frame = LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg)
    waypoints = [item for item in mission.items if int(item.command) == Command.NAV_WAYPOINT]
    return frame.to_local(np.array([w.latitude_deg for w in waypoints]),
                          np.array([w.longitude_deg for w in waypoints]))
