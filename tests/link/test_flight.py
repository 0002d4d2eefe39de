"""The simulator's flight model on its own: bank-limited turns, ArduPlane's waypoint
completion, and miss distances measured against the exact planned path."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import make_mission
from dtsp_mission.autopilot.navigation import (G, Airframe, MissionFlight, closest_approach_m,
                                              launch_heading_rad)
from dtsp_mission.sim.vehicle import SimulatedVehicle, VehicleSettings
from dtsp_mission.autopilot.wire import first_mission_seq, to_wire


def fly_offline(mission, airframe: Airframe):
    vehicle = SimulatedVehicle(VehicleSettings(mission.home, mission.autopilot, airframe))
    try:
        vehicle.mission = to_wire(mission.for_vehicle())
        items = vehicle.local_items()
    finally:
        vehicle._transport.close()
    first = first_mission_seq(mission.autopilot)
    flight = MissionFlight(items, airframe, launch_heading_rad(items, first), first)
    track, banks = [(0.0, 0.0, 0.0)], []
    while not flight.finished and flight.state.time_s < 4000:
        flight.step(0.05)
        track.append((flight.state.x_m, flight.state.y_m, flight.state.alt_m))
        banks.append(abs(flight.state.bank_rad))
    return flight, np.array(track), np.array(banks)


@pytest.mark.parametrize("autopilot,return_mode", [("ardupilot", "rtl"), ("px4", "land")])
def test_flies_every_item_and_never_turns_tighter_than_its_limit(autopilot, return_mode):
    mission = make_mission(10, 5, 80.0, span_m=1500.0, autopilot=autopilot,
                           return_mode=return_mode, airspeed_m_s=20.0)
    airframe = Airframe(20.0, 80.0, 8.0)
    flight, track, banks = fly_offline(mission, airframe)
    assert flight.finished
    wire = to_wire(mission.for_vehicle())
    assert [seq for seq, _ in flight.reached] == list(range(first_mission_seq(mission.autopilot), len(wire)))
    radius = 20.0 ** 2 / (G * np.tan(banks.max()))
    assert radius >= 80.0 * (1 - 1e-9)
    if return_mode == "land":
        assert track[-1, 2] == pytest.approx(0.0, abs=1e-9)   # on the ground at the end


def test_with_a_turn_margin_targets_are_passed_within_5_m():
    """An aircraft whose limit is 10 % tighter than the planned rho follows the plan closely;
    the measured miss distances are the figure the docs report."""
    mission = make_mission(30, 11, 80.0, span_m=2500.0, airspeed_m_s=20.0)
    flight, track, _ = fly_offline(mission, Airframe(20.0, 72.0, 5.0, roll_natural_rad_s=6.0, roll_damping=0.8))
    targets = mission.path.chain.pose_at(mission.path.target_s_m)[:, :2]
    miss = closest_approach_m(track[:, :2], targets)
    print(f"miss distances with a 10 % margin: median {np.median(miss):.2f} m, max {miss.max():.2f} m")
    assert flight.finished and miss.max() <= 5.0


def test_closest_approach_is_exact_on_segments():
    track = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    points = np.array([[5.0, 3.0], [12.0, 5.0], [-4.0, -3.0]])
    assert closest_approach_m(track, points) == pytest.approx([3.0, 2.0, 5.0])


def test_the_flight_estimate_said_before_flying_is_the_mission_s_length():
    """``fly`` says up front how long the flight is and bounds its wait by it: the estimate
    (straight legs between the stored positions, loiter circles, the way home) is within 1 %
    of the planned flight for waypoint missions."""
    from dtsp_mission.sim.fly import estimated_flight_m
    for mission in (make_mission(8, 4, 80.0, span_m=1200.0, airspeed_m_s=20.0),
                    make_mission(40, 7, 80.0, airspeed_m_s=20.0, design="geometry")):
        estimate = estimated_flight_m(mission.for_vehicle(), 80.0)
        assert abs(estimate / mission.summary["flight_length_m"] - 1.0) < 0.01
