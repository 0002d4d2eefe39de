"""Wire items: ArduPilot's home placeholder, normalisation, and the plan/vehicle comparison."""

from __future__ import annotations

import pytest

from dtsp_mission.export import exporter_for
from dtsp_mission.mission import Autopilot, Command, Frame
from dtsp_mission.autopilot.wire import WireItem, describe_vehicle, differences, from_wire, to_wire
from conftest import make_mission


@pytest.fixture(scope="module")
def mission():
    return make_mission(12, 3, 80.0, span_m=1500.0, airspeed_m_s=20.0)


def test_ardupilot_gets_home_at_seq_0_and_px4_does_not():
    ardupilot = make_mission(8, 1, 80.0, span_m=1000.0).for_vehicle()
    px4 = make_mission(8, 1, 80.0, span_m=1000.0, autopilot="px4").for_vehicle()
    wire = to_wire(ardupilot)
    assert len(wire) == len(ardupilot.items) + 1
    assert (wire[0].frame, wire[0].command) == (Frame.GLOBAL, Command.NAV_WAYPOINT)
    assert wire[0].x == round(ardupilot.home.latitude_deg * 1e7)
    assert wire[1].command == Command.NAV_TAKEOFF
    assert [w.seq for w in wire] == list(range(len(wire)))
    assert [w.current for w in wire] == [1] + [0] * (len(wire) - 1)
    px4_wire = to_wire(px4)
    assert len(px4_wire) == len(px4.items) and px4_wire[0].command == Command.NAV_TAKEOFF


def test_wire_values_are_what_mission_item_int_carries(mission):
    for item, wire in zip(mission.items, to_wire(mission.for_vehicle())[1:]):
        if item.has_position:
            assert abs(wire.x / 1e7 - item.latitude_deg) <= 0.5e-7
            assert abs(wire.y / 1e7 - item.longitude_deg) <= 0.5e-7
        assert abs(wire.z - item.altitude_m) <= 1e-5 * max(1.0, abs(item.altitude_m))
    back = from_wire(to_wire(mission.for_vehicle()), Autopilot.ARDUPILOTMEGA)
    assert [i.command for i in back] == [i.command for i in mission.items]


def test_differences_find_every_change_and_ignore_the_home_slot(mission):
    wire = to_wire(mission.for_vehicle())
    assert differences(wire, list(wire), Autopilot.ARDUPILOTMEGA) == []
    vehicle_home = WireItem(**{**wire[0].__dict__, "x": wire[0].x + 5000, "z": 431.0})
    assert differences(wire, [vehicle_home] + wire[1:], Autopilot.ARDUPILOTMEGA) == []
    moved = WireItem(**{**wire[5].__dict__, "y": wire[5].y + 1})
    problems = differences(wire, wire[:5] + [moved] + wire[6:], Autopilot.ARDUPILOTMEGA)
    assert len(problems) == 1 and "item 5" in problems[0] and "y" in problems[0]
    assert "holds 7 items" in differences(wire, wire[:7], Autopilot.ARDUPILOTMEGA)[0]
    assert describe_vehicle(wire[:1], wire, Autopilot.ARDUPILOTMEGA) == "the vehicle holds no mission now"
    real = len(wire) - 1
    assert describe_vehicle(wire[:7], wire, Autopilot.ARDUPILOTMEGA).startswith(
        f"the vehicle holds the first 6 of the {real} items of this mission: do not fly it")
    # ArduPilot after a broken upload over a longer old mission: new items first, old ones after
    old = [WireItem(**{**item.__dict__, "z": item.z + 7.0}) for item in wire]
    assert f"the first 6 of the {real} items of this mission, followed by {real - 6} items left " \
        "from its earlier mission" in describe_vehicle(wire[:7] + old[7:], wire, Autopilot.ARDUPILOTMEGA)
    assert "shares nothing with this one (its earlier mission" in \
        describe_vehicle(old[:9], wire, Autopilot.ARDUPILOTMEGA)
    assert "unknown" in describe_vehicle(None, wire, Autopilot.ARDUPILOTMEGA)


@pytest.mark.parametrize("suffix", [".plan", ".waypoints"])
def test_mission_files_read_back_to_the_same_wire_items(mission, tmp_path, suffix):
    path = tmp_path / f"m{suffix}"
    exporter = exporter_for(path)
    exporter.write(mission, path)
    again = exporter.read(path)
    assert again.autopilot == mission.autopilot
    assert differences(to_wire(mission.for_vehicle()), to_wire(again), mission.autopilot) == []
