"""Tours for the wind against the designs flown in it; writes ``docs/wind-tour.md``.

    python benchmarks/wind_tour.py [--design-csv docs/wind-design.csv] [--out docs/wind-tour.md]

Per site and forecast wind of ``docs/wind-design.csv`` (the flights of
``benchmarks/wind_design.py``): the tour the planner finds at rho 80 m (as there), its time at
22 m/s in calm air, and the time of the tour for that wind (``planning.wind_tour``: from the
same order or its reverse, the air headings chosen for the least flight time and refined, the
order then improved on time, Dubins paths in the air mass), each checked; against them, the flight time of the mission designed for that wind as the
design benchmark measured it in the forecast wind (take-off to the last target: it is not a
closed tour, so the comparison flatters the flight by the last leg and takes the climb-out
against it).  Median of 3 runs of the wind tour's planning (one core).
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

RHO_M, AIRSPEED_M_S = 80.0, 22.0


def _wind(text: str):
    from dtsp_mission.autopilot.navigation import Wind
    if text == "calm":
        return Wind()
    speed, _, rest = text.partition(" m/s from ")
    return Wind(float(speed), float(rest.split()[0]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--design-csv", type=Path, default=ROOT / "docs" / "wind-design.csv")
    parser.add_argument("--sites", default=None, help="only these sites of the CSV")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "wind-tour.md")
    args = parser.parse_args()
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[:1]))
    from design_time import sites
    from dtsp_mission.api import plan_tour
    from dtsp_mission.files import write_atomic
    from dtsp_mission.planning.wind_tour import plan_wind_tour
    with open(args.design_csv, newline="") as handle:
        flights = [row for row in csv.DictReader(handle) if row["flown_in"] == row["forecast"]]
    names = list(dict.fromkeys(row["site"] for row in flights))
    if args.sites:
        names = [name for name in names if name in args.sites.split(",")]
    lines = ["| site | forecast wind | calm tour s | tour for the wind s | plan s | check | "
             "design's flight s | flight / tour for the wind |",
             "|---|---|---:|---:|---:|---|---:|---:|"]
    ratios: dict[str, list[float]] = {}
    for name, targets in sites(names):
        tour, _ = plan_tour(targets, RHO_M)
        calm_s = tour.length_m / AIRSPEED_M_S
        for row in (r for r in flights if r["site"] == name):
            wind = _wind(row["forecast"])
            seconds = []
            for _ in range(3):
                started = time.perf_counter()
                windy = plan_wind_tour(tour.targets_m, tour.visit_order, RHO_M, AIRSPEED_M_S,
                                       wind.velocity_m_s,
                                       ground_headings_rad=tour.visit_poses()[:, 2])
                seconds.append(time.perf_counter() - started)
            report = windy.check()
            flight_s = float(row["flight_s"])
            ratio = flight_s / windy.time_s
            ratios.setdefault(name, []).append(ratio)
            lines.append(f"| {name} | {row['forecast']} | {calm_s:.0f} | {windy.time_s:.0f} "
                         f"({100 * (windy.time_s / calm_s - 1):+.1f} %) | {np.median(seconds):.2f} | "
                         f"{'valid' if report.ok else 'INVALID: ' + '; '.join(report.problems)} | "
                         f"{flight_s:.0f} | {ratio:.2f} |")
            print(lines[-1], flush=True)
    summary = "\n".join(f"- {name}: flight over the tour for the wind, median {np.median(r):.2f}, "
                        f"max {max(r):.2f} (the goal: at most 1.05)" for name, r in ratios.items())
    intro = __doc__.split("\n\n", 2)[2].strip()
    text = ("# Tours for the wind\n\n"
            f"Made by `benchmarks/wind_tour.py` from `{args.design_csv.name}`.\n\n" + intro
            + "\n\n" + summary + "\n\n" + "\n".join(lines) + "\n")
    write_atomic(args.out, text)


if __name__ == "__main__":
    main()
