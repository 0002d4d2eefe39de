"""Every written file is read back by the real readers: MAVSDK's QGroundControl and Mission
Planner importers, pymavlink's MAVWPLoader, json/jsonschema, and our tour reader."""

import json

import numpy as np
import pytest
from pymavlink import mavwp

from conftest import make_mission
from dtsp_mission.errors import InputError
from dtsp_mission.export import exporter_for, exporters
from dtsp_mission.export.qgc_plan import plan_dict, plan_rule_violations
from dtsp_mission.mission import Command, degrees_to_e7
from dtsp_mission.tour import read_tour
from dtsp_mission.tour.json_form import origin_from_dict


@pytest.fixture(scope="module", params=["ardupilot", "px4"])
def mission(request):
    return make_mission(30, autopilot=request.param, airspeed_m_s=21.0, max_items=5000,
                        home_deg=(46.801, 6.949), home_altitude_amsl_m=452.0)


def assert_item_matches(imported, item, seq):
    assert imported.seq == seq
    assert (imported.command, imported.frame) == (int(item.command), int(item.frame))
    assert imported.autocontinue == int(item.autocontinue)
    for k, value in enumerate(item.params, start=1):
        assert getattr(imported, f"param{k}") == pytest.approx(value, abs=1e-6)
    assert imported.x == degrees_to_e7(item.latitude_deg)
    assert imported.y == degrees_to_e7(item.longitude_deg)
    assert imported.z == pytest.approx(item.altitude_m, abs=1e-4)


def test_builtin_exporters_register_through_entry_points():
    assert {"plan", "waypoints", "geojson", "tour"} <= set(exporters())
    assert exporter_for("a/b.PLAN").name == "plan"
    assert exporter_for("x.waypoints").name == "waypoints"
    assert exporter_for("x.geojson").name == "geojson"
    assert exporter_for("x.json").name == "tour"
    assert exporter_for("x.txt", "waypoints").name == "waypoints"
    with pytest.raises(InputError, match="cannot tell the output format"):
        exporter_for("x.kmz")


def test_plan_is_imported_by_mavsdk_item_for_item(mission, tmp_path, mavsdk_mission_raw):
    path = exporter_for("m.plan").write(mission, tmp_path / "m.plan")
    imported = mavsdk_mission_raw.import_qgroundcontrol_mission(str(path))
    assert len(imported.mission_items) == len(mission.items)
    for seq, (got, item) in enumerate(zip(imported.mission_items, mission.items)):
        assert_item_matches(got, item, seq)
    data = json.loads(path.read_text())
    assert plan_rule_violations(data) == []
    assert data["mission"]["plannedHomePosition"] == [46.801, 6.949, 452.0]
    assert data["mission"]["firmwareType"] == int(mission.autopilot)
    assert data["mission"]["cruiseSpeed"] == 21.0


BREAKAGES = [
    (lambda d: d.update(version=2), "version must be 1"),
    (lambda d: d.update(fileType="Mission"), "fileType"),
    (lambda d: d.pop("groundStation"), "groundStation"),
    (lambda d: d.update(rallyPoints={}), "rallyPoints"),
    (lambda d: d.update(geoFence={}), "geoFence"),
    (lambda d: d["mission"].update(version=1), "mission.version must be 2"),
    (lambda d: d["mission"].pop("firmwareType"), "firmwareType"),
    (lambda d: d["mission"].update(plannedHomePosition=[1, 2]), "plannedHomePosition"),
    (lambda d: d["mission"]["items"][0].update(autoContinue=1), "autoContinue"),
    (lambda d: d["mission"]["items"][0]["params"].pop(), "exactly 7"),
    (lambda d: d["mission"]["items"][0]["params"].__setitem__(4, None), "params 5-7"),
    (lambda d: d["mission"]["items"][0].update(Altitude=100), "go together"),
]


@pytest.mark.parametrize("breakage, message", BREAKAGES)
def test_plan_rule_checker_catches_each_broken_rule(mission, breakage, message):
    data = plan_dict(mission)
    assert plan_rule_violations(data) == []
    breakage(data)
    assert any(message in problem for problem in plan_rule_violations(data))


