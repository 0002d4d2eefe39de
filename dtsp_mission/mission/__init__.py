"""From tour to mission: the flight path, its waypoints, and the list of mission items."""

from .build import build_mission
from .settings import DEFAULT_MAX_ITEMS, MissionSettings
from .guidance import DesignTuning
from ..autopilot.commands import AUTOPILOTS, Autopilot, Command, Frame
from .model import (FlightPath, Home, Mission, MissionItem, VehicleMission,
                    degrees_to_e7)

__all__ = ["AUTOPILOTS", "Autopilot", "Command", "DEFAULT_MAX_ITEMS", "DesignTuning", "FlightPath", "Frame", "Home", "Mission",
           "MissionItem", "MissionSettings", "VehicleMission", "build_mission", "degrees_to_e7"]
