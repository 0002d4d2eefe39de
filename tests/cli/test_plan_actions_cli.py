"""``plan`` with actions at the targets, the two faces of one pipeline, PX4 and .waypoints,
and ``fly`` measuring to the targets: end to end, read back by the real readers."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from pymavlink import mavwp

from dtsp_mission.export.qgc_plan import plan_rule_violations

SITE = Path(__file__).parents[2] / "examples" / "site-inspection.csv"


def run(command, *arguments):
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", command, *map(str, arguments)],
                          capture_output=True, text=True, timeout=300)


@pytest.fixture
def small_site(tmp_path):
    """Ten targets of the bundled site, with action columns."""
    rows = SITE.read_text().splitlines()[1:11]
    path = tmp_path / "t.csv"
    lines = ["lat,lon,alt,name,photo,loiter_turns"]
    for k, row in enumerate(rows):
        lines.append(f"{row},{'yes' if k % 2 == 0 else 'no'},{2 if k == 4 else ''}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_plan_writes_the_actions_each_autopilot_accepts(small_site, tmp_path, mavsdk_mission_raw):
    for autopilot, photo, roi in (("ardupilot", 203, 201), ("px4", 2000, 195)):
        plan, waypoints = tmp_path / f"{autopilot}.plan", tmp_path / f"{autopilot}.waypoints"
        result = run("plan", small_site, "--radius", "60", "--airspeed", "20", "--algorithm",
                     "alternating", "--autopilot", autopilot, "--return", "land", "--roi",
                     "--gimbal-pitch", "-60", "--loiter", "line1-pylon02:1", "-o", plan,
                     "-o", waypoints)
        assert result.returncode == 0, result.stderr
        data = json.loads(plan.read_text())
        assert plan_rule_violations(data) == []
        commands = [item["command"] for item in data["mission"]["items"]]
        assert commands.count(photo) == 5
        if autopilot == "ardupilot":     # and DO_SET_ROI at 0, 0, 0: ArduPilot's "no ROI"
            assert commands.count(roi) == 11 and commands[-1] == 21      # NAV_LAND last
        else:
            assert commands.count(roi) == 10 and commands.count(197) == 1     # DO_SET_ROI_NONE
        assert commands.count(18 if autopilot == "ardupilot" else 19) == 2   # pylon02 and pylon05
        imported = mavsdk_mission_raw.import_qgroundcontrol_mission(str(plan)).mission_items
        assert [item.command for item in imported] == commands
        if autopilot == "ardupilot":     # the shutter flag reaches MAVSDK as a plain x of 1
            assert {item.x for item in imported if item.command == photo} == {1}
        loader = mavwp.MAVWPLoader()
        assert loader.load(str(waypoints)) == len(commands) + 1      # row 0 is the home
        assert [loader.wp(k).command for k in range(1, loader.count())] == commands
        px4_note = "row 0" in result.stderr
        assert px4_note == (autopilot == "px4")


def test_a_loiter_at_an_unknown_target_is_a_clear_error(small_site, tmp_path):
    for spec, message in (("nosuch", "no such target"), ("11", "from 1 to 10"),
                          ("3:1.5", "whole number")):
        result = run("plan", small_site, "--radius", "60", "--loiter", spec, "-o",
                     tmp_path / "m.plan")
        assert result.returncode == 2 and message in result.stderr, (spec, result.stderr)
        assert "Traceback" not in result.stderr and not (tmp_path / "m.plan").exists()


def test_cli_and_api_are_one_pipeline(small_site, tmp_path):
    """The same request through the command line and through the API gives the same items."""
    from dtsp_mission.api import plan_mission
    from dtsp_mission.export import read_mission
    from dtsp_mission.mission import MissionSettings
    from dtsp_mission.targets import read_targets
    out = tmp_path / "m.plan"
    result = run("plan", small_site, "--radius", "60", "--airspeed", "20", "--algorithm",
                 "alternating", "--design", "guidance", "--photo", "-o", out)
    assert result.returncode == 0, result.stderr
    api = plan_mission(read_targets(small_site), 60.0, MissionSettings(
        airspeed_m_s=20.0, design="guidance", photo=True), algorithm="alternating")
    from_file = read_mission(out)
    assert len(from_file.items) == len(api.items)
    for ours, theirs in zip(from_file.items, api.items):
        assert (ours.command, ours.frame) == (theirs.command, theirs.frame)
        assert np.allclose([*ours.params, ours.latitude_deg, ours.longitude_deg, ours.altitude_m],
                           [*theirs.params, theirs.latitude_deg, theirs.longitude_deg,
                            theirs.altitude_m], atol=1e-9)
    if "planned with a turn radius" in result.stderr:       # the widening is part of both
        assert api.rho_m > 60.0


def test_a_px4_waypoints_file_uploads_without_its_home_row(tmp_path, start_vehicle):
    """WPL 110 keeps home in row 0 for every autopilot (QGroundControl reads it so); the file
    does not say the autopilot, so the uploader takes the vehicle's and sends PX4 the items
    only: the vehicle's item 0 is the take-off, not a waypoint at home at 0 m."""
    from dtsp_mission.export import read_mission
    from dtsp_mission.upload import upload_mission
    out = tmp_path / "p.waypoints"
    result = run("plan", SITE, "--radius", "80", "--algorithm", "alternating", "--autopilot",
                 "px4", "--return", "land", "--design", "geometry", "--max-items", "5000",
                 "-o", out)
    assert result.returncode == 0, result.stderr
    assert "row 0" in result.stderr and "PX4" in result.stderr
    mission = read_mission(out)
    assert not mission.autopilot_stated
    from dtsp_mission.autopilot import Autopilot
    from dataclasses import replace
    vehicle = start_vehicle(replace(mission, autopilot=Autopilot.PX4), max_items=5000)
    report = upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
    assert report.verified and report.items == len(mission.items)
    assert vehicle.mission[0].command == 22 and len(vehicle.mission) == len(mission.items)


