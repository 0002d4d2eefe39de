"""The flight model against a real PX4 SITL (SIH) flight of a designed 100-target mission asking
18 m/s (``tests/data/px4-sitl-speed``): the SIH plane flies no faster than it can, and the
model, flying it so, passes the targets and takes the time the real one did."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dtsp_mission.autopilot.navigation import Airframe, closest_approach_m
from dtsp_mission.autopilot.parameters import PX4_DEFAULTS
from dtsp_mission.frame import LocalFrame
from dtsp_mission.sim.fly import targets_in
from dtsp_mission.sim.predict import predict_flight
from dtsp_mission.sitl.flight import measured_span, mission_seqs

from .recorded import read_recorded

DATA = Path(__file__).resolve().parents[1] / "data" / "px4-sitl-speed"


@pytest.fixture(scope="module")
def recorded():
    return read_recorded(DATA)


def test_the_sih_plane_flies_no_faster_than_it_can_whatever_the_mission_asks():
    assert Airframe.from_px4_parameters(PX4_DEFAULTS, airspeed_m_s=18.0).airspeed_m_s == 13.9
    assert Airframe.from_px4_parameters(PX4_DEFAULTS).airspeed_m_s == pytest.approx(13.9)
    slower = Airframe.from_px4_parameters(PX4_DEFAULTS, airspeed_m_s=12.0).airspeed_m_s
    assert slower == pytest.approx(12.0 * 13.9 / 15.0)


def test_the_model_takes_the_time_px4_took_and_passes_the_targets_as_it_did(recorded):
    """From the take-off's end to the last target: the model's time within 2 % of the real
    2,194 s (0.8 % today; 17 % short when it flew the 18 m/s asked), and per target the
    model's closest approach within 2 m of the real one at the 95th percentile (1.2 m today;
    2.5 m at 18 m/s) and 3 m at most (2.0 m; 3.05 m at 18 m/s)."""
    mission, track, reached = recorded
    first, last = mission_seqs(mission)
    flight = predict_flight(mission, Airframe.from_px4_parameters(PX4_DEFAULTS))
    real_s = reached[last] - reached[first]
    model_s = flight.reached[last] - flight.reached[first]
    assert model_s == pytest.approx(real_s, rel=0.02)
    targets = targets_in(mission)
    frame = LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg)
    points = frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    real = closest_approach_m(measured_span(track, reached, first, last), points)
    model = closest_approach_m(measured_span(flight.track, flight.reached, first, last), points)
    difference = np.abs(real - model)
    assert np.percentile(difference, 95) <= 2.0
    assert difference.max() <= 3.0
    assert real.max() <= 5.0                   # and the real flight held every target
