"""``plan --map``: one self-contained interactive HTML page (Bokeh, its JavaScript embedded) with
the targets coloured by the predicted miss, the planned path, the mission items in order,
home, the geofence.  No headless browser is installed here, so the page is checked by its
content: the document Bokeh embeds is parsed and its data compared with the plan's."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run(*arguments):
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", *map(str, arguments)],
                          capture_output=True, text=True, timeout=180)


def _columns(document) -> list[dict]:
    """Every ColumnDataSource's data in a serialized Bokeh document, as {column: values}."""
    found = []

    def walk(node):
        if isinstance(node, dict):
            if node.get("name") == "ColumnDataSource" or node.get("type") == "object" and \
                    node.get("name") == "ColumnDataSource":
                data = node.get("attributes", {}).get("data", {})
                entries = data.get("entries", []) if isinstance(data, dict) else []
                found.append({key: value for key, value in entries})
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)
    walk(document)
    return found


def test_the_map_holds_the_mission_and_needs_nothing_but_tiles(tmp_path):
    targets = tmp_path / "s8.csv"
    targets.write_text("\n".join((ROOT / "examples" / "site-inspection.csv").read_text()
                                 .splitlines()[:9]) + "\n")
    made = run("plan", targets, "--radius", 80, "--time-limit", 1, "-o", tmp_path / "m.fence.plan",
               "--map", tmp_path / "m.html", "--json")
    assert made.returncode == 0, made.stderr
    summary = json.loads(made.stdout)
    page = (tmp_path / "m.html").read_text()
    assert "<script src=" not in page                     # BokehJS is in the page itself
    assert "tile.openstreetmap.org/{z}/{x}/{y}.png" in page
    documents = re.findall(r'<script type="application/json" id="[^"]+">\s*(.*?)\s*</script>',
                           page, re.S)
    assert len(documents) == 1
    columns = _columns(json.loads(documents[0]))
    target_columns = [c for c in columns if "miss_text" in c]
    assert len(target_columns) == 1
    shown = target_columns[0]
    names = [line.split(",")[3] for line in targets.read_text().splitlines()[1:]]
    assert sorted(shown["name"]) == sorted(names)
    assert shown["miss_text"] == [f"{m:.1f} m" for m in summary["predicted_miss_m"]]
    plan = json.loads((tmp_path / "m.fence.plan").read_text())
    item_columns = [c for c in columns if "command" in c and "role" in c]
    assert len(item_columns) == 1
    positioned = [k for k, item in enumerate(plan["mission"]["items"], start=1)
                  if item["command"] < 100 and item["frame"] != 2]
    assert item_columns[0]["item"] == positioned          # the items, in order
    assert "geofence" in page and "predicted miss, m" in page


def test_a_map_needs_a_mission_on_the_earth_and_an_html_name(tmp_path):
    local = tmp_path / "xy.csv"
    local.write_text("x,y\n0,0\n500,0\n0,500\n")
    refused = run("plan", local, "--radius", 80, "--map", tmp_path / "m.html")
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert "lat/lon" in refused.stderr or "origin" in refused.stderr, refused.stderr
    wrong = run("plan", ROOT / "examples" / "site-inspection.csv", "--radius", 80,
                "--map", tmp_path / "m.png")
    assert wrong.returncode == 2 and "name it .html" in wrong.stderr
    assert not (tmp_path / "m.html").exists()