@pytest.mark.parametrize("breakage", [BREAKAGES[0][0], BREAKAGES[3][0], BREAKAGES[4][0],
                                      BREAKAGES[5][0]])
def test_mavsdk_rejects_what_the_rules_reject(mission, breakage, mavsdk_mission_raw):
    from mavsdk.plugins.mission_raw import MissionRawError
    data = plan_dict(mission)
    mavsdk_mission_raw.import_qgroundcontrol_mission_from_string(json.dumps(data))
    breakage(data)
    with pytest.raises(MissionRawError):
        mavsdk_mission_raw.import_qgroundcontrol_mission_from_string(json.dumps(data))


def test_waypoints_file_is_read_by_mavwploader_field_for_field(mission, tmp_path):
    path = exporter_for("m.waypoints").write(mission, tmp_path / "m.waypoints")
    lines = path.read_text().splitlines()
    assert lines[0] == "QGC WPL 110"
    assert all(len(line.split("\t")) == 12 for line in lines[1:])
    loader = mavwp.MAVWPLoader()
    assert loader.load(str(path)) == len(mission.items) + 1
    home = loader.wp(0)
    assert (home.x, home.y, home.z, home.frame) == (46.801, 6.949, 452.0, 0)
    for seq, item in enumerate(mission.items, start=1):
        got = loader.wp(seq)
        assert got.seq == seq and got.current == 0
        assert (got.command, got.frame, got.autocontinue) == (int(item.command), int(item.frame),
                                                             int(item.autocontinue))
        assert [got.param1, got.param2, got.param3, got.param4] == pytest.approx(list(item.params),
                                                                                  abs=1e-6)
        assert got.x == pytest.approx(item.latitude_deg, abs=1e-10)
        assert got.y == pytest.approx(item.longitude_deg, abs=1e-10)
        assert got.z == pytest.approx(item.altitude_m, abs=1e-6)


def test_waypoints_file_is_read_by_mavsdks_mission_planner_importer(mission, tmp_path,
                                                                     mavsdk_mission_raw):
    path = exporter_for("m.waypoints").write(mission, tmp_path / "m.waypoints")
    imported = mavsdk_mission_raw.import_mission_planner_mission(str(path)).mission_items
    assert len(imported) == len(mission.items) + 1       # home first
    for seq, item in enumerate(mission.items, start=1):
        assert_item_matches(imported[seq], item, seq)


def test_geojson_has_path_targets_waypoints_and_home(mission, tmp_path):
    path = exporter_for("m.geojson").write(mission, tmp_path / "m.geojson")
    features = json.loads(path.read_text())["features"]
    kinds = [f["properties"]["kind"] for f in features]
    assert kinds.count("flight_path") == 1 and kinds.count("home") == 1
    assert kinds.count("target") == 30
    assert kinds.count("waypoint") == sum(i.has_position for i in mission.items)
    line = np.array(features[0]["geometry"]["coordinates"])
    local = mission.frame.to_local(line[:, 1], line[:, 0])
    # Sampled from the exact path: each vertex lies on it.
    assert line.shape[1] == 2 and len(line) > 100
    assert np.hypot(*(local[0] - mission.path.chain.starts[0, :2])) < 1e-6
    for feature in features:
        if feature["properties"]["kind"] == "target":
            target = feature["properties"]["target"] - 1          # numbers are 1-based
            assert feature["properties"]["name"] == f"t{target}"
            item = mission.items[feature["properties"]["item"] - 1]
            assert item.role == "target" and item.target == target
            assert feature["geometry"]["coordinates"] == [item.longitude_deg, item.latitude_deg]


def test_tour_json_from_a_mission_carries_the_frame_origin(mission, tmp_path):
    path = exporter_for("t.json").write(mission, tmp_path / "t.json")
    tour = read_tour(path)
    assert np.array_equal(tour.chain.starts, mission.tour.chain.starts)
    assert origin_from_dict(json.loads(path.read_text())) == (mission.frame.origin_lat_deg,
                                                              mission.frame.origin_lon_deg)


