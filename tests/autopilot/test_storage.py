"""The storage model against a real ArduPlane: every read-back of the recorded SITL data set.

``tests/data/arduplane-sitl`` is the recorded data set (``../shared/arduplane-sitl``): per case
the uploaded ``mission.plan`` and the ``readback.json`` the vehicle returned; ``facts_probe.json``
holds a probe mission of unusual items and what came back.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from dtsp_mission.autopilot import Autopilot, WireItem, capacity, stored_item
from dtsp_mission.export import read_mission
from dtsp_mission.autopilot.wire import describe_vehicle, differences, to_wire

DATA = Path(__file__).resolve().parents[1] / "data" / "arduplane-sitl"
CASES = sorted(p.name for p in DATA.iterdir() if (p / "readback.json").exists())
ARDUPILOT = Autopilot.ARDUPILOTMEGA


def readback(case: str) -> list[WireItem]:
    keys = ("seq", "frame", "command", "current", "autocontinue", "param1", "param2", "param3",
            "param4", "x", "y", "z", "mission_type")
    return [WireItem(**{k: item[k] for k in keys})
            for item in json.loads((DATA / case / "readback.json").read_text())]


def test_the_data_set_is_all_there():
    assert len(CASES) == 9


@pytest.mark.parametrize("case", CASES)
def test_the_stored_form_of_every_planned_item_is_what_arduplane_returned(case):
    planned = to_wire(read_mission(DATA / case / "mission.plan"))
    returned = readback(case)
    assert len(planned) == len(returned)
    for sent, got in zip(planned[1:], returned[1:]):          # seq 0 is the vehicle's own home
        assert replace(stored_item(sent, ARDUPILOT), current=0) == got


@pytest.mark.parametrize("case", CASES)
def test_the_upload_check_passes_every_real_readback(case):
    planned = to_wire(read_mission(DATA / case / "mission.plan"))
    returned = readback(case)
    assert differences(planned, returned, ARDUPILOT) == []
    assert describe_vehicle(returned, planned, ARDUPILOT) == "the vehicle holds exactly the planned mission"


@pytest.mark.parametrize("change, field", [
    (dict(x=1), "x"),                 # 1e-7 degree: beyond no storage resolution
    (dict(command=17), "command"),
    (dict(z=0.02), "z"),              # 2 cm: the vehicle keeps centimetres
    (dict(param2=1.0), "param2"),     # an acceptance radius off by one metre
])
def test_a_real_difference_in_a_readback_still_fails(change, field):
    case = "dtsp_u40"
    planned = to_wire(read_mission(DATA / case / "mission.plan"))
    returned = readback(case)
    victim = returned[5]
    returned[5] = replace(victim, **{k: getattr(victim, k) + v for k, v in change.items()})
    problems = differences(planned, returned, ARDUPILOT)
    assert len(problems) == 1 and problems[0].startswith("item 5 differs in " + field)
    assert "do not fly it" in describe_vehicle(returned, planned, ARDUPILOT)


def test_a_missing_item_fails():
    planned = to_wire(read_mission(DATA / "square" / "mission.plan"))
    returned = readback("square")[:-1]
    assert any("holds 5 items" in p for p in differences(planned, returned, ARDUPILOT))


def test_the_probe_of_unusual_items_comes_back_as_modelled():
    probe = json.loads((DATA / "facts_probe.json").read_text())["normalisation"]
    keys = ("seq", "frame", "command", "current", "autocontinue", "param1", "param2", "param3",
            "param4", "x", "y", "z", "mission_type")
    for sent, got in zip(probe["sent"][1:], probe["readback"][1:]):
        p = sent["params"]
        wire = WireItem.normalised(sent["seq"], sent["frame"], sent["command"], 0, 1, *p[:4],
                                   round(p[4] * 1e7), round(p[5] * 1e7), p[6])
        assert stored_item(wire, ARDUPILOT) == WireItem(**{k: got[k] for k in keys}), sent


def test_capacity_is_the_stock_vehicles():
    probe = json.loads((DATA / "facts_probe.json").read_text())
    assert probe["656"]["ack_name"] == "MAV_MISSION_NO_SPACE" and probe["655"]["ack_type"] == 0
    assert capacity(ARDUPILOT) == 655
    assert capacity(Autopilot.PX4) == 500


@pytest.mark.parametrize("z", [118.9, 113.4, 109.01, 77.19, 123.456])
def test_a_stored_altitude_is_not_truncated_twice_by_the_check(z):
    sent = WireItem.normalised(5, 3, 16, 0, 1, 0, 0, 0, 0, 473977000, 85456000, z)
    kept = stored_item(sent, ARDUPILOT)
    assert abs(kept.z - z) < 0.01 and kept.z <= z + 1e-6        # centimetres, truncated
    planned = [sent] * 2
    assert differences(planned, [kept] * 2, ARDUPILOT) == []
    assert differences(planned, [replace(kept, z=kept.z - 0.01)] * 2, ARDUPILOT) != []
