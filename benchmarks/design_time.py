"""How long `plan` takes to design a mission for the guidance, on one core; prints a table.

    python benchmarks/design_time.py [--repeats 3] [--sites bundled,uniform100,clustered400,...] [--cores 1]

Per site (the README's bundled site, and the seeded sites of ``benchmarks/mission_items.py``),
planned at rho 80 m, 22 m/s, 120 m with the default guidance design through
``pipeline.run_plan`` as ``plan`` does: the median over the repeats of the whole plan, of the
tour's planning and of the rest (the mission design, with any wider tours it plans), the
radius the mission was planned at, the targets the design does not hold, and the predicted
flight against the tour at rho 80.  The process is pinned to ``--cores`` cores (the design
flies its winds on every core it may use); the first run on a machine compiles the kernels
and is not counted (a warm-up plan of a small site runs first).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))


def sites(names: list[str]):
    from dtsp_mission.targets import read_targets
    from mission_items import _site             # the benchmark sites, seed 0
    for name in names:
        if name == "bundled":
            yield name, read_targets(ROOT / "examples" / "site-inspection.csv")
        else:                                   # uniform100, clustered400, dense200, ...
            kind = name.rstrip("0123456789")
            yield name, _site(kind, int(name[len(kind):]), 0)


def plan_once(targets) -> dict:
    from dtsp_mission.mission import MissionSettings
    from dtsp_mission.mission.widening import targets_beyond
    from dtsp_mission.pipeline import PlanRequest, run_plan
    settings = MissionSettings(altitude_m=120.0, airspeed_m_s=22.0, design="guidance")
    started = time.perf_counter()
    result = run_plan(PlanRequest(targets=targets, rho_m=80.0, settings=settings))
    total = time.perf_counter() - started
    mission = result.mission
    return {"total_s": total, "tour_s": result.planning_s, "design_s": total - result.planning_s,
            "rho_m": mission.rho_m, "beyond": targets_beyond(mission),
            "predicted_km": mission.guidance.predicted_flight_m / 1e3,
            "tour_km": result.tour.length_m / 1e3}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--sites", default="bundled")
    parser.add_argument("--cores", type=int, default=1)
    args = parser.parse_args()
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[: args.cores]))
    import numpy as np
    from dtsp_mission.targets.model import local_targets
    from dtsp_mission.frame import LocalFrame
    warm = local_targets(np.random.default_rng(0).uniform(-800, 800, (12, 2))).to_geodetic(
        LocalFrame(46.8, 6.95))
    plan_once(warm)
    print(f"| site | targets | plan s (median of {args.repeats}) | tour s | design s | planned rho m "
          f"| targets beyond | predicted flight km / tour at rho 80 km |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for name, targets in sites(args.sites.split(",")):
        runs = [plan_once(targets) for _ in range(args.repeats)]
        median = {key: statistics.median(run[key] for run in runs)
                  for key in ("total_s", "tour_s", "design_s")}
        last = runs[-1]
        print(f"| {name} | {len(targets)} | {median['total_s']:.1f} | {median['tour_s']:.1f} | "
              f"{median['design_s']:.1f} | {last['rho_m']:g} | {last['beyond']} | "
              f"{last['predicted_km']:.2f} / {last['tour_km']:.2f} "
              f"({100 * (last['predicted_km'] / last['tour_km'] - 1):+.0f} %) |", flush=True)


if __name__ == "__main__":
    main()
