"""Checks before an upload, against the simulated vehicle over loopback UDP: the other
autopilot refused, navigation parameters that differ and a far home warned about."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conftest import make_mission
from dtsp_mission.autopilot import Autopilot
from dtsp_mission.autopilot.parameters import ARDUPLANE_DEFAULTS, read_parameters
from dtsp_mission.errors import LinkError
from dtsp_mission.mission.model import Home
from dtsp_mission.upload import upload_mission


@pytest.fixture(scope="module")
def mission():
    return make_mission(8, 4, 80.0, span_m=1200.0, airspeed_m_s=22.0).for_vehicle()


def test_a_stock_vehicle_gives_no_warning(mission, start_vehicle):
    vehicle = start_vehicle(mission)
    report = upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
    assert report.verified and report.warnings == ()


def test_a_plan_for_the_other_autopilot_is_refused_before_anything_is_sent(mission, start_vehicle):
    vehicle = start_vehicle(mission, autopilot=Autopilot.PX4)
    with pytest.raises(LinkError) as caught:
        upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
    assert "made for ArduPilot, but the vehicle runs PX4" in str(caught.value)
    assert "`autopilot` px4" in str(caught.value)
    assert vehicle.uploads == 0 and vehicle.mission == []


def test_each_differing_navigation_parameter_is_named(mission, start_vehicle):
    tuned = replace(ARDUPLANE_DEFAULTS, NAVL1_PERIOD=17.0, WP_RADIUS=90.0)
    vehicle = start_vehicle(mission, parameters=tuned)
    report = upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
    assert report.verified
    assert len(report.warnings) == 2
    assert any("NAVL1_PERIOD is 17, the mission was designed for 15" in w for w in report.warnings)
    assert any("WP_RADIUS is 90" in w for w in report.warnings)
    # designed for the vehicle's own values: nothing to say
    again = upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}", designed_for=tuned)
    assert again.warnings == ()


def test_a_home_far_from_the_vehicles_is_warned_about(mission, start_vehicle):
    far = Home(mission.home.latitude_deg + 0.05, mission.home.longitude_deg, 0.0)
    vehicle = start_vehicle(replace(mission, home=far))
    report = upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
    assert any("km from the vehicle's home" in w and "5.6 km" in w for w in report.warnings)


def test_a_parameter_file_as_ardupilot_writes_it(tmp_path):
    path = tmp_path / "vehicle.parm"
    path.write_text("# saved by MAVProxy\nNAVL1_PERIOD 18\nWP_RADIUS,60\nSOMETHING_ELSE 3\n")
    parameters = read_parameters(path)
    assert parameters.NAVL1_PERIOD == 18.0 and parameters.WP_RADIUS == 60.0
    assert parameters.ROLL_LIMIT_DEG == ARDUPLANE_DEFAULTS.ROLL_LIMIT_DEG


def test_a_parameter_file_as_qgroundcontrol_saves_it(tmp_path):
    """QGroundControl's saved .params (vehicle, component, name, value, type; tab-separated)
    reads as a .parm does, for ArduPilot's and PX4's names."""
    from dtsp_mission.autopilot.parameters import PX4_DEFAULTS, read_px4_parameters
    path = tmp_path / "vehicle.params"
    path.write_text("# Onboard parameters for Vehicle 1\n#\n# Stack: PX4 Pro\n#\n"
                    "# Vehicle-Id Component-Id Name Value Type\n"
                    "1\t1\tNPFG_PERIOD\t14.000000000000000000\t9\n"
                    "1\t1\tNAV_ACC_RAD\t25.000000000000000000\t9\n"
                    "1\t1\tNAVL1_PERIOD\t18.000000000000000000\t9\n"
                    "1\t1\tSYS_AUTOSTART\t10041\t6\n")
    px4 = read_px4_parameters(path)
    assert (px4.NPFG_PERIOD, px4.NAV_ACC_RAD, px4.FW_R_LIM) == (14.0, 25.0, PX4_DEFAULTS.FW_R_LIM)
    assert read_parameters(path).NAVL1_PERIOD == 18.0


def test_a_px4_vehicles_navigation_parameters_are_compared_by_px4s_names(start_vehicle):
    """A PX4 is asked for its own parameters (NPFG_*, NAV_ACC_RAD, FW_*): the simulated one
    answers as PX4 does; a tuned one is named, one tuned as designed for is not."""
    from dtsp_mission.autopilot.parameters import PX4_DEFAULTS
    px4 = make_mission(6, 5, 80.0, span_m=1000.0, autopilot="px4").for_vehicle()
    vehicle = start_vehicle(px4, autopilot=Autopilot.PX4)
    assert upload_mission(px4, f"udpout:127.0.0.1:{vehicle.port}").warnings == ()
    tuned = replace(PX4_DEFAULTS, NPFG_PERIOD=14.0)
    vehicle = start_vehicle(px4, autopilot=Autopilot.PX4, parameters=tuned)
    report = upload_mission(px4, f"udpout:127.0.0.1:{vehicle.port}")
    assert report.verified and report.warnings == (
        "the vehicle's NPFG_PERIOD is 14, the mission was designed for 10: it will fly "
        "differently than predicted",)
    again = upload_mission(px4, f"udpout:127.0.0.1:{vehicle.port}", designed_for=tuned)
    assert again.warnings == ()


def test_a_px4_plan_is_refused_by_an_ardupilot_vehicle(start_vehicle):
    px4 = make_mission(6, 5, 80.0, span_m=1000.0, autopilot="px4").for_vehicle()
    vehicle = start_vehicle(px4, autopilot=Autopilot.ARDUPILOTMEGA)
    with pytest.raises(LinkError) as caught:
        upload_mission(px4, f"udpout:127.0.0.1:{vehicle.port}")
    assert "made for PX4, but the vehicle runs ArduPilot" in str(caught.value)
    assert "`autopilot` ardupilot" in str(caught.value)
    assert vehicle.uploads == 0


def test_a_vehicle_whose_wind_estimate_differs_from_the_design_wind_is_warned_about(mission, start_vehicle):
    """ArduPilot streams its wind estimate (WIND); an upload of a mission designed for another
    wind says so, naming both, and says nothing when they agree within 2 m/s and 30 deg."""
    from dtsp_mission.autopilot.navigation import Wind
    vehicle = start_vehicle(mission, wind=Wind(8.0, 40.0))
    calm = replace(mission, design_wind=(0.0, 0.0))
    report = upload_mission(calm, f"udpout:127.0.0.1:{vehicle.port}")
    assert report.verified
    assert [w for w in report.warnings if "wind" in w] == [
        "the vehicle estimates a wind of 8.0 m/s from 40 deg; the mission was designed for "
        "0 m/s from 0 deg: it will fly differently than predicted (plan again with `wind` as the vehicle estimates it)"]
    close = replace(mission, design_wind=(7.0, 55.0))
    assert not [w for w in upload_mission(close, f"udpout:127.0.0.1:{vehicle.port}").warnings
                if "wind" in w]


def test_the_plan_file_carries_the_design_wind(tmp_path):
    """The .plan records the wind a guidance design was made for, and reading it back gives
    the uploader that wind to compare with the vehicle's."""
    import numpy as np
    from dtsp_mission.api import plan_tour
    from dtsp_mission.autopilot.navigation import Wind
    from dtsp_mission.export import exporter_for, read_mission
    from dtsp_mission.frame import LocalFrame
    from dtsp_mission.mission import MissionSettings, build_mission
    from dtsp_mission.targets.model import local_targets
    points = np.random.default_rng(4).uniform(-800, 800, (8, 2))
    targets = local_targets(points).to_geodetic(LocalFrame(46.8, 6.95))
    tour, frame = plan_tour(targets, 80.0)
    designed = build_mission(tour, frame, targets, MissionSettings(
        design="guidance", airspeed_m_s=22.0, wind=Wind(6.0, 250.0), wind_spread_m_s=0.0))
    path = tmp_path / "w.plan"
    path.write_text(exporter_for(path).render(designed))
    assert read_mission(path).design_wind == (6.0, 250.0)
    assert designed.for_vehicle().design_wind == (6.0, 250.0)


def test_a_vehicle_that_is_no_fixed_wing_is_refused_before_anything_is_sent(mission, start_vehicle):
    vehicle = start_vehicle(mission, mav_type=2)            # MAV_TYPE_QUADROTOR
    with pytest.raises(LinkError) as caught:
        upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
    assert "the vehicle is a quadrotor (MAV_TYPE 2" in str(caught.value)
    assert "nothing was sent" in str(caught.value)
    assert vehicle.uploads == 0
    # a VTOL flies fixed-wing missions
    vtol = start_vehicle(mission, mav_type=22)
    assert upload_mission(mission, f"udpout:127.0.0.1:{vtol.port}").verified


def test_a_file_without_its_autopilot_sent_to_ardupilot_says_so(mission, start_vehicle):
    unstated = replace(mission, autopilot_stated=False)
    vehicle = start_vehicle(mission)
    report = upload_mission(unstated, f"udpout:127.0.0.1:{vehicle.port}")
    assert report.verified
    assert any("does not say its autopilot" in w and "sent as an ArduPilot mission" in w
               for w in report.warnings)
