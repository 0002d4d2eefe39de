"""How closely the flight model, flying as PX4 navigates, reproduces a recorded PX4 flight.

A case folder holds what a real PX4 SITL (v1.16, its SIH fixed wing) was given and what it
did, in the format of ``tests/data/px4-sitl`` (read its README): ``mission.plan``,
``params.parm`` (PX4's names), ``track.csv`` (10 Hz, east/north in the plan's home frame),
``reached.csv`` (MISSION_ITEM_REACHED as received, repeated about once a second: the first of
each seq counts), ``items.csv`` (closest approach of the whole track to each navigation item)
and, for planned missions, ``misses.csv``.  :func:`compare_px4_case` flies the mission as PX4
stored it with the case's parameters (:meth:`Airframe.from_px4_parameters`) and measures what
:mod:`.arduplane_agreement` measures, so the tables read alike.  These flights are not
lock-stepped: a repeated real flight differs by a metre or two.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ..autopilot import Autopilot, Command
from ..autopilot.navigation import MODEL_STEP_S, Airframe, closest_approach_m
from ..autopilot.parameters import read_px4_parameters
from ..export import read_mission
from ..sim.predict import predict_flight
from .arduplane_agreement import RECORDED_AFTER_S, Agreement, _rows, agreement, timed_and_tracked


def compare_px4_case(folder: str | Path, airframe: Airframe | None = None,
                     dt_s: float = MODEL_STEP_S) -> Agreement:
    """The PX4 model against the recorded PX4 flight in ``folder``."""
    folder = Path(folder)
    airframe = airframe or Airframe.from_px4_parameters(read_px4_parameters(folder / "params.parm"))
    # uploaded in plan order, as PX4 stores it (the hand-made plans say ArduPilot)
    mission = replace(read_mission(folder / "mission.plan"), autopilot=Autopilot.PX4)
    predicted = predict_flight(mission, airframe, dt_s, RECORDED_AFTER_S, 7200.0)
    model, frame, model_reached = predicted.track, predicted.frame, dict(predicted.flight.reached)

    real_reached: dict[int, float] = {}
    for row in _rows(folder / "reached.csv"):
        real_reached.setdefault(int(row["seq"]), float(row["time_s"]))
    # the take-off's reach (seq 0), or where PX4 did not report it, the first item after it
    start_real = real_reached.get(0, real_reached[min(real_reached)])
    start_model = model_reached.get(0, 0.0)
    common, timing, real_xy, model_xy, track = timed_and_tracked(
        folder, frame, model, model_reached, real_reached, start_real, start_model, 1)
    end = common[-1]

    after_takeoff = model[model[:, 0] >= start_model, 1:3]
    if (folder / "misses.csv").exists():       # targets
        points = _rows(folder / "misses.csv")
        real_closest = np.array([float(r["miss_m"]) for r in points])
    else:       # waypoints before the last one reached (the recording stops as it is reached)
        points = [r for r in _rows(folder / "items.csv")
                  if int(r["command"]) == Command.NAV_WAYPOINT and int(r["seq"]) < end]
        real_closest = np.array([float(r["closest_whole_track_m"]) for r in points])
    xy = frame.to_local(np.array([float(r["lat"]) for r in points]),
                        np.array([float(r["lon"]) for r in points]))
    model_closest = closest_approach_m(after_takeoff, xy)
    return agreement(folder.name, common, timing, real_xy, model_xy, track, real_closest,
                     model_closest)
