"""The second hostile-input report (issue 49), as regression tests: each command as a user
typed it, in a real process under a timeout -- a clear message and a non-zero exit, or the
right result; never a traceback, a hang, a silent loss or a file written over an input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SITE = ROOT / "examples" / "site-inspection.csv"
QUICK = ("--radius", 80, "--time-limit", 1)


def run(*arguments, cwd=None, timeout=120):
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", *map(str, arguments)],
                          capture_output=True, text=True, timeout=timeout, cwd=cwd)


def refused(result, *words, code=2):
    assert result.returncode == code, (result.returncode, result.stderr[-2000:])
    assert "Traceback" not in result.stderr
    for word in words:
        assert word in result.stderr, result.stderr
    return result


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """``s8.csv`` (the bundled site's first 8 targets) and ``base.plan`` planned from it."""
    folder = tmp_path_factory.mktemp("site")
    lines = SITE.read_text().splitlines()[:9]
    (folder / "s8.csv").write_text("\n".join(lines) + "\n")
    planned = run("plan", folder / "s8.csv", *QUICK, "-o", folder / "base.plan")
    assert planned.returncode == 0, planned.stderr
    return folder


def edited(site, tmp_path, change) -> Path:
    """``base.plan`` with ``change(document)`` applied, written to a new file."""
    document = json.loads((site / "base.plan").read_text())
    change(document)
    path = tmp_path / "edited.plan"
    path.write_text(json.dumps(document))
    return path


def item(command, params, frame=2):
    return {"type": "SimpleItem", "command": command, "frame": frame, "params": params,
            "autoContinue": True, "doJumpId": 99}


def nth_waypoint(document, k: int = 1) -> dict:
    """The k-th NAV_WAYPOINT item of a .plan document (0: the first; the design may put
    DO_CHANGE_SPEED items of slow zones among them)."""
    return [i for i in document["mission"]["items"] if i.get("command") == 16][k]


def at_waypoint(document, command, first_param, altitude=100.0):
    items = document["mission"]["items"]
    lat, lon = nth_waypoint(document)["params"][4:6]
    items.insert(items.index(nth_waypoint(document, 2)),
                 item(command, [first_param, 0, 0, 0, lat, lon, altitude], frame=3))


# -- one validation of option values, the same everywhere ------------------------------------

@pytest.mark.parametrize("arguments,words", [
    (("plan", "SITE", "--radius", 80, "--airspeed", "inf"), ["--airspeed", "from 5 to 100 m/s"]),
    (("plan", "SITE", "--radius", 80, "--seed", 2 ** 64), ["--seed", "out of range"]),
    (("plan", "SITE", "--airspeed", 22, "--max-bank", "1e-6"), ["--max-bank", "from 10 to 89 deg"]),
    (("plan", "SITE", "--radius", 80, "--launch-bearing", "1e300"), ["--launch-bearing"]),
    (("plan", "SITE", "--radius", 80, "--l1-period", 80), ["NAVL1_PERIOD 80 is out of its range"]),
    (("fly", "PLAN", "--airspeed", "1e-3"), ["--airspeed"]),
    (("fly", "PLAN", "--radius", "1e9"), ["--radius", "from 0.1 to 20000 m"]),
    (("fly", "PLAN", "--l1-period", "1e6"), ["--l1-period"]),
    (("fly", "PLAN", "--max-miss", -1), ["--max-miss"]),
    (("fly", "PLAN", "--max-miss", "nan"), ["--max-miss"]),
    (("fly", "PLAN", "--speedup", "1e-9"), ["--speedup", "0 (as fast as possible) or"]),
    (("fly", "PLAN", "--speedup", "inf"), ["--speedup"]),
    (("fly", "PLAN", "--max-items", 0), ["--max-items"]),
    (("sim", "--home", "46.8,6.9", "--radius", 80, "--max-items", 70000), ["--max-items"]),
    (("sim", "--home", "46.8,6.9", "--radius", 80, "--speedup", "nan"), ["--speedup"]),
    (("sim", "--home", "46.8,6.9", "--radius", 80, "--home-amsl", "nan"), ["--home-amsl"]),
    (("sim", "--home", "46.8,6.9", "--radius", "1e9"), ["--radius"]),
    (("upload", "PLAN", "--connect", "udpout:127.0.0.1:9", "--heartbeat-timeout", -1),
     ["--heartbeat-timeout"]),
    (("upload", "PLAN", "--connect", "udpout:127.0.0.1:9", "--heartbeat-timeout", "nan"),
     ["--heartbeat-timeout"]),
    (("dubins", "0,0,0", "100,0,0", "--radius", "1e300"), ["--radius"]),
    (("dubins", "0,0,0", "100,0,0", "--radius", "1e-300"), ["--radius"]),
    (("dubins", "0,0,0", "1e300,0,0", "--radius", 80), ["x and y must be within"]),
])
def test_option_values_have_the_same_limits_in_every_command(site, arguments, words):
    arguments = [site / "s8.csv" if a == "SITE" else site / "base.plan" if a == "PLAN" else a
                 for a in arguments]
    refused(run(*arguments, timeout=60), *words)


def test_a_heading_of_1e300_degrees_ends_at_the_goal():
    result = run("dubins", "0,0,0", "100,0,1e300", "--radius", 80)
    assert result.returncode == 0, result.stderr
    end_heading = float(result.stdout.split("heading ")[-1].split(" deg")[0])
    assert abs((end_heading - 1e300 % 360.0 + 180.0) % 360.0 - 180.0) < 1e-6


def test_plan_designs_for_its_l1_period(site, tmp_path):
    result = run("plan", site / "s8.csv", *QUICK, "--l1-period", 17, "--json",
                 "-o", tmp_path / "p.plan")
    assert result.returncode == 0, result.stderr
    designed = json.loads((tmp_path / "p.plan").read_text())["dtspMission"]["aircraft"]
    assert designed["parameters"]["NAVL1_PERIOD"] == 17


@pytest.mark.parametrize("extra,words", [
    (("--return", "rtl", "--landing-bearing", 90), ["landing bearing is for --return land"]),
    (("--tolerance", 2), ["--tolerance) is for --design geometry"]),
    (("--loiter-radius", 120), ["no target loiters"]),
    (("--wind", "15.3@90"), ["plus its spread", "--wind-spread"]),
    (("--home", "90,0"), ["is --home right"]),
    (("--loiter", "3:256"), ["from 0 to 255"]),
])
def test_options_that_would_be_ignored_or_misread_are_named(site, tmp_path, extra, words):
    refused(run("plan", site / "s8.csv", *QUICK, *extra, "-o", tmp_path / "x.plan"), *words)
    assert not (tmp_path / "x.plan").exists()


def test_a_loiter_name_shared_by_several_targets_is_refused(tmp_path):
    (tmp_path / "t.csv").write_text("lat,lon,name\n46.8078,6.9408,a\n46.8079,6.9430,a\n"
                                    "46.8090,6.9423,b\n")
    refused(run("plan", tmp_path / "t.csv", *QUICK, "--loiter", "a", "-o", tmp_path / "t.plan"),
            "2 targets have that name (numbers 1, 2)")


# -- readers take what QGroundControl and GIS tools write -------------------------------------

def test_a_plan_as_qgroundcontrol_writes_it_is_flown():
    result = run("fly", ROOT / "tests" / "data" / "qgroundcontrol-4.plan", "--speedup", 400, "--json")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["flight"]["completed"] is True


def test_geojson_in_another_coordinate_system_is_refused(tmp_path):
    points = [{"type": "Feature", "properties": {},
               "geometry": {"type": "Point", "coordinates": [46.80 + k / 1000, 6.94 + k / 1000]}}
              for k in range(4)]
    data = {"type": "FeatureCollection", "features": points,
            "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::4326"}}}
    (tmp_path / "t.geojson").write_text(json.dumps(data))
    refused(run("plan", tmp_path / "t.geojson", *QUICK, "-o", tmp_path / "t.plan"),
            "declares the coordinate system 'urn:ogc:def:crs:EPSG::4326'", "RFC 7946")
    data["crs"]["properties"]["name"] = "urn:ogc:def:crs:OGC:1.3:CRS84"
    data["features"] = [dict(f, geometry={"type": "Point", "coordinates": f["geometry"]["coordinates"][::-1]})
                        for f in points]
    (tmp_path / "t.geojson").write_text(json.dumps(data))
    assert run("plan", tmp_path / "t.geojson", *QUICK, "-o", tmp_path / "t.json").returncode == 0


