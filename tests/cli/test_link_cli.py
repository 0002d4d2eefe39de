"""The `upload`, `fly`, `sim` and `plan --upload/--simulate` commands, end to end over
loopback UDP."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from conftest import free_udp_port, make_mission

from dtsp_mission.autopilot import Autopilot
from dtsp_mission.autopilot.navigation import Airframe
from dtsp_mission.cli.main import cli
from dtsp_mission.export import exporter_for
from dtsp_mission.autopilot.wire import differences, to_wire
from dtsp_mission.targets import read_targets

SITE = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "site-inspection.csv")


@pytest.fixture(scope="module")
def mission():
    return make_mission(8, 4, 80.0, span_m=1200.0, airspeed_m_s=20.0)


def run(*args):
    return CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)


@pytest.mark.parametrize("suffix,via", [(".plan", "pymavlink"), (".waypoints", "mavsdk")])
def test_upload_command_puts_the_file_on_the_vehicle(mission, tmp_path, start_vehicle, suffix, via):
    path = tmp_path / f"m{suffix}"
    exporter_for(path).write(mission, path)
    vehicle = start_vehicle(mission)
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}", "--via", via)
    assert result.exit_code == 0, result.output
    assert "holds exactly the planned mission" in result.output
    assert not differences(to_wire(mission.for_vehicle()), vehicle.mission, mission.autopilot)


def test_upload_command_errors(mission, tmp_path, start_vehicle):
    path = tmp_path / "m.plan"
    exporter_for(path).write(mission, path)
    vehicle = start_vehicle(mission, max_items=10)
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}")
    assert result.exit_code == 2 and "no room for" in result.output
    assert "holds no mission" in result.output
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{free_udp_port()}",
                 "--heartbeat-timeout", "1")
    assert result.exit_code == 2 and "no heartbeat" in result.output
    result = run("upload", tmp_path / "missing.plan", "--connect", "udpout:127.0.0.1:1")
    assert result.exit_code == 2 and "no such file" in result.output
    (tmp_path / "bad.plan").write_text("{}")
    result = run("upload", tmp_path / "bad.plan", "--connect", "udpout:127.0.0.1:1")
    assert result.exit_code == 2 and "not a valid QGroundControl plan" in result.output
    result = run("upload", tmp_path / "m.geojson", "--connect", "udpout:127.0.0.1:1")
    assert result.exit_code == 2
    # the home slot is counted the same way in every line: slots, never "items" for one, and
    # "items" for the other
    slots = len(to_wire(mission.for_vehicle()))
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}")
    assert f"({slots} mission slots)" in result.output and f"no room for {slots} mission slots" in result.output
    for link in ("/dev/ttyNOSUCH0,57600", "COM3,57600", "tcp:127.0.0.1:1"):     # nothing there
        result = run("upload", path, "--connect", link, "--heartbeat-timeout", "1")
        errors = [line for line in result.output.splitlines() if line.startswith("Error")]
        assert result.exit_code == 2 and len(errors) == 1 and "cannot open the connection" in errors[0] \
            and "Traceback" not in result.output, result.output
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}", "--timeout", "0")
    assert result.exit_code == 2 and "--timeout" in result.output and "above 0 and at most 86400 s" in result.output


def test_fly_command_reports_every_target(mission, tmp_path):
    path = tmp_path / "m.plan"
    exporter_for(path).write(mission, path)
    result = run("fly", path, "--radius", 80, "--airspeed", 20, "--speedup", 400)
    assert result.exit_code == 0, result.output
    assert "simulated flight completed" in result.output
    stored = exporter_for(path).read(path)
    rows = [re.search(rf"^{re.escape(target.name)}\t([\d.]+)\t", result.output, re.M).group(1)
            for target in stored.targets]
    # What fly prints is the flight the model makes of the stored mission with the aircraft
    # the options describe (the link and the report, not the model, are under test here).
    from dtsp_mission.autopilot.navigation import closest_approach_m
    from dtsp_mission.sim.fly import targets_in
    from dtsp_mission.sim.predict import predict_flight
    offline = predict_flight(stored, Airframe.turning_at(80.0, 20.0), after_last_s=30.0)
    aims = targets_in(stored)          # the targets the .plan carries, in visiting order
    assert aims.names == tuple(t.name for t in stored.targets)
    expected = closest_approach_m(offline.track[:, 1:3],
                                  offline.frame.to_local(aims.latitudes_deg, aims.longitudes_deg))
    assert len(rows) == 8 and max(abs(float(r) - e) for r, e in zip(rows, expected)) < 1.0
    strict = run("fly", path, "--radius", 80, "--airspeed", 20, "--speedup", 400,
                 "--max-miss", 0.001)
    assert strict.exit_code == 1 and "missed by" in strict.output


def test_plan_simulate_and_upload_in_one_go(tmp_path, start_vehicle, mission):
    vehicle = start_vehicle(mission, max_items=4000)   # with SD storage: the site needs ~1,800 items
    out = tmp_path / "site.plan"              # by geometry: the guidance design is tested elsewhere
    result = run("plan", SITE, "--radius", 80, "--alt", 120, "--airspeed", 22, "--max-items",
                 4000, "--time-limit", 1, "--design", "geometry", "-o", out,
                 "--upload", f"udpout:127.0.0.1:{vehicle.port}")
    assert result.exit_code == 0, result.output
    assert out.exists() and "holds exactly the planned mission" in result.output
    assert len(vehicle.mission) == len(exporter_for(out).read(out).items) + 1


def test_sim_command_runs_as_a_process_and_accepts_uploads(mission, tmp_path):
    """Over TCP, as to ArduPilot SITL (tcp:127.0.0.1:5760): the same link syntax both sides."""
    import socket
    path = tmp_path / "m.plan"
    exporter_for(path).write(mission, path)
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    process = subprocess.Popen(
        [sys.executable, "-m", "dtsp_mission.cli", "sim", "--listen", f"tcp:127.0.0.1:{port}",
         "--home", f"{mission.home.latitude_deg},{mission.home.longitude_deg}",
         "--radius", "80", "--airspeed", "20", "--speedup", "400", "--autostart"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"})
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(iter(process.stdout.readline, "")),
                              daemon=True)
    reader.start()
    try:
        time.sleep(1.5)
        result = run("upload", path, "--connect", f"tcp:127.0.0.1:{port}")
        assert result.exit_code == 0, result.output
        deadline = time.monotonic() + 60    # about 250 s of flight at 400x: 1 s unloaded
        while time.monotonic() < deadline and not any("mission complete" in l for l in lines):
            time.sleep(0.2)
    finally:
        process.terminate()
        process.wait(timeout=10)
        reader.join(timeout=10)
    output = "".join(lines)
    assert f"connect with tcp:127.0.0.1:{port}" in output
    assert f"mission received: {len(to_wire(mission.for_vehicle()))} items" in output
    assert "mission complete" in output


def test_upload_a_tour_json_builds_the_mission_with_plan_options(tmp_path, start_vehicle, mission):
    tour = tmp_path / "tour.json"
    result = run("plan", SITE, "--radius", 80, "--max-items", 4000, "--time-limit", 1, "-o", tour)
    assert result.exit_code == 0, result.output
    vehicle = start_vehicle(mission, max_items=4000, autopilot=Autopilot.PX4)   # with SD storage
    result = run("upload", tour, "--connect", f"udpout:127.0.0.1:{vehicle.port}",
                 "--max-items", 4000, "--alt", 150, "--autopilot", "px4")
    assert result.exit_code == 0, result.output
    assert "holds exactly the planned mission" in result.output
    assert vehicle.mission[0].command == 22 and vehicle.mission[-1].command == 21   # PX4: takeoff first, land last
    assert {item.z for item in vehicle.mission if item.command == 16 and item.param2 > 0} == {150.0}
    bare = tmp_path / "bare.json"
    assert run("plan", tmp_path / "local.csv", "--radius", 80).exit_code == 2   # missing file
    (tmp_path / "local.csv").write_text("x,y\n0,0\n500,0\n0,500\n")
    assert run("plan", tmp_path / "local.csv", "--radius", 80, "-o", bare).exit_code == 0
    result = run("upload", bare, "--connect", f"udpout:127.0.0.1:{vehicle.port}")
    assert result.exit_code == 2 and "no frame origin" in result.output


@pytest.mark.heavy(seconds=60)
def test_a_site_too_big_for_the_vehicle_is_flown_as_sorties_it_accepts(tmp_path, start_vehicle):
    """The first 100 targets of the bundled site do not fit a vehicle holding 60 items; plan
    splits them, the simulated vehicle with that real capacity accepts each sortie, and each
    sortie flies its targets."""
    capacity = 60
    site = tmp_path / "site100.csv"
    site.write_text("\n".join(Path(SITE).read_text().splitlines()[:101]) + "\n")
    out = tmp_path / "site.plan"
    result = run("plan", site, "--radius", 80, "--alt", 120, "--airspeed", 22, "--home",
                 "46.8155,6.9618", "--max-items", capacity, "-o", out, "--time-limit", 0)
    assert result.exit_code == 0, result.output
    count = int(re.search(r"split into (\d+) sorties", result.output).group(1))
    files = [tmp_path / f"site-{k}.plan" for k in range(1, count + 1)]
    assert all(f.exists() for f in files) and not out.exists()
    missions = [exporter_for(f).read(f) for f in files]
    vehicle = start_vehicle(missions[0], max_items=capacity, airframe=Airframe.turning_at(80.0, 22.0))
    flown = []
    for path, sortie in zip(files, missions):
        assert len(sortie.items) + 1 <= capacity
        result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}")
        assert result.exit_code == 0, result.output
        assert "holds exactly the planned mission" in result.output
        assert len(vehicle.mission) == len(sortie.items) + 1
        result = run("fly", path, "--radius", 80, "--airspeed", 22, "--speedup", 1000,
                     "--max-miss", 1000)
        assert result.exit_code == 0, result.output
        assert "simulated flight completed" in result.output
        flown += [name for name in sortie.targets
                  if re.search(rf"^{re.escape(name.name)}\t[\d.]+\t", result.output, re.M)]
    # every target in exactly one sortie (the .plan carries its own), each flown
    assert count >= 2 and sorted(t.name for t in flown) == sorted(read_targets(site).names)


def test_upload_and_fly_print_one_json_summary(mission, tmp_path, start_vehicle):
    import json
    path = tmp_path / "m.plan"
    exporter_for(path).write(mission, path)
    vehicle = start_vehicle(mission)
    result = CliRunner().invoke(cli, ["upload", str(path), "--connect", f"udpout:127.0.0.1:{vehicle.port}",
                                      "--json", "-q"], catch_exceptions=False)
    assert result.exit_code == 0 and result.stderr == ""
    upload = json.loads(result.stdout)["upload"]
    assert upload["verified"] and upload["mission_slots"] == len(to_wire(mission.for_vehicle()))
    result = CliRunner().invoke(cli, ["fly", str(path), "--radius", "80", "--airspeed", "20",
                                      "--speedup", "400", "--json"], catch_exceptions=False)
    flight = json.loads(result.stdout)["flight"]
    assert result.exit_code == 0 and flight["completed"] and len(flight["targets"]) == 8
    assert "simulated flight completed" in result.stderr


def test_upload_of_a_fenced_plan_sends_the_fence_and_rally_point_and_reads_them_back(
        mission, tmp_path, start_vehicle):
    from dtsp_mission.autopilot.wire import other_differences, other_to_wire
    from dtsp_mission.export import read_mission
    path = tmp_path / "m.fence.plan"
    exporter_for(path).write(mission, path)
    planned = read_mission(path)
    vehicle = start_vehicle(mission)
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}")
    assert result.exit_code == 0, result.output
    assert f"geofence: {len(planned.fence)} items sent, downloaded back equal" in result.output
    assert "rally points: 1 items sent, downloaded back equal" in result.output
    assert other_differences(other_to_wire(planned.fence, 1), vehicle.fence) == []
    assert [(i.command, i.z) for i in vehicle.rally] == [(5100, planned.rally[0].altitude_m)]
    # a vehicle without fence support: the mission is there, the refused part is named
    bare = start_vehicle(mission, fence_support=False)
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{bare.port}")
    assert result.exit_code == 2, result.output
    assert "the geofence were not accepted: the vehicle does not keep them" in result.output
    assert "the mission items are on the vehicle and verified" in result.output
    assert bare.uploads == 1 and bare.fence == []
    # MAVSDK's uploader carries mission items only: said before anything is claimed
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}", "--via", "mavsdk")
    assert result.exit_code == 2 and "mavsdk uploader cannot send" in result.output


def test_a_waypoints_file_sent_to_px4_is_said_to_be_sent_as_a_px4_mission(mission, tmp_path,
                                                                          start_vehicle):
    path = tmp_path / "m.waypoints"
    exporter_for(path).write(mission, path)
    vehicle = start_vehicle(mission, autopilot=Autopilot.PX4)
    result = run("upload", path, "--connect", f"udpout:127.0.0.1:{vehicle.port}")
    assert result.exit_code == 0, result.output
    assert "does not say its autopilot" in result.output and "PX4" in result.output
    assert "(and a home slot if the vehicle is ArduPilot)" in result.output
    assert vehicle.mission[0].command == 22          # no home slot: take-off first


def test_fly_flies_the_aircraft_the_plan_was_designed_for(tmp_path):
    """A .plan records the navigation parameters it was designed for; `fly` flies them
    without being told (here a tuned NAVL1_PERIOD 18), says when an option flies another
    aircraft (--radius limits the bank), and `upload` compares the vehicle with them."""
    parm = tmp_path / "tuned.parm"
    parm.write_text("NAVL1_PERIOD 18\nWP_RADIUS 60\n")
    csv = tmp_path / "t.csv"
    csv.write_text("lat,lon\n46.80,6.950\n46.805,6.955\n46.801,6.962\n46.796,6.957\n")
    plan = tmp_path / "m.plan"
    done = subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "plan", str(csv), "--radius",
                           "80", "--alt", "100", "--airspeed", "22", "--vehicle-params", str(parm),
                           "-q", "-o", str(plan)], capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stderr
    stored = exporter_for(plan).read(plan)
    assert stored.designed_for.NAVL1_PERIOD == 18 and stored.designed_for.WP_RADIUS == 60
    flown = subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "fly", str(plan),
                            "--speedup", "400"], capture_output=True, text=True, timeout=240)
    assert flown.returncode == 0, flown.stderr
    assert "L1 period 18 s" in flown.stdout and "another aircraft" not in flown.stderr
    other = subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "fly", str(plan),
                            "--speedup", "400", "--radius", "80"],
                           capture_output=True, text=True, timeout=240)
    assert other.returncode == 0, other.stderr
    assert "flying another aircraft than the plan was designed for: ROLL_LIMIT_DEG" in other.stderr
    assert "(designed for 65)" in other.stderr


def test_fly_as_fast_as_possible_loses_no_position_report(mission, tmp_path):
    """--speedup 0 is paced to what the link carries: every report the vehicle sends arrives,
    and the misses are those of the whole flight."""
    from dtsp_mission.sim.fly import fly_mission, planned_targets
    check = fly_mission(mission.for_vehicle(), planned_targets(mission),
                        Airframe.from_parameters(airspeed_m_s=20.0), speedup=0.0)
    assert check.completed and check.lost_reports == 0
    assert check.samples >= 10 * check.flight_time_s * 0.95     # 10 Hz of the whole flight


def test_lost_position_reports_are_counted():
    from dtsp_mission.sim.fly import lost_reports
    assert lost_reports([0.0, 0.1, 0.2, 0.3], 10.0) == 0
    assert lost_reports([0.0, 0.1, 0.5, 0.6, 1.0], 10.0) == 3 + 3
    assert lost_reports([], 10.0) == 0


def test_plan_reads_the_vehicle_first_and_designs_for_it(tmp_path, start_vehicle):
    """--from-vehicle reads the navigation parameters, home and wind estimate of the vehicle
    and designs for them (each value reported); --upload does the same, so the upload finds
    nothing that differs; a vehicle that is not there is an error before any design."""
    import json
    from dataclasses import replace as replaced

    from dtsp_mission.autopilot.navigation import Wind
    from dtsp_mission.autopilot.parameters import ARDUPLANE_DEFAULTS
    from dtsp_mission.mission.model import Home
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    site = tmp_path / "s8.csv"
    site.write_text("\n".join((root / "examples" / "site-inspection.csv").read_text()
                              .splitlines()[:9]) + "\n")
    home = Home(46.8075, 6.9420, 612.0)
    tuned = replaced(ARDUPLANE_DEFAULTS, NAVL1_PERIOD=17.0, WP_RADIUS=60.0)
    vehicle = start_vehicle(VehicleMissionAt(home), parameters=tuned, wind=Wind(4.0, 250.0))
    link = f"udpout:127.0.0.1:{vehicle.port}"
    result = run("plan", site, "--radius", 80, "--time-limit", 1, "--from-vehicle", link,
                 "-o", tmp_path / "v.plan", "--json")
    assert result.exit_code == 0, result.output
    read = json.loads(result.stdout)["vehicle_read"]
    assert read["parameters"]["NAVL1_PERIOD"] == 17.0 and read["parameters"]["WP_RADIUS"] == 60.0
    assert read["home_deg"] == pytest.approx([46.8075, 6.9420]) and read["home_amsl_m"] == pytest.approx(612.0)
    assert read["wind"] == pytest.approx([4.0, 250.0], abs=0.05)
    assert "read from the vehicle at" in result.stderr and "NAVL1_PERIOD 17" in result.stderr
    plan = json.loads((tmp_path / "v.plan").read_text())
    assert plan["dtspMission"]["aircraft"]["parameters"]["NAVL1_PERIOD"] == 17.0
    assert plan["mission"]["plannedHomePosition"] == pytest.approx([46.8075, 6.9420, 612.0])
    assert (plan["dtspMission"]["designWind"]["speed_m_s"], plan["dtspMission"]["designWind"]["from_deg"]) == (4.0, 250.0)
    assert vehicle.uploads == 0
    uploaded = run("plan", site, "--radius", 80, "--time-limit", 1, "--upload", link, "--json")
    assert uploaded.exit_code == 0, uploaded.output
    assert vehicle.uploads == 1 and "warning" not in uploaded.stderr
    missing = run("plan", site, "--radius", 80, "--time-limit", 1, "--from-vehicle",
                  "udpout:127.0.0.1:9", "-o", tmp_path / "x.plan")
    assert missing.exit_code == 2 and "reading the vehicle before the design" in missing.output
    assert "no heartbeat" in missing.output and not (tmp_path / "x.plan").exists()


class VehicleMissionAt:
    """What start_vehicle needs of a mission: its home and autopilot."""

    def __init__(self, home):
        from dtsp_mission.autopilot import Autopilot
        self.home, self.autopilot = home, Autopilot.ARDUPILOTMEGA


#: ``python -c`` this, then the command's arguments: ``dtsp-mission`` with Ctrl-C raising
#: KeyboardInterrupt whatever SIGINT's disposition was when the process started.
_WITH_CTRL_C = ("import runpy, signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
                "sys.argv[0] = 'dtsp-mission'; runpy.run_module('dtsp_mission.cli', run_name='__main__')")


def test_ctrl_c_during_an_upload_says_what_the_vehicle_may_hold(tmp_path, start_vehicle):
    """SIGINT while the items go out (a slow link: every datagram delayed): exit 130 and what
    an ArduPilot holds then, not click's bare "Aborted!"."""
    import signal

    from dtsp_mission.sim.fault_proxy import Faults, FaultProxy
    big = make_mission(60, 8, 80.0, span_m=3000.0, airspeed_m_s=20.0)
    path = tmp_path / "big.plan"
    exporter_for(path).write(big, path)
    vehicle = start_vehicle(big)
    with FaultProxy(("127.0.0.1", vehicle.port), Faults(delay_s=0.08, seed=1)) as proxy:
        # The command as a terminal runs it, Ctrl-C delivered: a shell that starts the suite in
        # the background ignores SIGINT for it, and every child inherits that (Python then
        # keeps ignoring it), so the child takes the interpreter's own handler back first.
        process = subprocess.Popen([sys.executable, "-c", _WITH_CTRL_C, "upload", str(path),
                                    "--connect", f"udpout:127.0.0.1:{proxy.port}"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 60
        while vehicle.server.counts["requests_sent"] < 5 and time.monotonic() < deadline:
            time.sleep(0.05)
        requested = vehicle.server.counts["requests_sent"]
        process.send_signal(signal.SIGINT)
        try:
            out, err = process.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            process.kill()
            out, err = process.communicate()
            pytest.fail(f"no exit within 60 s of SIGINT (sent after {requested} item requests, "
                        f"{vehicle.server.counts['requests_sent']} by the kill): {out!r} {err!r}")
    assert process.returncode == 130, (out, err)
    assert "Traceback" not in err and "Aborted!" not in err
    assert re.search(r"interrupted after \d+ of \d+ items were sent: ArduPilot writes items", err), err
