"""``dtsp-mission plan`` from geodetic inputs to mission files, end to end."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from pymavlink import mavwp

from conftest import assert_valid_tour
from dtsp_mission.export.qgc_plan import plan_rule_violations
from dtsp_mission.tour import read_tour

EXAMPLES = Path(__file__).parents[2] / "examples"
SITE = EXAMPLES / "site-inspection.csv"
AREA = EXAMPLES / "survey-area.geojson"


def run(*arguments):
    """``dtsp-mission plan`` with the arguments; auto's improvement budget is 1 s unless given
    (these tests are about missions, the improver is tested on its own)."""
    arguments = [*map(str, arguments)]
    if "--time-limit" not in arguments:
        arguments += ["--time-limit", "1"]
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "plan", *arguments],
                          capture_output=True, text=True, timeout=900)


@pytest.mark.heavy(seconds=35)
def test_site_example_to_every_format_and_a_plot_designed_for_a_stock_ardupilot(tmp_path):
    """The README's quick start (more formats): the guidance design fits the site in a stock
    ArduPlane, one waypoint per target, and the report says what it predicts."""
    outputs = [tmp_path / name for name in ("m.plan", "m.waypoints", "m.geojson", "m.json")]
    arguments = [SITE, "--radius", "80", "--alt", "120", "--airspeed", "22",   # the stock 655 slots
                 "--plot", tmp_path / "m.png"]
    for output in outputs:
        arguments += ["-o", output]
    result = run(*arguments)
    assert result.returncode == 0, result.stderr
    assert "272 targets" in result.stdout and "mission (ArduPilot)" in result.stdout
    assert "min at 22 m/s" in result.stdout and "home (launch) not given" in result.stderr
    plan = json.loads(outputs[0].read_text())
    assert plan_rule_violations(plan) == []
    items = plan["mission"]["items"]
    assert items[0]["command"] == 22 and items[-1]["command"] == 20
    loader = mavwp.MAVWPLoader()
    assert loader.load(str(outputs[1])) == len(items) + 1
    assert len([f for f in json.loads(outputs[2].read_text())["features"]
                if f["properties"]["kind"] == "target"]) == 272
    assert_valid_tour(read_tour(outputs[3]))
    assert (tmp_path / "m.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The names and altitudes from the CSV reach the files.
    targets = [f["properties"] for f in json.loads(outputs[2].read_text())["features"]
               if f["properties"]["kind"] == "target"]
    assert {t["name"] for t in targets} >= {"line1-pylon01", "tank1-01", "fence-01"}
    assert {t["altitude_m"] for t in targets} == {90.0, 70.0, 60.0}
    assert len(items) + 1 <= 655
    # one waypoint per target, plus one per target passed a second time (revisits carry the
    # targets' acceptance radius too)
    again = re.search(r"(\d+) passing a target again", result.stdout)
    revisits = int(again.group(1)) if again else 0
    assert len([i for i in items if i["command"] == 16 and i["params"][1] > 0]) == 272 + revisits
    assert "designed for the autopilot's guidance" in result.stdout
    assert "predicted flight" in result.stdout and "km of exact path" in result.stdout
    # the slow zones the report counts are the DO_CHANGE_SPEED items below the airspeed
    zones = re.search(r"(\d+) slow zones \(DO_CHANGE_SPEED to ([\d.]+) m/s and back\)", result.stdout)
    slow = [i["params"][1] for i in items if i["command"] == 178 and i["params"][1] < 22.0]
    assert (int(zones.group(1)) if zones else 0) == len(slow)
    assert not zones or float(zones.group(2)) == min(slow) == 16.5
    # what could not be held is named, with the design limit and the margin it keeps
    if re.search(r"[1-9]\d* of 272 targets are predicted beyond", result.stderr + result.stdout):
        assert re.search(r"\d+ of 272 targets are predicted beyond 3.5 m \(--max-miss 5 m less "
                         r"the model's margin of 1.5 m\) in the forecast wind, or beyond --max-miss in the "
                         r"others: "
                         r"\S+ \(\d", result.stderr)
    else:                                            # and the summary claims none
        assert "of 272 targets are predicted beyond" not in result.stderr


@pytest.mark.heavy(seconds=19)
def test_geometry_design_over_the_stock_budget_is_split_into_sorties_and_a_coarser_tolerance_fits(tmp_path):
    result = run(SITE, "--radius", "80", "--design", "geometry", "--airspeed", "22",
                 "--max-items", "300", "-o", tmp_path / "m.plan", "-o", tmp_path / "tour.json")
    assert result.returncode == 0, result.stderr
    assert re.search(r"as one mission it needs \d+ items \(at least\) but the vehicle holds 300", result.stdout)
    count = int(re.search(r"split into (\d+) sorties", result.stdout).group(1))
    assert count >= 2 and not (tmp_path / "m.plan").exists()
    targets = 0
    for k in range(1, count + 1):
        assert f"sortie {k}:" in result.stdout
        items = json.loads((tmp_path / f"m-{k}.plan").read_text())["mission"]["items"]
        assert len(items) + 1 <= 300
        assert items[0]["command"] == 22 and items[-1]["command"] == 20     # take-off ... RTL
        targets += sum(i["command"] == 16 and i["params"][1] > 0 for i in items)
    assert targets == 272                    # every target in exactly one sortie
    assert not (tmp_path / f"m-{count + 1}.plan").exists()
    # The tour file is the whole tour, placed on the earth.
    tour = json.loads((tmp_path / "tour.json").read_text())
    assert "origin" in json.dumps(tour)
    result = run(SITE, "--radius", "80", "--design", "geometry", "--tolerance", "8", "-o",
                 tmp_path / "m.plan")
    assert result.returncode == 0, result.stderr
    assert len(json.loads((tmp_path / "m.plan").read_text())["mission"]["items"]) + 1 <= 655


def test_max_items_beyond_mavlink_is_refused(tmp_path):
    result = run(SITE, "--radius", "80", "--max-items", "70000", "-o", tmp_path / "m.plan")
    assert result.returncode == 2 and "--max-items" in result.stderr and "to 65,535 mission items" in result.stderr


@pytest.mark.heavy(seconds=20)
def test_random_targets_in_a_polygon_are_seeded(tmp_path):
    first, second, other = (tmp_path / f"{n}.waypoints" for n in ("a", "b", "c"))
    common = ["--random", "60", "--area", AREA, "--airspeed", "20", "--max-bank", "30",
              "--autopilot", "px4", "--max-items", "3000"]
    assert run(*common, "--seed", "4", "-o", first).returncode == 0
    assert run(*common, "--seed", "4", "-o", second).returncode == 0
    result = run(*common, "--seed", "5", "-o", other)
    assert result.returncode == 0, result.stderr
    # the radius the flight model's aircraft turns at that bank: 20^2 / (0.73 g tan 30 deg)
    assert "rho 102.5 m: the aircraft's turn at 20 m/s and 30 deg bank" in result.stdout
    assert first.read_text() == second.read_text() != other.read_text()
    assert "\t21\t" in first.read_text().splitlines()[-1]      # PX4 default: a landing


def test_geojson_targets_and_local_csv_with_origin(tmp_path):
    features = [{"type": "Feature", "properties": {"name": f"p{i}", "alt": 80 + i},
                 "geometry": {"type": "Point", "coordinates": [6.95 + 0.004 * i, 46.8 + 0.003 * (i % 3)]}}
                for i in range(8)]
    source = tmp_path / "t.geojson"
    source.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    result = run(source, "--radius", "60", "--return", "land", "--max-items", "2000",
                 "-o", tmp_path / "g.plan")
    assert result.returncode == 0, result.stderr
    items = json.loads((tmp_path / "g.plan").read_text())["mission"]["items"]
    assert [i["command"] for i in items].count(189) == 1 and items[-1]["command"] == 21
    local = tmp_path / "local.csv"
    local.write_text("x,y,name\n0,0,a\n800,100,b\n400,900,c\n-300,500,d\n")
    result = run(local, "--radius", "60", "--origin", "46.8,6.95", "--max-items", "2000",
                 "-o", tmp_path / "l.geojson")
    assert result.returncode == 0, result.stderr
    names = {f["properties"].get("name") for f in json.loads((tmp_path / "l.geojson").read_text())["features"]}
    assert {"a", "b", "c", "d"} <= names


def test_vehicle_options_must_be_complete(tmp_path):
    result = run(SITE, "--max-bank", "30", "-o", tmp_path / "m.json")
    assert result.returncode == 2 and "--max-bank needs --airspeed" in result.stderr
    result = run(SITE, "-o", tmp_path / "m.json")
    assert result.returncode == 2 and "give the turn radius" in result.stderr
    result = run(SITE, "--radius", "80", "--airspeed", "20", "--max-bank", "30")
    assert result.returncode == 2 and "not both" in result.stderr


def test_a_tour_only_output_never_fails_on_the_mission_budget(tmp_path):
    out = tmp_path / "tour.json"
    result = run(SITE, "--radius", "80", "--max-items", "50", "-o", out)
    assert result.returncode == 0, result.stderr
    assert "as one mission this would not fit the vehicle" in result.stderr
    tour = json.loads(out.read_text())
    assert "origin" in json.dumps(tour) and len(tour["targets"]) == 272


def test_a_site_across_the_antimeridian_gives_a_geojson_line_cut_there(tmp_path):
    """RFC 7946 3.1.9: the flight path is a MultiLineString whose parts meet at +-180 deg;
    no segment jumps across the map."""
    import json
    import subprocess
    import sys

    import shapely.geometry
    targets = tmp_path / "fiji.csv"
    targets.write_text("lat,lon\n-16.50,179.990\n-16.51,-179.995\n-16.505,179.985\n-16.49,-179.99\n")
    out = tmp_path / "m.geojson"
    result = subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "plan", str(targets),
                             "--radius", "80", "-o", str(out), "--time-limit", "0"],
                            capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr
    geometry = json.loads(out.read_text())["features"][0]["geometry"]
    assert geometry["type"] == "MultiLineString" and len(geometry["coordinates"]) >= 2
    line = shapely.geometry.shape(geometry)
    for part in geometry["coordinates"]:
        longitudes = [p[0] for p in part]
        assert max(abs(a - b) for a, b in zip(longitudes, longitudes[1:])) < 1.0
    ends = [part[-1] for part in geometry["coordinates"][:-1]]
    starts = [part[0] for part in geometry["coordinates"][1:]]
    assert all(abs(e[0]) == 180.0 and s[0] == -e[0] and s[1] == e[1] for e, s in zip(ends, starts))
    assert line.is_valid


def test_sanity_checks_refuse_or_warn_with_a_clear_message(tmp_path):
    """A radius the aircraft cannot bank for, an altitude no fixed wing flies, --endurance
    without a speed: refused (exit 2); a home far from every target: a note."""
    targets = tmp_path / "t.csv"
    targets.write_text("lat,lon\n46.80,6.94\n46.81,6.95\n46.805,6.955\n")
    steep = run(targets, "--radius", 5, "--airspeed", 22)
    # the smallest radius named is the one the flight model flies: v^2 / (0.70 g tan 65 deg),
    # v = 22 m/s + 1 m/s x (1 / cos 65 deg - 1), the airspeed it flies at that bank
    assert steep.returncode == 2 and "cannot turn at 5 m: at 22 m/s with a roll limit of 65 deg" \
        in steep.stderr and "no tighter than 38 m" in steep.stderr
    assert run(targets, "--radius", 37, "--airspeed", 22, "-o", tmp_path / "t.json").returncode == 2
    assert run(targets, "--radius", 38, "--airspeed", 22, "-o", tmp_path / "t.json").returncode == 0
    high = run(targets, "--radius", 80, "--alt", 50000)
    assert high.returncode == 2 and "--alt" in high.stderr and "at most 10000 m" in high.stderr
    assert "needs --airspeed" in run(targets, "--radius", 80, "--endurance", 10).stderr
    far = run(targets, "--radius", 80, "--home", "46.5,6.5", "-o", tmp_path / "far.plan",
              "--time-limit", 0)
    assert far.returncode == 0 and "home is 47.4 km from the nearest target: is --home right?" in far.stderr


@pytest.mark.heavy(seconds=19)
def test_a_flight_beyond_the_endurance_is_split_into_sorties_that_each_fit(tmp_path):
    rng = np.random.default_rng(3)
    targets = tmp_path / "t.csv"
    rows = [f"{46.8 + dy / 111_000:.6f},{6.95 + dx / 76_000:.6f}"
            for dx, dy in rng.uniform(-2000, 2000, (30, 2))]
    targets.write_text("lat,lon\n" + "\n".join(rows) + "\n")
    out = tmp_path / "site.plan"
    result = run(targets, "--radius", 80, "--airspeed", 22, "--endurance", 12, "-o", out,
                 "--time-limit", 0.2, "--json", "-q")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["flight_time_s"] > 12 * 60            # as one mission it would not do
    assert len(summary["sorties"]) >= 2 and sum(s["targets"] for s in summary["sorties"]) == 30
    assert all(s["flight_time_s"] <= 12 * 60 for s in summary["sorties"])
    assert [Path(f).name for f in summary["files"]] == [f"site-{k}.plan" for k in
                                                        range(1, len(summary["sorties"]) + 1)]


def test_the_plot_shows_direction_visits_take_off_return_and_scale(tmp_path):
    """SVG keeps its text as text, so what an operator reads can be checked: visit numbers,
    take-off, the return, north and a scale bar, the legend; PDF by its extension."""
    targets = tmp_path / "t.csv"
    targets.write_text("lat,lon\n46.80,6.94\n46.81,6.95\n46.805,6.955\n46.79,6.96\n")
    svg, pdf = tmp_path / "m.svg", tmp_path / "m.pdf"
    for picture in (svg, pdf):
        result = run(targets, "--radius", 80, "--airspeed", 22, "-o", tmp_path / "m.plan",
                     "--plot", picture, "--time-limit", 0)
        assert result.returncode == 0, result.stderr
    text = svg.read_text()
    for label in (">1<", ">4<", ">take-off<", ">N<", "return to home", "numbered in visiting order",
                  "from take-off to the return"):
        assert label in text, label
    assert re.search(r">\d+ (m|km)<", text)                       # the scale bar
    assert pdf.read_bytes()[:4] == b"%PDF"


def test_plan_in_a_forecast_wind_reports_the_tour_for_that_wind_and_the_models_flight_time(tmp_path):
    """--wind: the report names the tour flown in that wind and the flight against it; the
    JSON summary has both times, the flight's the model's in that wind."""
    rng = np.random.default_rng(11)
    site = tmp_path / "site.csv"
    site.write_text("name,lat,lon\n" + "".join(
        f"t{k},{47.40 + 0.01 * rng.random():.7f},{8.50 + 0.015 * rng.random():.7f}\n"
        for k in range(15)))
    result = run(site, "--radius", "80", "--alt", "120", "--airspeed", "22", "--wind", "6@270",
                 "-o", tmp_path / "m.plan", "--json")
    assert result.returncode == 0, result.stderr
    assert "tour in the forecast wind:" in result.stderr
    assert "in a wind of 6 m/s from 270 deg (the model's time" in result.stderr
    summary = json.loads(result.stdout)
    assert summary["wind_tour_time_s"] > 0
    assert summary["wind_tour_air_length_m"] == pytest.approx(22 * summary["wind_tour_time_s"])
    assert (summary["flight_length_m"] / 28 < summary["flight_time_s"]
            < summary["flight_length_m"] / 16)


def test_max_aim_offset_keeps_each_target_s_waypoint_that_close(tmp_path):
    """``--max-aim-offset``: every target has a waypoint within the cap (its own, aimed no
    farther); without it the design aims some farther."""
    from dtsp_mission.export import read_mission
    from dtsp_mission.frame import LocalFrame
    from dtsp_mission.targets import read_targets
    targets_file = tmp_path / "t.csv"
    targets_file.write_text("\n".join(SITE.read_text().splitlines()[:31]) + "\n")
    targets = read_targets(str(targets_file))

    def nearest_waypoint_m(*options) -> np.ndarray:
        out = tmp_path / "m.plan"
        result = run(str(targets_file), "--radius", "80", "--airspeed", "22", *options, "-o", str(out))
        assert result.returncode == 0, result.stderr
        mission = read_mission(str(out), None)
        frame = LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg)
        waypoints = [i for i in mission.items if i.command == 16]
        at = frame.to_local(np.array([i.latitude_deg for i in waypoints]),
                            np.array([i.longitude_deg for i in waypoints]))
        points = frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
        return np.array([np.hypot(*(at - p).T).min() for p in points])

    assert nearest_waypoint_m().max() > 3.0
    assert nearest_waypoint_m("--max-aim-offset", "3").max() <= 3.0 + 0.02