def test_mission_formats_refuse_a_bare_tour(mission, tmp_path):
    with pytest.raises(InputError, match="needs a mission in degrees"):
        exporter_for("m.plan").write(mission.tour, tmp_path / "m.plan")
    assert not (tmp_path / "m.plan").exists()
    assert mission.items[0].command == Command.NAV_TAKEOFF


def test_targets_are_numbered_alike_in_every_output(mission, tmp_path):
    """Target N is the file's row N (1-based) in GeoJSON, KML and fly's report; visits count
    from 1; a mission item has the number QGroundControl shows (1-based, home is 0)."""
    from dataclasses import replace as replaced

    from dtsp_mission.sim.fly import targets_in
    path = exporter_for("m.geojson").write(mission, tmp_path / "m.geojson")
    targets = [f["properties"] for f in json.loads(path.read_text())["features"]
               if f["properties"]["kind"] == "target"]
    count = len(mission.target_items)
    assert sorted(t["target"] for t in targets) == list(range(1, count + 1))
    assert sorted(t["visit"] for t in targets) == list(range(1, count + 1))
    for t in targets:
        assert mission.items[t["item"] - 1].target == t["target"] - 1
    unnamed = replaced(mission, target_names=None)
    labels = targets_in(unnamed.for_vehicle()).names
    assert sorted(labels, key=lambda label: int(label.split()[1])) == \
        [f"target {k}" for k in range(1, count + 1)]
    kml = pytest.importorskip("dtsp_mission_kml")
    text = exporter_for("m.kml").render_for(unnamed, tmp_path / "m.kml")
    text = text.decode() if isinstance(text, bytes) else text
    assert "<name>target 1</name>" in text and "<name>T0</name>" not in text and kml


def test_every_output_gives_the_same_two_lengths(mission, tmp_path):
    """One flight length (take-off to the return) and one tour length (the closed Dubins
    tour), named and rounded as plan prints them, in GeoJSON and KML alike."""
    flight_km = f"{mission.summary['flight_length_m'] / 1e3:,.2f} km"
    tour_m = f"tour {mission.tour.length_m:,.1f} m"
    path = exporter_for("m.geojson").write(mission, tmp_path / "m.geojson")
    line = json.loads(path.read_text())["features"][0]["properties"]
    assert line["flight_length_m"] == mission.summary["flight_length_m"]
    assert line["tour_length_m"] == mission.tour.length_m
    pytest.importorskip("dtsp_mission_kml")
    text = exporter_for("m.kml").render_for(mission, tmp_path / "m.kml")
    text = text.decode() if isinstance(text, bytes) else text
    assert f"flight: {flight_km} from take-off to the return ({tour_m}" in text


def test_the_plan_carries_the_targets_themselves(mission, tmp_path):
    """A .plan written here carries the targets (not their waypoints) in visiting order, so
    that a flight of the file is measured against them; a plan from elsewhere carries none,
    and a broken entry is refused by number."""
    from dtsp_mission.errors import FileFormatError
    from dtsp_mission.export import read_mission
    path = tmp_path / "m.plan"
    exporter_for(path).write(mission, path)
    carried = read_mission(path).targets
    assert carried == mission.visited_targets() and len(carried) == len(mission.target_items)
    latitudes, longitudes = mission.target_positions_deg
    visited = [item.target for item in mission.items if item.role == "target"]
    assert [(t.latitude_deg, t.longitude_deg) for t in carried] == \
        [(latitudes[k], longitudes[k]) for k in visited]
    data = json.loads(path.read_text())
    del data["dtspMission"]
    path.write_text(json.dumps(data))
    assert read_mission(path).targets == ()
    data["dtspMission"] = {"targets": [{"name": "a", "latitude_deg": 46.8, "longitude_deg": 6.9},
                                       {"name": "b", "latitude_deg": 95.0, "longitude_deg": 6.9}]}
    path.write_text(json.dumps(data))
    with pytest.raises(FileFormatError, match="dtspMission.targets entry 2"):
        read_mission(path)