SQUARE = [[6.94, 46.80], [6.95, 46.80], [6.95, 46.81], [6.94, 46.81], [6.94, 46.80]]
HOLE = [[6.944, 46.804], [6.946, 46.804], [6.946, 46.806], [6.944, 46.806], [6.944, 46.804]]


def polygon_file(path, rings):
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": rings}}]}))
    return path


def test_an_area_with_a_hole_is_refused_not_ignored(tmp_path):
    refused(run("plan", "--random", 8, "--area", polygon_file(tmp_path / "h.geojson", [SQUARE, HOLE]),
                *QUICK, "-o", tmp_path / "r.plan"), "1 hole(s)")


def test_a_file_with_only_an_area_says_there_are_no_point_targets(site, tmp_path):
    area = polygon_file(tmp_path / "a.geojson", [SQUARE])
    refused(run("plan", area, *QUICK, "-o", tmp_path / "a.plan"), "no point targets")
    refused(run("fly", site / "base.plan", "--targets", area), "no point targets")


@pytest.mark.parametrize("command", ["plan", "check", "fly"])
def test_json_nested_100000_deep_is_a_message(site, tmp_path, command):
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    arguments = {"plan": ("plan", tmp_path / "deep.json", *QUICK, "-o", tmp_path / "d.plan"),
                 "check": ("check", tmp_path / "deep.json"),
                 "fly": ("fly", site / "base.plan", "--targets", tmp_path / "deep.json")}[command]
    refused(run(*arguments), "nested too deep")


