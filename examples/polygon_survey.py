"""A polygon survey: seeded random sample points inside a survey area, every installed planner
compared on them, the shortest flown as the mission.

The area is ``survey-area.geojson`` (about 4 x 2.5 km); 600 sample points stand for, e.g., soil
or water sampling sites that must each be overflown.  Same seed, same points, same mission.

Run: python examples/polygon_survey.py [--out DIR] [--count N] [--seed S]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from dtsp_mission.api import local_frame_for
from dtsp_mission.export import exporter_for
from dtsp_mission.mission import MissionSettings, build_mission
from dtsp_mission.planning import TilingUnavailable, get_planner, minimum_area_region
from dtsp_mission.planning.lower_bounds import lower_bound
from dtsp_mission.targets import random_targets, read_geojson

HERE = Path(__file__).resolve().parent
RHO_M = 90.0
PLANNERS = ("auto", "lanes", "headings", "alternating", "nearest", "rbta")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("."))
    parser.add_argument("--count", type=int, default=600)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    area = read_geojson(HERE / "survey-area.geojson").area_deg
    targets = random_targets(area, args.count, args.seed)
    frame, local = local_frame_for(targets)
    region = minimum_area_region(local.positions_m)
    bound = lower_bound(local.positions_m, RHO_M, region.area_m2)
    print(f"{len(local)} sample points, rho {RHO_M:g} m, lower bound {bound.value_m:,.0f} m ({bound.kind})")
    print(f"{'planner':<12} {'tour m':>10} {'/ bound':>8} {'time s':>7}")
    tours = {}
    for name in PLANNERS:
        started = time.perf_counter()
        try:
            tour = get_planner(name).plan(local.positions_m, RHO_M)     # checked by plan()
        except TilingUnavailable as error:
            print(f"{name:<12} not applicable: {error}")
            continue
        tours[name] = tour
        print(f"{name:<12} {tour.length_m:>10,.0f} {tour.length_m / bound.value_m:>8.2f} "
              f"{time.perf_counter() - started:>7.2f}")
    best = min(tours.values(), key=lambda t: t.length_m)
    assert tours["auto"].length_m <= best.length_m + 1e-6, "auto is not the shortest"
    mission = build_mission(tours["auto"], frame, targets,
                            MissionSettings(altitude_m=110.0, airspeed_m_s=23.0, max_items=4000))
    for name in ("survey.plan", "survey.geojson"):
        print("wrote", exporter_for(name).write(mission, args.out / name))


if __name__ == "__main__":
    main()
