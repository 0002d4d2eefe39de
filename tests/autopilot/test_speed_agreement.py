"""The flight model against a real ArduPlane SITL flight with slow zones
(``tests/data/arduplane-sitl-speed``): the airspeed changes as ArduPlane's TECS makes them,
and the navigation at the lower airspeed passes the waypoints as the real aircraft does."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from dtsp_mission.autopilot.navigation import Airframe, closest_approach_m
from dtsp_mission.sim.predict import predict_flight

from .recorded import read_recorded, waypoints_m

DATA = Path(__file__).resolve().parents[1] / "data" / "arduplane-sitl-speed"


@pytest.fixture(scope="module")
def recorded():
    mission, track, reached = read_recorded(DATA)
    return mission, track, reached, waypoints_m(mission)


def _speed_at(track: np.ndarray, north_m: float) -> float:
    """Ground speed (calm: the airspeed) where the northbound leg crosses ``north_m``."""
    t, x, y = track[:, 0], track[:, 1], track[:, 2]
    j = int(np.argmin(np.abs(y - north_m) + 1e6 * (np.abs(x) > 30.0)))
    a, b = max(j - 5, 0), min(j + 5, len(t) - 1)
    return float(np.hypot(x[b] - x[a], y[b] - y[a]) / (t[b] - t[a]))


def _fly(mission, airframe: Airframe = Airframe()):
    flight = predict_flight(mission, airframe)
    return flight.track[:, :3], dict(flight.reached)


def test_the_model_slows_down_as_arduplane_does(recorded):
    mission, track, _, _ = recorded
    model, _ = _fly(mission)
    # on the straight from the first waypoint (800 m north) towards the zig-zag
    for north in (900.0, 1000.0, 1100.0, 1200.0):
        assert _speed_at(model, north) == pytest.approx(_speed_at(track, north), abs=0.8)
    assert _speed_at(track, 1200.0) < 17.5         # the real aircraft is slow there


def test_the_waypoints_are_reached_when_arduplane_reaches_them(recorded):
    """Timing from the take-off's end: within 1.8 s at every waypoint (1.5 s today, most of
    it from the climb-out); with the airspeed changed at once, 3.4 s."""
    mission, _, reached, _ = recorded
    _, model = _fly(mission)
    _, instant = _fly(mission, replace(Airframe(), airspeed_up_m_s2=0.0, airspeed_down_m_s2=0.0))

    def worst(times):
        return max(abs((reached[s] - reached[1]) - (times[s] - times[1]))
                   for s in reached if s > 1 and s in times)
    assert worst(model) <= 1.8
    assert worst(instant) > worst(model) + 1.0


def test_the_model_passes_the_waypoints_as_arduplane_does(recorded):
    """Closest approach to each waypoint, real against model: within 0.6 m at each waypoint of
    the slow zig-zag; over the whole flight median 0.4 m and max 7 m (5.8 m today: the fast
    zig-zag entered while accelerating, where the real aircraft swings 4-6 m wider)."""
    mission, track, reached, points = recorded
    model, model_reached = _fly(mission)
    real = closest_approach_m(track[track[:, 0] >= reached[1], 1:3], points)
    predicted = closest_approach_m(model[model[:, 0] >= model_reached[1], 1:3], points)
    diff = np.abs(real - predicted)
    slow = slice(1, 8)                 # the waypoints flown at 16.5 m/s
    assert diff[slow].max() <= 0.6, diff[slow]
    assert np.median(diff) <= 0.4 and diff.max() <= 7.0, diff