def test_a_quote_left_open_in_a_csv_is_refused(tmp_path):
    (tmp_path / "q.csv").write_text('lat,lon,name\n46.8078,6.9408,"a,b"\n46.8079,6.9415,'
                                    '"unterminated\n46.8090,6.9423,c\n')
    refused(run("plan", tmp_path / "q.csv", *QUICK, "-o", tmp_path / "q.plan"),
            "line 3: a quote opened here is never closed")


@pytest.mark.parametrize("text,words", [
    ("\ufeffNAVL1_PERIOD 17\n", None),
    ("NAVL1_PERIOD 17\nNAVL1_PERIOD 25\n", ["NAVL1_PERIOD is given twice, 17 (line 1) and 25 (line 2)"]),
    ("1\t1\tNAVL1_PERIOD\t17\t9\n2\t1\tNAVL1_PERIOD\t17\t9\n", ["parameters of 2 vehicles"]),
    ("NPFG_PERIOD 12\n", ["holds PX4 parameters (NPFG_PERIOD)", "--autopilot px4"]),
    ("TRIM_ARSPD_CM 3500\n", ["at 35 m/s"]),     # read as AIRSPEED_CRUISE: rho 80 too tight
])
def test_parameter_files_are_read_as_written(site, tmp_path, text, words):
    (tmp_path / "v.parm").write_text(text, encoding="utf-8")
    result = run("plan", site / "s8.csv", *QUICK, "--vehicle-params", tmp_path / "v.parm",
                 "-o", tmp_path / "v.plan")
    if words is None:
        assert result.returncode == 0, result.stderr
        designed = json.loads((tmp_path / "v.plan").read_text())["dtspMission"]["aircraft"]
        assert designed["parameters"]["NAVL1_PERIOD"] == 17
    else:
        refused(result, *words)


# -- inputs never overwritten, sortie files never over unrelated or stale ---------------------

def test_an_output_that_is_an_input_is_refused(site, tmp_path):
    copy = tmp_path / "in.csv"
    copy.write_text((site / "s8.csv").read_text())
    before = copy.read_text()
    refused(run("plan", copy, *QUICK, "-o", copy, "--format", "geojson"), "is an input of this run")
    assert copy.read_text() == before


