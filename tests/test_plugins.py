"""First-party plugins (plugins/): discovered through their entry points, used through the CLI,
their files read back by real readers (fastkml; MAVSDK's QGroundControl importer); and a broken
plugin is listed and skipped."""

import json
import math
import re
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import shapely

from conftest import environment_with_distribution, make_mission
from dtsp_mission.export import exporter_for, read_mission

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")
SITE = os.path.join(EXAMPLES, "site-inspection.csv")


def run(*args, env=None):
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", *args], capture_output=True,
                          text=True, timeout=300, env=env)


def test_plugins_command_lists_builtins_and_first_party_plugins():
    result = run("plugins", "--json")
    assert result.returncode == 0, result.stderr
    records = {(r["group"], r["name"]): r for r in json.loads(result.stdout)}
    assert records[("exporters", "kml")]["distribution"].startswith("dtsp-mission-kml ")
    assert records[("exporters", "plan-fence")]["distribution"].startswith("dtsp-mission-fence ")
    assert records[("planners", "lanes")]["distribution"].startswith("dtsp-mission ")
    assert {("uploaders", "pymavlink"), ("commands", "plugins")} <= set(records)
    assert all(r["state"] == "ok" for r in records.values())
    table = run("plugins")
    assert table.returncode == 0 and "kml" in table.stdout and "(.fence.plan)" in table.stdout


@pytest.fixture(scope="module")
def site_files(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    result = run("plan", SITE, "--radius", "80", "--alt", "120", "--airspeed", "22", "--time-limit", "1",
                 "--design", "geometry",
                 "--max-items", "4000", "-o", str(out / "site.kml"), "-o", str(out / "site.fence.plan"),
                 "-o", str(out / "site.plan"))
    assert result.returncode == 0, result.stderr
    assert "wrote" in result.stdout and "site.kml" in result.stdout
    return out


def test_kml_is_valid_and_holds_the_path_targets_and_home(site_files):
    from fastkml import kml
    document = kml.KML.parse(str(site_files / "site.kml"))
    assert document.validate()
    root = document.features[0]
    folders = {f.name: f for f in root.features}
    assert set(folders) == {"Flight path", "Targets", "Home"}
    header = open(SITE).readline().strip().split(",")
    names = [dict(zip(header, line.split(",")))["name"] for line in open(SITE).read().splitlines()[1:]]
    targets = folders["Targets"].features
    assert sorted(p.name for p in targets) == sorted(names)
    # Every target placemark lies on the drawn path (sampled from the exact arcs).
    path = np.array(folders["Flight path"].features[0].geometry.coords)[:, :2]
    scale = np.array([math.cos(math.radians(path[0, 1])) * 111_320.0, 110_540.0])
    line = shapely.LineString(path * scale)
    for placemark in targets:
        point = np.array(placemark.geometry.coords)[0, :2] * scale
        assert line.distance(shapely.Point(point)) < 1.0, placemark.name
    visits = sorted(int(re.search(r"visit (\d+) of", p.description).group(1)) for p in targets)
    assert visits == list(range(1, len(targets) + 1))


def test_fenced_plan_is_imported_by_mavsdk_with_fence_and_rally(site_files, mavsdk_mission_raw):
    imported = mavsdk_mission_raw.import_qgroundcontrol_mission(str(site_files / "site.fence.plan"))
    plain = mavsdk_mission_raw.import_qgroundcontrol_mission(str(site_files / "site.plan"))
    assert len(imported.mission_items) == len(plain.mission_items)
    vertices = [i for i in imported.geofence_items if i.command == 5001]   # POLYGON_VERTEX_INCLUSION
    assert len(vertices) >= 3 and all(int(i.param1) == len(vertices) for i in vertices)
    rally = [i for i in imported.rally_items if i.command == 5100]         # NAV_RALLY_POINT
    assert len(rally) == 1
    # upload reads it as a mission like any .plan, and its fence and rally point as MAVSDK does
    fenced = read_mission(site_files / "site.fence.plan")
    assert fenced.items == read_mission(site_files / "site.plan").items
    ours = [(i.command, round(i.latitude_deg * 1e7), round(i.longitude_deg * 1e7), i.params[0])
            for i in fenced.fence]
    theirs = [(i.command, i.x, i.y, i.param1) for i in imported.geofence_items]
    assert ours == theirs
    assert [(i.command, round(i.latitude_deg * 1e7), round(i.longitude_deg * 1e7), i.altitude_m)
            for i in fenced.rally] == [(i.command, i.x, i.y, i.z) for i in imported.rally_items]


def test_fence_holds_the_whole_path_with_the_margin(tmp_path):
    from dtsp_mission_fence import fence_margin_m, fence_polygon_local
    mission = make_mission(count=60, rho_m=70.0)
    fence = shapely.Polygon(fence_polygon_local(mission))
    assert fence.is_valid and fence.exterior.is_ccw
    chain = mission.path.chain
    samples = chain.pose_at(np.linspace(0, chain.length_m, 20000))[:, :2]
    distances = shapely.distance(fence.exterior, shapely.points(samples))
    assert shapely.contains_xy(fence, samples[:, 0], samples[:, 1]).all()
    assert distances.min() >= fence_margin_m(mission)
    assert len(fence.exterior.coords) < 100
    written = exporter_for(tmp_path / "m.fence.plan").write(mission, tmp_path / "m.fence.plan")
    data = json.loads(written.read_text())
    assert data["rallyPoints"]["points"][0][2] == max(i.altitude_m for i in mission.items if i.has_position)


def test_a_broken_exporter_plugin_is_listed_and_skipped(tmp_path):
    env = environment_with_distribution(tmp_path, "broken-exporter", textwrap.dedent("""\
        [dtsp_mission.exporters]
        shapefile = no_such_module_anywhere:Exporter
        [dtsp_mission.planners]
        magic = json:dumps
        """))
    listing = run("plugins", env=env)
    assert listing.returncode == 0
    assert "shapefile" in listing.stdout and "broken-exporter 1.0" in listing.stdout
    assert "BROKEN: ModuleNotFoundError" in listing.stdout
    assert "BROKEN: TypeError" in listing.stdout and "2 broken plugin(s)" in listing.stderr
    planned = run("plan", SITE, "--radius", "80", "--max-items", "4000", "--time-limit", "1",
                  "--design", "geometry", "-o",
                  str(tmp_path / "m.plan"), env=env)
    assert planned.returncode == 0, planned.stderr
    assert (tmp_path / "m.plan").exists()
