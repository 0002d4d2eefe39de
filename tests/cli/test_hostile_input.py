"""The rows of the hostile-input report (issue 31) that are fixed, as regression tests: each
command as a user typed it, in a real process under a timeout, must end with a one-line
message and exit 2 (or a correct result) -- never a traceback, never a hang, never a file
written over something that is not a regular file."""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SITE = ROOT / "examples" / "site-inspection.csv"


def run(*arguments, cwd=None):
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", *map(str, arguments)],
                          capture_output=True, text=True, timeout=120, cwd=cwd)


def refused(result, *words):
    assert result.returncode == 2, (result.returncode, result.stderr[-2000:])
    assert "Traceback" not in result.stderr
    for word in words:
        assert word in result.stderr, result.stderr


def test_targets_that_merge_into_one_give_a_result_not_a_traceback(tmp_path):
    (tmp_path / "n3.csv").write_text("x,y\n0,0\n0.000000001,0\n0,0.000000001\n")
    result = run("plan", tmp_path / "n3.csv", "--radius", 80, "--origin", "46.8,6.95",
                 "-o", tmp_path / "n3.json")
    assert "Traceback" not in result.stderr
    assert result.returncode in (0, 2), result.stderr


@pytest.mark.parametrize("properties,words", [('"camera"', ["'properties' must be an object"]),
                                              ('{"alt": true}', ["'alt' must be a number"])])
def test_geojson_properties_of_the_wrong_kind_are_named(tmp_path, properties, words):
    features = [{"type": "Feature", "properties": "PROPS",
                 "geometry": {"type": "Point", "coordinates": [6.95, 46.8]}},
                {"type": "Feature", "properties": {"alt": 100},
                 "geometry": {"type": "Point", "coordinates": [6.96, 46.81]}}]
    text = json.dumps({"type": "FeatureCollection", "features": features})
    (tmp_path / "t.geojson").write_text(text.replace('"PROPS"', properties))
    refused(run("plan", tmp_path / "t.geojson", "--radius", 80, "--time-limit", 1,
                "-o", tmp_path / "t.plan"), *words)
    assert not (tmp_path / "t.plan").exists()


def test_a_third_geojson_coordinate_is_not_dropped_in_silence(tmp_path):
    features = [{"type": "Feature", "properties": {},
                 "geometry": {"type": "Point", "coordinates": [6.95 + k / 100, 46.8, 500]}}
                for k in range(3)]
    (tmp_path / "t.geojson").write_text(json.dumps({"type": "FeatureCollection",
                                                    "features": features}))
    refused(run("plan", tmp_path / "t.geojson", "--radius", 80, "-o", tmp_path / "t.json"),
            "third coordinate")


@pytest.mark.parametrize("line,words", [
    ("ROLL_LIMIT_DEG 0", ["ROLL_LIMIT_DEG 0 is out of its range"]),
    ("AIRSPEED_CRUISE 0", ["AIRSPEED_CRUISE 0 is out of its range"]),
    ("NAVL1_PERIOD nan", ["NAVL1_PERIOD nan is out of its range"]),
    ("NAVL1_PERIOD -5", ["NAVL1_PERIOD -5 is out of its range"]),
    ("NAVL1_PERIODX 12", ["did you mean NAVL1_PERIOD"]),
    ("ROLL_LIMIT_DEG 12", ["cannot turn at 80 m", "no tighter than"]),
])
def test_vehicle_parameters_are_checked_before_planning(tmp_path, line, words):
    (tmp_path / "v.parm").write_text(line + "\n")
    refused(run("plan", SITE, "--radius", 80, "--time-limit", 1, "--vehicle-params",
                tmp_path / "v.parm", "-o", tmp_path / "v.json"), *words)
    assert not (tmp_path / "v.json").exists()


@pytest.mark.parametrize("value", ["nan", "inf", "1e300"])
def test_time_limits_are_finite(tmp_path, value):
    refused(run("plan", SITE, "--radius", 80, "--time-limit", value, "-o", tmp_path / "t.json"),
            "--time-limit")


def test_a_radius_beyond_reason_is_refused_before_planning(tmp_path):
    refused(run("plan", SITE, "--radius", "1e9", "-o", tmp_path / "t.json"), "--radius", "to 20000 m")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_an_output_never_replaces_a_fifo(tmp_path):
    fifo = tmp_path / "out.plan"
    os.mkfifo(fifo)
    refused(run("plan", SITE, "--radius", 80, "--time-limit", 1, "-o", fifo), "is a FIFO")
    assert fifo.is_fifo()