def test_sorties_never_replace_an_unrelated_file_and_never_leave_stale_ones(site, tmp_path):
    fast = ("--radius", 80, "--time-limit", 0)
    (tmp_path / "q-2.plan").write_text("keep\n")
    refused(run("plan", site / "s8.csv", *fast, "--max-items", 7, "-o", tmp_path / "q.plan"),
            "q-2.plan exists and is not a sortie file dtsp-mission wrote")
    assert (tmp_path / "q-2.plan").read_text() == "keep\n" and not (tmp_path / "q-1.plan").exists()
    split = run("plan", site / "s8.csv", *fast, "--max-items", 7, "-o", tmp_path / "z.plan")
    assert split.returncode == 0, split.stderr
    assert (tmp_path / "z-1.plan").exists() and (tmp_path / "z-2.plan").exists()
    whole = run("plan", site / "s8.csv", *fast, "-o", tmp_path / "z.plan")
    assert whole.returncode == 0, whole.stderr
    assert sorted(p.name for p in tmp_path.glob("z*")) == ["z.plan"]
    assert "removed" in whole.stdout + whole.stderr


def test_a_split_that_fits_is_found(tmp_path):
    lines = SITE.read_text().splitlines()[:17]
    (tmp_path / "s16.csv").write_text("\n".join(lines) + "\n")
    result = run("plan", tmp_path / "s16.csv", *QUICK, "--max-items", 10, "--json",
                 "-o", tmp_path / "m.plan")
    assert result.returncode == 0, result.stderr
    sorties = json.loads(result.stdout)["sorties"]
    assert sum(len(list(tmp_path.glob("m-*.plan"))) for _ in [0]) == len(sorties) >= 2
    for k in range(1, len(sorties) + 1):
        items = json.loads((tmp_path / f"m-{k}.plan").read_text())["mission"]["items"]
        assert len(items) + 1 <= 10                        # with ArduPilot's home slot


# -- missions checked as plan checks what it writes -------------------------------------------

@pytest.mark.parametrize("change,words", [
    (lambda d: nth_waypoint(d, 0).__setitem__("command", 9999), ["command 9999 is no MAVLink command"]),
    (lambda d: nth_waypoint(d)["params"].__setitem__(slice(4, 6), [0, 0]), ["km from home"]),
    (lambda d: nth_waypoint(d)["params"].__setitem__(4, 90.0), ["km from home"]),
    (lambda d: at_waypoint(d, 18, 1e6), ["ArduPilot keeps from 1 to 255 turns"]),
    (lambda d: nth_waypoint(d)["params"].__setitem__(6, 50_000), ["beyond the 10,000 m"]),
])
def test_missions_no_autopilot_would_fly_as_planned_are_refused(site, tmp_path, change, words):
    plan = edited(site, tmp_path, change)
    refused(run("fly", plan), *words)
    refused(run("upload", plan, "--connect", "udpout:127.0.0.1:9", "--heartbeat-timeout", 1), *words)


def test_waypoints_underground_in_the_amsl_frame_are_refused(site, tmp_path):
    def underground(document):
        document["mission"]["plannedHomePosition"][2] = 600.0
        for entry in document["mission"]["items"]:
            if entry["command"] == 16:
                entry["frame"], entry["params"][6] = 0, 95.0
    plan = edited(site, tmp_path, underground)
    refused(run("fly", plan), "505 m below home")
    refused(run("upload", plan, "--connect", "udpout:127.0.0.1:9"), "505 m below home")


def test_upload_holds_a_file_to_the_altitude_floor(site, tmp_path):
    plan = edited(site, tmp_path, lambda d: nth_waypoint(d)["params"].__setitem__(6, 2.0))
    refused(run("upload", plan, "--connect", "udpout:127.0.0.1:9"),
            "below the altitude floor of 30 m", "at 2 m above home")


@pytest.mark.parametrize("command,first,words", [
    (177, [2, -1, 0, 0, 0, 0, 0], ["DO_JUMP", "for ever"]),
    (177, [2, 5, 0, 0, 0, 0, 0], ["DO_JUMP", "5 times"]),
    (93, [1e7, -1, -1, -1, 0, 0, 0], ["NAV_DELAY"]),
])
def test_fly_refuses_what_its_model_does_not_fly(site, tmp_path, command, first, words):
    plan = edited(site, tmp_path, lambda d: d["mission"]["items"].insert(5, item(command, first)))
    refused(run("fly", plan, timeout=60), *words)


