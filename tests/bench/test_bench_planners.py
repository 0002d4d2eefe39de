"""``dtsp-mission bench planners``: every planner measured, the default never longer."""

import json
import subprocess
import sys

import pytest


@pytest.mark.heavy(seconds=16)
def test_planner_bench_measures_every_planner_and_auto_is_shortest(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "dtsp_mission.cli", "bench", "planners", "--sizes", "40,300",
         "--seeds", "2", "--time-limit", "1", "--json", str(tmp_path / "runs.json"), "--csv", str(tmp_path / "runs.csv"),
         "--markdown", str(tmp_path / "table.md"), "--plot", str(tmp_path / "plot.png")],
        capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert "planning" not in result.stderr      # no progress-bar label in a log (not a terminal)
    runs = json.loads((tmp_path / "runs.json").read_text())
    assert {r["planner"] for r in runs} >= {"alternating", "headings", "rbta", "auto"}
    assert len(runs) == 2 * 2 * len({r["planner"] for r in runs})
    for r in runs:
        if r["planner"] == "rbta" and r["n"] == 40:
            assert not r["valid"] and r["error"].startswith("TilingUnavailable")
        else:
            assert r["valid"], r
            assert r["length_m"] >= r["best_m"] and r["over_bound"] > 1.0
    for n in (40, 300):
        for seed in (0, 1):
            lengths = {r["planner"]: r["length_m"] for r in runs
                       if r["n"] == n and r["seed"] == seed and r["valid"]}
            assert lengths["auto"] == min(lengths.values())
    assert "not applicable" in result.stdout
    assert "Produced by `dtsp-mission bench planners" in (tmp_path / "table.md").read_text()
    assert (tmp_path / "runs.csv").read_text().count("\n") == len(runs) + 1
    assert (tmp_path / "plot.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.heavy(seconds=25)
def test_the_anchor_is_a_peer_on_every_family_and_the_table_gives_each_length_over_it(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "dtsp_mission.cli", "bench", "planners", "--sizes", "12",
         "--seeds", "1", "--families", "uniform,dense,clustered", "--planners", "auto,headings",
         "--anchor", "--time-limit", "1", "--json", str(tmp_path / "runs.json"),
         "--markdown", str(tmp_path / "table.md")],
        capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    runs = json.loads((tmp_path / "runs.json").read_text())
    assert {(r["family"], r["planner"]) for r in runs} == {
        (f, p) for f in ("uniform", "dense", "clustered") for p in ("auto", "headings", "lkh-anchor")}
    for r in runs:
        assert r["valid"], r
        assert r["over_anchor"] == r["length_m"] / r["anchor_m"]
        if r["planner"] == "auto":      # at or below the anchor (K = 8, 16, 32) on 12 targets,
            assert r["length_m"] <= r["anchor_m"] * (1 + 1e-6)   # to 1 mm per km
    assert "/ anchor (median, range)" in result.stdout
    table = (tmp_path / "table.md").read_text()
    assert "| dense | 12 | lkh-anchor |" in table
    # The table can be made again from the runs, measuring nothing.
    merged = subprocess.run(
        [sys.executable, "-m", "dtsp_mission.cli", "bench", "planners", "--merge",
         str(tmp_path / "runs.json"), "--markdown", str(tmp_path / "again.md")],
        capture_output=True, text=True, timeout=600)
    assert merged.returncode == 0, merged.stderr
    assert (tmp_path / "again.md").read_text().split("\n\n", 2)[2] == table.split("\n\n", 2)[2]
