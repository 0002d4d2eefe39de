"""The readers of every input file under mutation (issue 31): CSV and GeoJSON targets, QGC
``.plan`` and ``.waypoints`` missions, ``.parm`` vehicle parameters.

Each valid file is changed the ways a hand, an editor or another tool changes files -- a value
swapped for a hostile one (NaN, infinities, 999, an empty field, a string, a list, a quote, a
NUL), a key or line dropped or doubled, the text cut short -- and read.  A reader must give a
result that the rest of the pipeline can use (a mission's every item packs into a MAVLink
MISSION_ITEM_INT) or raise a :class:`~dtsp_mission.errors.DtspError` (exit 2 with its one-line
message from the CLI): never another exception, which the CLI would print as a traceback.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pymavlink.dialects.v20 import common as mavlink

from conftest import make_mission
from dtsp_mission.autopilot.parameters import read_parameters
from dtsp_mission.errors import DtspError
from dtsp_mission.export import exporter_for, read_mission
from dtsp_mission.targets import read_targets
from dtsp_mission.autopilot.wire import to_wire

ROOT = Path(__file__).resolve().parents[2]
TEXT_VALUES = ["", "nan", "NaN", "inf", "-inf", "1e309", "-1", "0", "999", "-999", "1e-320",
               "true", "null", "x", '"', ",", "\t", " ", "é", "\x00", "1,2", "46.8.1", "0x10"]
JSON_VALUES = [None, True, False, "x", "", [], {}, [1, 2], float("nan"), float("inf"), -1, 0,
               999, -999, 1e308, 2 ** 40, "46.8", [6.95, 46.8, 500]]
FUZZ = settings(max_examples=80, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                        HealthCheck.too_slow])


def _packs(mission) -> None:
    """Every item of ``mission`` encodes as MISSION_ITEM_INT (what an upload sends)."""
    encoder = mavlink.MAVLink(None, srcSystem=255, srcComponent=190)
    for item in to_wire(mission):
        mavlink.MAVLink_mission_item_int_message(
            1, 1, item.seq, item.frame, item.command, item.current, item.autocontinue,
            item.param1, item.param2, item.param3, item.param4, item.x, item.y, item.z,
            item.mission_type).pack(encoder)


def _read_or_refuse(reader, path: Path) -> None:
    try:
        result = reader(path)
    except DtspError as error:
        assert str(error).strip() and "\n" not in str(error).strip(), repr(str(error))
        return
    if hasattr(result, "items") and hasattr(result, "home"):
        _packs(result)


@st.composite
def text_mutations(draw, text: str) -> str:
    """``text`` with a few of its fields or lines changed, dropped, doubled, or cut."""
    lines = text.splitlines(keepends=True)
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["field", "field", "drop", "double", "cut"]))
        k = draw(st.integers(0, len(lines) - 1))
        if kind == "field":
            separator = "\t" if "\t" in lines[k] else ("," if "," in lines[k] else " ")
            fields = lines[k].rstrip("\n").split(separator)
            fields[draw(st.integers(0, len(fields) - 1))] = draw(st.sampled_from(TEXT_VALUES))
            lines[k] = separator.join(fields) + "\n"
        elif kind == "drop" and len(lines) > 1:
            del lines[k]
        elif kind == "double":
            lines.insert(k, lines[k])
        elif kind == "cut":
            lines[k] = lines[k][:draw(st.integers(0, len(lines[k])))]
    return "".join(lines)


def _paths(document, prefix=()):
    """Every (container, key) path in a JSON document."""
    if isinstance(document, dict):
        for key, value in document.items():
            yield prefix + (key,)
            yield from _paths(value, prefix + (key,))
    elif isinstance(document, list):
        for index, value in enumerate(document):
            yield prefix + (index,)
            yield from _paths(value, prefix + (index,))


@st.composite
def json_mutations(draw, document) -> str:
    """``document`` with one to three values replaced by hostile ones, or keys dropped."""
    changed = copy.deepcopy(document)
    for _ in range(draw(st.integers(1, 3))):
        paths = list(_paths(changed))
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = changed
        for key in path[:-1]:
            parent = parent[key]
        if draw(st.booleans()) and isinstance(parent, dict):
            del parent[path[-1]]
        else:
            parent[path[-1]] = copy.deepcopy(draw(st.sampled_from(JSON_VALUES)))
    return json.dumps(changed)


_MISSION_FILES: dict[str, str] = {}


def mission_file(suffix: str, folder: Path) -> str:
    """The text of a small planned mission in the format of ``suffix`` (made once)."""
    if suffix not in _MISSION_FILES:
        mission = make_mission(5, 3, 80.0, span_m=1200.0, airspeed_m_s=20.0)
        exporter_for(folder / f"base{suffix}").write(mission, folder / f"base{suffix}")
        _MISSION_FILES[suffix] = (folder / f"base{suffix}").read_text()
    return _MISSION_FILES[suffix]


CSV = "".join(ROOT.joinpath("examples", "site-inspection.csv").read_text().splitlines(True)[:6])
PARM = "NAVL1_PERIOD 17\nNAVL1_DAMPING 0.75\nROLL_LIMIT_DEG 45\nAIRSPEED_CRUISE 22\nWP_RADIUS 90\n"
GEOJSON = {"type": "FeatureCollection", "features": [
    {"type": "Feature", "properties": {"name": f"t{k}", "alt": 90, "photo": k % 2 == 0},
     "geometry": {"type": "Point", "coordinates": [6.95 + k / 300, 46.8 + k / 500]}}
    for k in range(3)] + [{"type": "Feature", "properties": {}, "geometry": {
        "type": "Polygon", "coordinates": [[[6.94, 46.79], [6.97, 46.79], [6.97, 46.81],
                                            [6.94, 46.79]]]}}]}


@FUZZ
@given(data=st.data())
def test_a_mutated_targets_csv_is_read_or_refused(tmp_path, data):
    path = tmp_path / "t.csv"
    path.write_text(data.draw(text_mutations(CSV)), encoding="utf-8", errors="surrogateescape")
    _read_or_refuse(read_targets, path)


@FUZZ
@given(data=st.data())
def test_a_mutated_targets_geojson_is_read_or_refused(tmp_path, data):
    path = tmp_path / "t.geojson"
    path.write_text(data.draw(json_mutations(GEOJSON)))
    _read_or_refuse(read_targets, path)


@FUZZ
@given(data=st.data())
def test_a_mutated_parm_file_is_read_or_refused(tmp_path, data):
    path = tmp_path / "v.parm"
    path.write_text(data.draw(text_mutations(PARM)))
    _read_or_refuse(read_parameters, path)


@FUZZ
@given(data=st.data())
def test_a_mutated_plan_is_read_or_refused(tmp_path, data):
    path = tmp_path / "m.plan"
    path.write_text(data.draw(json_mutations(json.loads(mission_file(".plan", tmp_path)))))
    _read_or_refuse(read_mission, path)


@FUZZ
@given(data=st.data())
def test_a_mutated_waypoints_file_is_read_or_refused(tmp_path, data):
    path = tmp_path / "m.waypoints"
    path.write_text(data.draw(text_mutations(mission_file(".waypoints", tmp_path))))
    _read_or_refuse(read_mission, path)


#: A .plan as QGroundControl (4.x) saves it (tests/data/qgroundcontrol-4.plan): every simple item
#: with AltitudeMode, Altitude and AMSLAltAboveTerrain (null but in the terrain mode), a yaw of
#: null, a terrain-mode item in frame GLOBAL (AMSL) beside relative ones.
QGC_PLAN = json.loads((ROOT / "tests" / "data" / "qgroundcontrol-4.plan").read_text())


def test_a_plan_as_qgroundcontrol_saves_it_is_read(tmp_path):
    path = tmp_path / "qgc.plan"
    path.write_text(json.dumps(QGC_PLAN, indent=4))
    mission = read_mission(path)
    assert [int(i.command) for i in mission.items] == [22, 16, 16, 178, 20]
    assert mission.height_above_home_m(mission.items[2]) == 537.9 - 487.9
    _packs(mission)


@FUZZ
@given(data=st.data())
def test_a_mutated_qgroundcontrol_plan_is_read_or_refused(tmp_path, data):
    path = tmp_path / "qgc.plan"
    path.write_text(data.draw(json_mutations(QGC_PLAN)))
    _read_or_refuse(read_mission, path)