def _plan_variant(tmp_path: Path, name: str, change) -> Path:
    """A small valid .plan (6 targets, geometry design), changed by ``change(document)``."""
    source = tmp_path / "base.plan"
    if not source.exists():
        (tmp_path / "t.csv").write_text("lat,lon\n" + "".join(
            f"{46.80 + 0.004 * (k % 3)},{6.95 + 0.005 * k}\n" for k in range(6)))
        result = run("plan", tmp_path / "t.csv", "--radius", 80, "--time-limit", 1, "--design",
                     "geometry", "-o", source)
        assert result.returncode == 0, result.stderr
    document = json.loads(source.read_text())
    change(document)
    out = tmp_path / name
    out.write_text(json.dumps(document))
    return out


def test_a_plan_position_off_the_globe_is_refused_when_read(tmp_path):
    def far(document):
        document["mission"]["items"][2]["params"][4] = 999
    refused(run("fly", _plan_variant(tmp_path, "far.plan", far), "--speedup", 0),
            "latitude 999", "not a position in degrees")


def test_fly_of_a_plan_without_waypoints_reports_instead_of_crashing(tmp_path):
    def bare(document):
        items = document["mission"]["items"]
        document["mission"]["items"] = [items[0], items[-1]]
    result = run("fly", _plan_variant(tmp_path, "bare.plan", bare), "--speedup", 0)
    assert "Traceback" not in result.stderr
    assert result.returncode == 0, result.stderr


# 400 (COMPONENT_ARM_DISARM): a MAVLink command, but none a mission takes (9999, none at all, is
# refused before anything is sent: test_hostile_input_2)
@pytest.mark.parametrize("field,value,answer", [("command", 400, "MAV_MISSION_UNSUPPORTED"),
                                                ("frame", 1, "MAV_MISSION_UNSUPPORTED_FRAME")])
def test_the_simulated_vehicle_refuses_what_ardupilot_refuses(tmp_path, field, value, answer):
    def odd(document):
        document["mission"]["items"][2][field] = value
    refused_flight = run("fly", _plan_variant(tmp_path, "odd.plan", odd), "--speedup", 0)
    assert refused_flight.returncode != 0 and "Traceback" not in refused_flight.stderr
    assert answer in refused_flight.stderr, refused_flight.stderr


def test_a_plan_without_the_altitude_mode_is_read_as_qgroundcontrol_reads_it(tmp_path):
    def older(document):
        del document["mission"]["globalPlanAltitudeMode"]
    result = run("fly", _plan_variant(tmp_path, "old.plan", older), "--speedup", 0)
    assert result.returncode == 0, result.stderr


def test_a_copter_plan_is_refused(tmp_path):
    def copter(document):
        document["mission"]["vehicleType"] = 2
    refused(run("fly", _plan_variant(tmp_path, "copter.plan", copter), "--speedup", 0),
            "vehicleType 2 is a quadrotor")


def test_plan_upload_to_nothing_leaves_no_file(tmp_path):
    import socket
    with socket.socket() as probe:                  # a loopback port where nothing listens
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    (tmp_path / "t.csv").write_text("lat,lon\n46.80,6.95\n46.81,6.96\n46.805,6.97\n")
    result = run("plan", tmp_path / "t.csv", "--radius", 80, "--time-limit", 1, "--design",
                 "geometry", "-o", tmp_path / "o.plan", "-o", tmp_path / "o.waypoints",
                 "--plot", tmp_path / "o.png", "--upload", f"tcp:127.0.0.1:{port}")
    assert result.returncode != 0 and "Traceback" not in result.stderr, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


SMALL = "lat,lon\n46.80,6.95\n46.81,6.96\n46.805,6.97\n"


def _small(tmp_path: Path, text: str = SMALL) -> Path:
    (tmp_path / "t.csv").write_text(text)
    return tmp_path / "t.csv"


def test_an_altitude_below_the_floor_is_refused_and_can_be_lowered_explicitly(tmp_path):
    refused(run("plan", _small(tmp_path), "--radius", 80, "--time-limit", 1, "--alt", 0.5,
                "-o", tmp_path / "a.json"), "--min-alt")
    lowered = run("plan", _small(tmp_path), "--radius", 80, "--time-limit", 1, "--alt", 20,
                  "--min-alt", 10, "--design", "geometry", "-o", tmp_path / "b.json")
    assert lowered.returncode == 0, lowered.stderr
    assert not (tmp_path / "a.json").exists()