def test_fly_refuses_to_loiter_for_ever_or_for_years(site, tmp_path):
    refused(run("fly", edited(site, tmp_path, lambda d: at_waypoint(d, 17, 0)), timeout=60),
            "loiters until told otherwise")
    refused(run("fly", edited(site, tmp_path, lambda d: at_waypoint(d, 19, 1e9)), timeout=60),
            "the simulator flies at most 24 h")


def test_fly_refuses_targets_that_are_not_the_missions(site, tmp_path):
    def far(document):
        for target in document["dtspMission"]["targets"]:
            target["latitude_deg"] -= 40.0
    refused(run("fly", edited(site, tmp_path, far)), "not the targets this mission was planned for")


# -- tour files, reports, plugins --------------------------------------------------------------

def test_check_refuses_a_stated_length_that_is_not_the_paths_and_a_tour_of_no_targets(site, tmp_path):
    planned = run("plan", site / "s8.csv", *QUICK, "-o", tmp_path / "t.json")
    assert planned.returncode == 0, planned.stderr
    tour = json.loads((tmp_path / "t.json").read_text())
    assert run("check", tmp_path / "t.json").returncode == 0
    (tmp_path / "short.json").write_text(json.dumps(dict(tour, length_m=1.0)))
    refused(run("check", tmp_path / "short.json"), "'length_m' says 1 m")
    (tmp_path / "none.json").write_text(json.dumps(dict(tour, targets=[], visits=[])))
    refused(run("check", tmp_path / "none.json"), "visits no targets")


def test_targets_as_good_as_one_point_report_no_absurd_ratio(tmp_path):
    (tmp_path / "n3.csv").write_text("x,y\n0,0\n0.000000001,0\n0,0.000000001\n")
    result = run("plan", tmp_path / "n3.csv", "--radius", 80, "--origin", "46.8,6.95",
                 "-o", tmp_path / "n3.json")
    assert result.returncode == 0, result.stderr
    assert "no ratio to report" in result.stdout and "0.0 m -> 0.0 m" not in result.stdout
    assert "improvement: none" in result.stdout


def test_a_plugin_never_replaces_a_built_in(site, tmp_path):
    from conftest import environment_with_distribution
    env = environment_with_distribution(tmp_path, "clashing-plugin", "\n".join([
        "[dtsp_mission.exporters]", "plan = no_such_module_anywhere:Exporter",
        "[dtsp_mission.commands]", "plan = json:dumps", ""]))
    listing = subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "plugins"], env=env,
                             capture_output=True, text=True, timeout=120)
    assert listing.returncode == 0, listing.stderr
    assert "'plan' of clashing-plugin is ignored" in listing.stderr
    planned = subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "plan", site / "s8.csv",
                              *map(str, QUICK), "-o", tmp_path / "p.plan"], env=env,
                             capture_output=True, text=True, timeout=120)
    assert planned.returncode == 0, planned.stderr
    assert json.loads((tmp_path / "p.plan").read_text())["fileType"] == "Plan"


def test_a_tcp_vehicle_that_goes_away_mid_talk_is_a_message(site):
    """A vehicle on TCP (ArduPilot SITL's link) that answers with heartbeats and then drops
    the connection (reset): the upload says the link closed, no traceback."""
    import socket
    import struct
    import threading

    from pymavlink.dialects.v20 import ardupilotmega as mavlink

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    port = server.getsockname()[1]

    def vehicle():
        connection, _ = server.accept()
        mav = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
        for _ in range(3):
            connection.sendall(mav.heartbeat_encode(1, 3, 0, 0, 3).pack(mav))
        connection.recv(4096)                         # the ground station's first words
        connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        connection.close()                            # RST: as a killed SITL
        server.close()
    threading.Thread(target=vehicle, daemon=True).start()
    result = run("upload", site / "base.plan", "--connect", f"tcp:127.0.0.1:{port}",
                 "--heartbeat-timeout", 5, timeout=90)
    assert result.returncode != 0 and "Traceback" not in result.stderr, result.stderr
    assert "the link to the vehicle at tcp:127.0.0.1" in result.stderr and "closed" in result.stderr, result.stderr
