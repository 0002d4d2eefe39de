"""``dtsp-mission plan`` end to end on local-metre CSV files, and its bad-input errors."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import assert_valid_tour
from dtsp_mission.tour import read_tour

EXAMPLE = Path(__file__).parents[2] / "examples" / "site-local.csv"


def run(*arguments):
    """``dtsp-mission plan``; auto's improvement budget is 1 s unless given (the improver is
    tested on its own in tests/planning/test_improve.py)."""
    arguments = [*map(str, arguments)]
    if "--time-limit" not in arguments:
        arguments += ["--time-limit", "1"]
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", "plan", *arguments],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("algorithm", ["auto", "rbta", "alternating", "headings"])
def test_plan_the_bundled_example(tmp_path, algorithm):
    out = tmp_path / "tour.json"
    result = run(str(EXAMPLE), "--radius", "80", "--algorithm", algorithm, "-o", str(out))
    assert result.returncode == 0, result.stderr
    assert "420 targets" in result.stdout and "lower bound" in result.stdout
    tour = read_tour(out)
    assert_valid_tour(tour)
    assert len(tour.targets_m) == 420
    assert tour.planner.startswith(algorithm)


def test_auto_is_never_longer_than_its_candidates(tmp_path):
    result = run(str(EXAMPLE), "--radius", "80")
    lengths = [float(line.split(":")[1].split("m")[0].replace(",", ""))
               for line in result.stdout.splitlines() if "candidate" in line]
    chosen = float(result.stdout.split("tour ")[1].split(" m")[0].replace(",", ""))
    assert len(lengths) == 5           # alternating, headings, lanes, nearest, rbta
    assert chosen <= min(lengths)      # the best of them, then improved
    assert "improvement:" in result.stdout


def test_rbta_falls_back_when_too_few_targets(tmp_path):
    targets = tmp_path / "few.csv"
    targets.write_text("x,y\n0,0\n5000,0\n0,5000\n5000,5000\n2500,2500\n")
    result = run(str(targets), "--radius", "100", "--algorithm", "rbta", "-o", str(tmp_path / "t.json"))
    assert result.returncode == 0 and "Alternating Algorithm instead" in result.stderr
    assert read_tour(tmp_path / "t.json").planner == "alternating"
    result = run(str(targets), "--radius", "100", "--algorithm", "rbta", "--no-fallback",
                 "-o", str(tmp_path / "u.json"))
    assert result.returncode == 2 and "needs at least" in result.stderr
    assert not (tmp_path / "u.json").exists()


BAD_INPUTS = [
    ("targets.csv", "", [], "the file is empty"),
    ("targets.csv", "x,y\n", [], "no targets below the header"),
    ("targets.csv", "x,y\n10,20\n", [], "hold 1 target(s) after merging duplicates"),
    ("targets.csv", "x,y\n10,20\n10,20\n", [], "hold 1 target(s) after merging duplicates"),
    ("targets.csv", "lat,height\n1,3\n", [], "the header must name either columns lat and lon"),
    ("targets.csv", "easting,northing\n1,2\n", [],
     "the header must name either columns lat and lon (degrees) or x and y (metres)"),
    ("targets.csv", "x,y\n1,2\n3,abc\n", [], "line 3: y must be a number"),
    ("targets.csv", "x,y\n1,2\nnan,4\n", [], "line 3: x must be a finite number"),
    ("targets.csv", "lat,lon\n47,8\n91,8\n", [], "line 3: lat 91 is not a number between -90"),
    ("targets.csv", "lat,lon\n47,8\n47,181\n", [], "line 3: lon 181 is not a number between"),
    ("targets.csv", "lat,lon\n40,8\n44,8\n", [], "too large an area for one flat mission frame"),
    ("targets.csv", "lat,lon,alt\n47,8,50\n47.01,8,-5\n", [], "altitude -5.0 m must be a number above 0"),
    ("targets.csv", "lat,lon\n47,8\n47.01,8\n", ["--alt", "-10"], "above 0 and at most 10000 m"),
    ("targets.csv", "lat,lon\n47,8\n47.01,8\n", ["--radius", "0"], "from 0.1 to 20000 m"),
    ("targets.csv", "lat,lon\n47,8\n47.01,8\n", ["--radius", "nan"], "from 0.1 to 20000 m"),
    ("targets.csv", "x,y\n0,0\n900,0\n", [], "give --origin LAT,LON"),
    ("targets.geojson", "{not json", [], "not valid JSON"),
    ("targets.geojson", '{"type": "FeatureCollection", "features": []}', [], "no Point features"),
    ("targets.geojson", '{"type": "LineString", "coordinates": [[8, 47], [8.1, 47]]}', [],
     "'LineString' geometry is not supported"),
    ("targets.txt.gz", "x", [], "cannot tell the format"),
]


@pytest.mark.parametrize("name, content, extra, message", BAD_INPUTS)
def test_bad_input_gives_a_clear_message_exit_2_and_leaves_outputs_alone(tmp_path, name, content,
                                                                         extra, message):
    targets = tmp_path / name
    targets.write_text(content)
    kept = tmp_path / "kept.plan"
    kept.write_text("the previous mission\n")
    fresh = tmp_path / "fresh.plan"
    arguments = [str(targets), "-o", str(kept), "-o", str(fresh), *extra]
    if "--radius" not in extra:
        arguments += ["--radius", "80"]
    result = run(*arguments)
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr
    assert kept.read_text() == "the previous mission\n" and not fresh.exists()
    assert not list(tmp_path.glob(".*.part"))


def test_bad_radius_and_missing_file(tmp_path):
    result = run(str(EXAMPLE), "--radius", "-5")
    assert result.returncode == 2 and "from 0.1 to 20000 m" in result.stderr
    result = run(str(tmp_path / "nope.csv"), "--radius", "80")
    assert result.returncode == 2 and "no such file" in result.stderr


def test_duplicates_are_merged_and_reported(tmp_path):
    targets = tmp_path / "dup.csv"
    rows = "\n".join(f"{x:.1f},{y:.1f}" for x, y in np.random.default_rng(1).uniform(0, 800, (30, 2)))
    targets.write_text("x,y\n" + rows + "\n" + rows.splitlines()[0] + "\n")
    result = run(str(targets), "--radius", "50", "-o", str(tmp_path / "t.json"))
    assert result.returncode == 0 and "1 duplicate targets merged" in result.stderr
    assert len(read_tour(tmp_path / "t.json").targets_m) == 30


# Defects a new user hit (issue 16): each a clear message and exit 2, or the right file.

SITE = Path(__file__).parents[2] / "examples" / "site-inspection.csv"
AREA = Path(__file__).parents[2] / "examples" / "survey-area.geojson"


def test_a_region_that_is_no_number_or_name_is_a_clear_error(tmp_path):
    result = run(str(EXAMPLE), "--radius", "80", "--region", "foo", "-o", str(tmp_path / "t.json"))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "region 'foo' is not 'bounding', 'min-area' or a sweep heading" in result.stderr


def test_a_negative_seed_is_refused_by_the_option(tmp_path):
    result = run("--random", "10", "--area", str(AREA), "--radius", "80", "--seed", "-1",
                 "-o", str(tmp_path / "t.json"))
    assert result.returncode == 2 and "Traceback" not in result.stderr and "--seed" in result.stderr


def test_a_targets_file_beside_random_is_refused_not_ignored(tmp_path):
    result = run(str(SITE), "--random", "10", "--area", str(AREA), "--radius", "80",
                 "-o", str(tmp_path / "t.json"))
    assert result.returncode == 2 and "not both" in result.stderr


def test_a_missing_output_folder_is_found_before_planning_and_nothing_is_written(tmp_path):
    ok, bad = tmp_path / "ok.json", tmp_path / "nope" / "m.json"
    result = run(str(EXAMPLE), "--radius", "80", "-o", str(ok), "-o", str(bad))
    assert result.returncode == 2 and "does not exist" in result.stderr
    assert "targets" not in result.stdout          # refused before any planning
    assert not ok.exists()


@pytest.mark.parametrize("suffix, magic", [(".svg", b"<?xml"), (".pdf", b"%PDF"), (".png", b"\x89PNG")])
def test_the_plot_is_written_in_the_format_of_its_extension(tmp_path, suffix, magic):
    picture = tmp_path / f"m{suffix}"
    result = run(str(EXAMPLE), "--radius", "80", "-o", str(tmp_path / "t.json"), "--plot", str(picture))
    assert result.returncode == 0, result.stderr
    assert picture.read_bytes().startswith(magic)


def test_an_unknown_plot_format_is_refused_before_planning(tmp_path):
    result = run(str(EXAMPLE), "--radius", "80", "--plot", str(tmp_path / "m.gif"))
    assert result.returncode == 2 and ".gif is none of them" in result.stderr


def test_quiet_prints_nothing_and_json_prints_one_summary(tmp_path):
    """-q: no output but errors; --json: exactly one JSON object on stdout (the report lines
    on stderr), with the lengths, items and files a script needs; -q --json: only that."""
    import json
    targets = tmp_path / "t.csv"
    targets.write_text("lat,lon\n46.80,6.94\n46.81,6.95\n46.805,6.955\n46.79,6.96\n")
    out = tmp_path / "m.plan"
    quiet = run(targets, "--radius", 80, "-q", "-o", out, "--time-limit", 0)
    assert quiet.returncode == 0 and quiet.stdout == "" and quiet.stderr == "" and out.exists()
    loud = run(targets, "--radius", 80, "--json", "-o", out, "--airspeed", 22, "--time-limit", 0)
    summary = json.loads(loud.stdout)
    assert summary["targets"] == 4 and summary["files"] == [str(out)]
    assert summary["tour_length_m"] > 0 and summary["flight_length_m"] > 0 and summary["items"] > 4
    assert len(summary["predicted_miss_m"]) == 4 and "planner auto" in loud.stderr
    both = run(targets, "--radius", 80, "--json", "-q", "-o", out, "--airspeed", 22, "--time-limit", 0)
    assert both.stderr == "" and summary["flight_time_s"] > 0
    assert {**json.loads(both.stdout), "planning_s": 0} == {**summary, "planning_s": 0}
    failed = run(targets, "--radius", -1, "-q")
    assert failed.returncode == 2 and failed.stdout == "" and "Error" in failed.stderr


def test_a_first_run_says_that_it_compiles(tmp_path):
    """Without numba's cache the first plan compiles for about a minute: it says so first
    (run here with the JIT off, so nothing is compiled or cached); with the cache, silence."""
    import os
    targets = tmp_path / "t.csv"
    targets.write_text("lat,lon\n46.80,6.94\n46.81,6.95\n46.805,6.955\n")
    base = [sys.executable, "-m", "dtsp_mission.cli", "plan", str(targets), "--radius", "80",
            "--algorithm", "alternating"]
    cold = tmp_path / "cold"
    cold.mkdir()
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cold), "NUMBA_DISABLE_JIT": "1"}
    first = subprocess.run(base, capture_output=True, text=True, timeout=300, env=env)
    assert first.returncode == 0, first.stderr
    assert "first run on this machine: compiling the planning kernels" in first.stderr
    warm = tmp_path / "warm" / "dtsp_mission" / "planning"
    warm.mkdir(parents=True)
    (warm / "improve._descend-1.py311.nbi").write_bytes(b"")
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "warm")
    again = subprocess.run(base, capture_output=True, text=True, timeout=300, env=env)
    assert again.returncode == 0 and "compiling" not in again.stderr
