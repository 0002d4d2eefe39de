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
    assert "--autopilot px4" in str(caught.value)
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


def test_a_px4_plan_is_refused_by_an_ardupilot_vehicle(start_vehicle):
    px4 = make_mission(6, 5, 80.0, span_m=1000.0, autopilot="px4").for_vehicle()
    vehicle = start_vehicle(px4, autopilot=Autopilot.ARDUPILOTMEGA)
    with pytest.raises(LinkError) as caught:
        upload_mission(px4, f"udpout:127.0.0.1:{vehicle.port}")
    assert "made for PX4, but the vehicle runs ArduPilot" in str(caught.value)
    assert "--autopilot ardupilot" in str(caught.value)
    assert vehicle.uploads == 0
