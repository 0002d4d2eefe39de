"""The storage model against a real PX4 (v1.16.0 SITL, stock fixed wing): every read-back of the
recorded data set and the probe of unusual items.

``tests/data/px4-sitl`` is the recorded data set (``../shared/px4-sitl``): per case the uploaded
``mission.plan`` and the ``readback.json`` PX4 returned; ``storage_probe.json`` holds a probe
mission of unusual items, what came back, and the answer to each item sent alone.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from dtsp_mission.autopilot import Autopilot, WireItem, stored_item
from dtsp_mission.autopilot.storage import ACCEPTED, UNSUPPORTED, MissionStore
from dtsp_mission.export import read_mission
from dtsp_mission.autopilot.wire import describe_vehicle, differences, to_wire

DATA = Path(__file__).resolve().parents[1] / "data" / "px4-sitl"
CASES = sorted(p.name for p in DATA.iterdir() if (p / "readback.json").exists())
PX4 = Autopilot.PX4
KEYS = ("seq", "frame", "command", "current", "autocontinue", "param1", "param2", "param3",
        "param4", "x", "y", "z", "mission_type")


def planned_wire(case: str) -> list[WireItem]:
    """The plan as uploaded to PX4: in plan order, no home slot (the calibration cases are
    ArduPlane plans, sent to PX4 as they are)."""
    return to_wire(replace(read_mission(DATA / case / "mission.plan"), autopilot=PX4))


def readback(case: str) -> list[WireItem]:
    return [WireItem.normalised(**{k: item[k] for k in KEYS})
            for item in json.loads((DATA / case / "readback.json").read_text())]


def test_the_data_set_is_all_there():
    assert CASES == ["circle_t10", "circle_t2", "dtsp_dense60", "geometry_u60", "square", "zigzag"]


def _same(a: WireItem, b: WireItem) -> bool:
    """Field for field, NaN equal to NaN (PX4 hands NaN yaw back as NaN)."""
    return all(x == y or (x != x and y != y) for x, y in zip(a.__dict__.values(), b.__dict__.values()))


@pytest.mark.parametrize("case", CASES)
def test_the_stored_form_of_every_planned_item_is_what_px4_returned(case):
    planned = planned_wire(case)
    returned = readback(case)
    assert len(planned) == len(returned)
    for sent, got in zip(planned, returned):
        assert _same(replace(stored_item(sent, PX4), current=0), replace(got, current=0)), (sent, got)


@pytest.mark.parametrize("case", CASES + ["t12"])
def test_the_upload_check_passes_what_px4_holds(case):
    """No false alarm: the recorded read-backs, and for ``t12`` (whose upload raised one on
    the real PX4: ``upload_stdout.txt``) the plan as PX4 stores it."""
    planned = planned_wire(case)
    returned = (readback(case) if case != "t12" else
                [stored_item(item, PX4) for item in planned])
    assert differences(planned, returned, PX4) == []
    assert describe_vehicle(returned, planned, PX4) == "the vehicle holds exactly the planned mission"


def test_a_real_difference_in_a_px4_readback_still_fails():
    planned = planned_wire("square")
    returned = readback("square")
    returned[2] = replace(returned[2], x=returned[2].x + 1)
    problems = differences(planned, returned, PX4)
    assert len(problems) == 1 and problems[0].startswith("item 2 differs in x")


def _probe():
    return json.loads((DATA / "storage_probe.json").read_text())


def test_the_probe_of_unusual_items_comes_back_as_modelled():
    probe = _probe()
    for sent, got in zip(probe["sent"], probe["returned"]):
        wire = WireItem.normalised(**{k: sent.get(k, 0 if k != "autocontinue" else 1) for k in KEYS})
        expected = WireItem.normalised(**{k: got[k] for k in KEYS})
        assert _same(replace(stored_item(wire, PX4), current=0), replace(expected, current=0)), sent


def test_the_simulated_px4_answers_each_probe_item_as_px4_did():
    probe = _probe()
    frames = {str(item["command"]): item["frame"] for item in probe["sent"]}
    for command, answer in probe["single_item_acks"].items():
        store = MissionStore(PX4)
        assert store.begin(1) == ACCEPTED
        item = WireItem.normalised(0, frames.get(command, 3), int(command), 0, 1, 0, 0, 0, 0,
                                   473977400, 85455900, 60.0)
        assert store.write(item) == answer, command


def test_a_command_without_a_position_in_a_global_frame_is_refused_by_px4():
    store = MissionStore(PX4)
    store.begin(1)
    speed = WireItem.normalised(0, 0, 178, 0, 1, 0, 18.5, -1, 0, 0, 0, 0)
    assert store.write(speed) == UNSUPPORTED
