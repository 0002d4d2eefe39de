"""The simulated vehicle's flight without the network: a mission, as the autopilot stores it,
flown by the flight model from rest at home, in the local frame at home.

The same items the simulated vehicle would fly after an upload (stored as the autopilot keeps
them, ArduPilot's home slot skipped), so an offline prediction and ``fly`` agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..autopilot import Command, stored_item
from ..autopilot.navigation import (CALM, FLIGHT_LIMIT_S, MODEL_STEP_S, Airframe, LocalItem,
                                    MissionFlight, Wind, launch_heading_rad, local_items)
from ..frame import LocalFrame
from ..autopilot.mission import VehicleMission
from ..autopilot.wire import first_mission_seq, to_wire

_FLOWN = (Command.NAV_WAYPOINT, Command.NAV_LOITER_TURNS, Command.NAV_LOITER_TIME)


@dataclass(frozen=True)
class PredictedFlight:
    """Track rows (time s, x, y, altitude above home; local frame at home), reach times by
    vehicle seq, and the frame."""

    track: np.ndarray
    reached: dict[int, float]
    frame: LocalFrame
    flight: MissionFlight


def predict_flight(mission: VehicleMission, airframe: Airframe, dt_s: float = MODEL_STEP_S,
                   after_last_s: float = 0.0, limit_s: float = FLIGHT_LIMIT_S,
                   wind: Wind = CALM) -> PredictedFlight:
    """Fly ``mission`` in ``wind`` until its last waypoint or loiter is reached, then
    ``after_last_s`` more (in RTL, as ArduPlane goes on after a mission without one)."""
    home = mission.home
    frame = LocalFrame(home.latitude_deg, home.longitude_deg)
    wire = [stored_item(item, mission.autopilot) for item in to_wire(mission)]
    items = local_items(wire, frame, home.altitude_amsl_m)
    if items[-1].command != Command.NAV_RETURN_TO_LAUNCH:
        items.append(LocalItem(len(items), Command.NAV_RETURN_TO_LAUNCH, math.nan, math.nan,
                               items[-1].alt_m, (0.0, 0.0, 0.0, 0.0)))
    first = first_mission_seq(mission.autopilot)
    heading = launch_heading_rad(items, first)
    flight = MissionFlight(items, airframe, heading, first, wind)
    last = max((i.seq for i in items if i.command in _FLOWN), default=first)
    head = np.zeros((1, 4))
    run = flight.run(dt_s, stop_after_seq=last, until_s=limit_s)
    track = [head, run.track]
    if not flight.finished and after_last_s > 0:
        track.append(flight.run(dt_s, until_s=min(flight.time_s + after_last_s, limit_s)).track)
    return PredictedFlight(np.concatenate(track), dict(flight.reached), frame, flight)
