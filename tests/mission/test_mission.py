"""From tour to mission items: flight path, waypoints within tolerance, targets exact, budget."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymavlink.dialects.v20 import common as mavlink

from conftest import make_mission
from dtsp_mission.errors import InputError
from dtsp_mission.mission import Autopilot, Command, Frame
from dtsp_mission.mission.discretise import deviation_m, waypoint_s
from dtsp_mission.mission.flight_path import approach
from dtsp_mission.tour.check import check_path
from dtsp_mission.vehicle import heading_to_bearing_deg


def test_enumeration_values_are_mavlinks():
    for command in Command:
        assert getattr(mavlink, f"MAV_CMD_{command.name}") == command.value
    for frame in Frame:
        assert getattr(mavlink, f"MAV_FRAME_{frame.name}") == frame.value
    for autopilot in Autopilot:
        assert getattr(mavlink, f"MAV_AUTOPILOT_{autopilot.name}") == autopilot.value


def polyline_distance_m(points: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """Distance from every point to the polyline through ``vertices`` (brute force)."""
    a, b = vertices[:-1], vertices[1:]
    best = np.full(len(points), np.inf)
    for start in range(0, len(points), 2000):
        p = points[start:start + 2000, None, :]
        direction = b - a
        squared = np.maximum(np.einsum("ij,ij->i", direction, direction), 1e-300)
        t = np.clip(np.einsum("kij,ij->ki", p - a, direction) / squared, 0.0, 1.0)
        nearest = a + t[..., None] * direction
        best[start:start + 2000] = np.min(np.hypot(*(p - nearest).transpose(2, 0, 1)), axis=1)
    return best


def item_polyline(mission) -> np.ndarray:
    positioned = [i for i in mission.items if i.has_position and i.command != Command.NAV_LAND]
    return mission.frame.to_local([i.latitude_deg for i in positioned],
                                  [i.longitude_deg for i in positioned])


@pytest.mark.parametrize("return_mode", ["rtl", "land", "none"])
@pytest.mark.parametrize("autopilot", ["ardupilot", "px4"])
def test_mission_structure_targets_and_tolerance(return_mode, autopilot):
    mission = make_mission(40, return_mode=return_mode, autopilot=autopilot, airspeed_m_s=20.0,
                           max_items=5000)
    items = mission.items
    path = mission.path
    # The flight path is one C1 chain within the turn radius through every target.
    report = check_path(path.chain, mission.rho_m, mission.tour.targets_m, path.target_s_m,
                        closed=False)
    assert report.ok, report.problems
    assert items[0].command == Command.NAV_TAKEOFF and items[0].altitude_m == 100.0
    assert items[1].command == Command.DO_CHANGE_SPEED and items[1].params[1] == 20.0
    # Every target is exactly one waypoint, at its own coordinates, in the order flown.
    targets = [k for k, item in enumerate(items) if item.role == "target"]
    assert sorted(items[k].target for k in targets) == list(range(40))
    flown = [items[k].target for k in targets]
    assert flown == list(np.argsort(path.target_s_m))
    local = mission.frame.to_local([items[k].latitude_deg for k in targets],
                                   [items[k].longitude_deg for k in targets])
    assert np.max(np.hypot(*(local - mission.tour.targets_m[flown]).T)) < 1e-6
    assert all(items[k].command == Command.NAV_WAYPOINT and items[k].params[1] == 5.0
               for k in targets)
    # Every point of the exact path is within the tolerance of the waypoint polyline.
    dense = path.chain.sample(0.5)[:, :2]
    assert np.max(polyline_distance_m(dense, item_polyline(mission))) <= mission.tolerance_m + 1e-6
    last_target = targets[-1]
    if return_mode == "rtl":
        assert items[-1].command == Command.NAV_RETURN_TO_LAUNCH and last_target == len(items) - 2
    elif return_mode == "none":
        assert last_target == len(items) - 1
    else:
        assert items[last_target + 1].command == Command.DO_LAND_START
        assert items[-1].command == Command.NAV_LAND and items[-1].altitude_m == 0.0
        assert (items[-1].latitude_deg, items[-1].longitude_deg) == (mission.home.latitude_deg,
                                                                     mission.home.longitude_deg)
        assert items[-2].role == "approach" and items[-2].altitude_m == approach(100.0)[0]
        # Lined up with the landing direction at the approach point.
        end = path.chain.ends()[-1]
        home = mission.frame.to_local(mission.home.latitude_deg, mission.home.longitude_deg)[0]
        assert np.hypot(*(end[:2] + approach(100.0)[1] * np.array([math.cos(end[2]), math.sin(end[2])])
                          - home)) < 1e-6
    assert mission.vehicle_item_count() == len(items) + (autopilot == "ardupilot")


def test_launch_and_landing_bearings_are_honoured():
    mission = make_mission(20, return_mode="land", launch_bearing_deg=270.0,
                           landing_bearing_deg=45.0, max_items=5000)
    chain = mission.path.chain
    assert heading_to_bearing_deg(chain.starts[0, 2]) == pytest.approx(270.0)
    assert heading_to_bearing_deg(chain.ends()[-1, 2]) == pytest.approx(45.0)


def test_item_budget_coarsens_then_refuses_with_the_count_needed():
    generous = make_mission(60, max_items=5000)
    assert generous.tolerance_m == pytest.approx(0.25 * 0.02 * 80)
    budget = int(0.85 * generous.vehicle_item_count())
    tight = make_mission(60, max_items=budget)
    assert tight.vehicle_item_count() <= budget
    assert generous.tolerance_m < tight.tolerance_m <= 0.02 * 80
    assert any("coarsened" in note for note in tight.notes)
    with pytest.raises(InputError, match=r"needs \d+ items .* holds 50 \(`max_items`\)"):
        make_mission(60, max_items=50)


def test_target_altitudes_are_used_and_interpolated_between():
    altitudes = np.linspace(60.0, 150.0, 30)
    mission = make_mission(30, altitudes=altitudes, max_items=5000)
    for item in mission.items:
        if item.role == "target":
            assert item.altitude_m == altitudes[item.target]
    path_altitudes = [i.altitude_m for i in mission.items if i.role == "path"]
    assert 60.0 <= min(path_altitudes) and max(path_altitudes) <= 150.0


def test_same_input_same_mission():
    assert make_mission(50, seed=3).items == make_mission(50, seed=3).items


def test_px4_defaults_to_a_landing_and_warns_about_rtl():
    assert make_mission(10, autopilot="px4", max_items=5000).items[-1].command == Command.NAV_LAND
    rtl = make_mission(10, autopilot="px4", return_mode="rtl", max_items=5000)
    assert any("MIS_TKO_LAND_REQ" in note for note in rtl.notes)
    assert not any(i.command == Command.NAV_LOITER_TURNS for i in rtl.items)


def test_px4_says_when_it_will_fly_slower_than_asked():
    from dataclasses import replace
    from dtsp_mission.autopilot.parameters import PX4_DEFAULTS

    def notes(asked: float, **vehicle) -> list[str]:
        mission = make_mission(8, autopilot="px4", airspeed_m_s=asked, max_items=5000,
                               vehicle=replace(PX4_DEFAULTS, **vehicle), design="geometry")
        return [note for note in mission.notes if "PX4 will fly" in note]

    # the SIH plane's own top speed (13.9 m/s true, 15 m/s as asked) binds below FW_AIRSPD_MAX
    assert notes(18.0) == ["asked 18 m/s, PX4 will fly 15.0 m/s (PX4 SITL's SIH plane flies no "
                           "faster than 13.9 m/s true airspeed): the mission is designed for the "
                           "speed it flies"]
    assert notes(15.0) == []
    # a lower FW_AIRSPD_MAX binds first
    assert notes(16.0, FW_AIRSPD_MAX=14.0) == [
        "asked 16 m/s, PX4 will fly 14.0 m/s (its FW_AIRSPD_MAX (14 m/s)): the mission is "
        "designed for the speed it flies"]


@settings(max_examples=30)
@given(count=st.integers(2, 12), seed=st.integers(0, 10_000), rho=st.sampled_from([20.0, 80.0, 300.0]),
       span=st.sampled_from([1.0, 100.0, 2000.0]), tolerance_fraction=st.sampled_from([0.005, 0.02, 0.2]))
def test_any_small_instance_gives_a_valid_flight_path_and_items(count, seed, rho, span,
                                                                tolerance_fraction):
    mission = make_mission(count, seed=seed, rho_m=rho, span_m=span,
                           tolerance_m=tolerance_fraction * rho, max_items=65_535)
    path = mission.path
    assert check_path(path.chain, rho, mission.tour.targets_m, path.target_s_m, closed=False).ok
    chosen = waypoint_s(path.chain, rho, path.target_s_m, mission.tolerance_m)
    assert deviation_m(path.chain, chosen, rho / 50) <= mission.tolerance_m * (1 + 1e-9)
    assert sum(i.role == "target" for i in mission.items) == count