def test_a_target_altitude_below_the_floor_is_refused_before_planning_naming_its_line(tmp_path):
    text = "lat,lon,alt\n46.80,6.95,90\n46.81,6.96,0.001\n46.805,6.97,90\n"
    refused(run("plan", _small(tmp_path, text), "--radius", 80, "--time-limit", 1,
                "-o", tmp_path / "a.json"), "line 3", "--min-alt")


def test_a_step_steeper_than_the_aircraft_climbs_is_a_warning(tmp_path):
    text = "lat,lon,alt\n46.80,6.95,40\n46.8015,6.95,300\n46.805,6.97,40\n"
    result = run("plan", _small(tmp_path, text), "--radius", 80, "--time-limit", 1,
                 "--design", "geometry", "-o", tmp_path / "a.plan")
    assert result.returncode == 0, result.stderr
    assert "steeper than" in result.stderr, result.stderr


def test_a_negative_relative_altitude_in_a_plan_is_refused(tmp_path):
    def sunk(document):
        document["mission"]["items"][2]["params"][6] = -20
    refused(run("fly", _plan_variant(tmp_path, "sunk.plan", sunk), "--speedup", 0),
            "below the ground")


@pytest.mark.parametrize("option,value,words", [
    ("--max-items", 3, ["a sortie needs at least 4 items", "allow more"]),
    ("--endurance", 0.01, ["--endurance"]),
])
def test_capacity_messages_say_what_is_needed(tmp_path, option, value, words):
    result = run("plan", _small(tmp_path), "--radius", 80, "--time-limit", 1, option, value,
                 "-o", tmp_path / "a.plan")
    refused(result, *words)
    assert "None" not in result.stderr


def test_a_port_out_of_range_is_named(tmp_path):
    refused(run("upload", _plan_variant(tmp_path, "p.plan", lambda d: None),
                "--connect", "tcp:127.0.0.1:99999"), "99999 is not a port number")


def test_upload_names_only_the_formats_it_reads(tmp_path):
    result = run("upload", _small(tmp_path), "--connect", "tcp:127.0.0.1:5799")
    refused(result, ".waypoints")
    assert ".geojson" not in result.stderr and ".kml" not in result.stderr


def test_dubins_takes_negative_poses_without_a_separator():
    result = run("dubins", "-5,0,0", "100,20,90", "--radius", 10)
    assert result.returncode == 0, result.stderr


def test_fly_refuses_targets_far_from_the_mission_and_shows_unknown_altitude(tmp_path):
    plan = _plan_variant(tmp_path, "f.plan", lambda d: None)
    (tmp_path / "far.csv").write_text("lat,lon\n10.0,10.0\n")
    refused(run("fly", plan, "--speedup", 0, "--targets", tmp_path / "far.csv"), "--targets")
    result = run("fly", plan, "--speedup", 0, "--targets", tmp_path / "t.csv")
    assert result.returncode == 0, result.stderr
    assert "nan" not in result.stdout.lower(), result.stdout
    assert "flying about" in result.stdout         # the estimate, said before flying


def test_random_targets_in_an_area_smaller_than_a_turn_are_refused(tmp_path):
    ring = [[6.95, 46.8], [6.9500001, 46.8], [6.9500001, 46.8000001], [6.95, 46.8000001],
            [6.95, 46.8]]
    (tmp_path / "tiny.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon",
                                                           "coordinates": [ring]}}]}))
    refused(run("plan", "--random", 8, "--area", tmp_path / "tiny.geojson", "--radius", 80,
                "-o", tmp_path / "r.json"), "smaller than one turn")


def test_many_loiter_turns_are_designed_in_seconds_and_counted_in_the_flight(tmp_path):
    """255 turns at each of 6 targets: a 1,000 km flight.  The design flies the first turns
    of each loiter (the rest repeat them) and adds the rest's length; fly says what it faces."""
    text = "lat,lon,loiter_turns\n" + "".join(
        f"{46.80 + 0.005 * (k % 3)},{6.95 + 0.01 * (k // 3) + 0.004 * k},255\n" for k in range(6))
    result = run("plan", _small(tmp_path, text), "--radius", 80, "--time-limit", 1,
                 "-o", tmp_path / "l.plan")
    assert result.returncode == 0, result.stderr
    found = re.search(r"predicted flight ([\d,.]+) km against ([\d,.]+) km", result.stdout)
    predicted, planned = (float(g.replace(",", "")) for g in found.groups())
    assert predicted > 6 * 255 * 2 * math.pi * 80 / 1000        # every turn counted
    assert abs(predicted / planned - 1) < 0.05, result.stdout
