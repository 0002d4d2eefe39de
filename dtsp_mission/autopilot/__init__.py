"""The autopilot model: what a vehicle stores, its parameters, and how it navigates.

Mission design predicts a flight with it, the simulated vehicle stores and flies with it, and
the uploader verifies a download with it: one model below all three.
"""

from .commands import AUTOPILOTS, VEHICLE_TYPE_FIXED_WING, Autopilot, Command, Frame
from .storage import CAPACITY, MAVLINK_MAX_ITEMS, WireItem, capacity, comparable, stored_item

__all__ = ["AUTOPILOTS", "CAPACITY", "MAVLINK_MAX_ITEMS", "VEHICLE_TYPE_FIXED_WING", "Autopilot",
           "Command", "Frame", "WireItem", "capacity", "comparable", "stored_item"]
