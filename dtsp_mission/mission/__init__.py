"""From tour to mission: the flight path, its waypoints, and the list of mission items."""

from .build import DEFAULT_MAX_ITEMS, MissionSettings, build_mission
from .commands import Autopilot, Command, Frame
from .model import FlightPath, Home, Mission, MissionItem, degrees_to_e7

__all__ = ["Autopilot", "Command", "DEFAULT_MAX_ITEMS", "FlightPath", "Frame", "Home", "Mission",
           "MissionItem", "MissionSettings", "build_mission", "degrees_to_e7"]
