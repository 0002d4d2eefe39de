"""``dtsp-mission bench planners``: every planner measured, the default never longer."""

import json
import subprocess
import sys


def test_planner_bench_measures_every_planner_and_auto_is_shortest(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "dtsp_mission.cli", "bench", "planners", "--sizes", "40,300",
         "--seeds", "2", "--json", str(tmp_path / "runs.json"), "--csv", str(tmp_path / "runs.csv"),
         "--markdown", str(tmp_path / "table.md"), "--plot", str(tmp_path / "plot.png")],
        capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
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