def test_fly_measures_to_the_targets_file_by_its_names(small_site, tmp_path):
    out = tmp_path / "m.plan"
    assert run("plan", small_site, "--radius", "60", "--airspeed", "20", "--algorithm",
               "alternating", "-o", out).returncode == 0
    measured = run("fly", out, "--airspeed", "20", "--radius", "60", "--speedup", "400",
                   "--targets", small_site)
    assert measured.returncode == 0, measured.stderr
    names = [line.split("\t")[0] for line in measured.stdout.splitlines() if "\t" in line][1:]
    assert sorted(names) == sorted(f"line1-pylon{k:02d}" for k in range(1, 11))
    # The .plan carries the targets themselves: without --targets they are measured alike.
    bare = run("fly", out, "--airspeed", "20", "--radius", "60", "--speedup", "400")
    assert bare.returncode == 0, bare.stderr
    assert sorted(line for line in bare.stdout.splitlines() if "\t" in line) == \
        sorted(line for line in measured.stdout.splitlines() if "\t" in line)
    assert "--targets" not in bare.stderr


def test_a_px4_mission_is_flown_as_px4_navigates(tmp_path):
    """`fly` of a PX4 plan flies the PX4 model (NPFG, its waypoint switching, PX4 SITL's fixed
    wing: docs/px4-agreement.md) and says so; the same file flown with a tuned PX4's
    parameters uses them."""
    out = tmp_path / "px4.plan"
    targets = Path(__file__).parents[1] / "data" / "px4-sitl" / "t12" / "targets.csv"
    planned = run("plan", targets, "--radius", "80", "--alt", "60", "--airspeed", "18",
                  "--autopilot", "px4", "--home", "47.39774,8.54559", "-o", out)
    assert planned.returncode == 0, planned.stderr
    flown = run("fly", out, "--speedup", "0", "--json")
    assert flown.returncode == 0, flown.stderr
    assert "NPFG period 10 s" in flown.stderr
    summary = json.loads(flown.stdout)
    misses = [t["miss_m"] for t in summary["flight"]["targets"]]
    # the real PX4 flew this design: median 1.3 m, max 2.3 m
    assert len(misses) == 12 and max(misses) < 5.0
    params = tmp_path / "tuned.params"
    params.write_text("NPFG_PERIOD 20\n")
    tuned = run("fly", out, "--speedup", "0", "--vehicle-params", params)
    assert tuned.returncode == 0 and "NPFG period 20 s" in tuned.stdout, tuned.stderr
