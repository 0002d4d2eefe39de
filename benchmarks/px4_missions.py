"""PX4 missions: items per target and how close the PX4 model passes, guidance design against
geometry; writes ``docs/px4-missions.md``.

    python benchmarks/px4_missions.py [--airspeed 18] [--out docs/px4-missions.md]

Per site (the README's bundled site and seed 0 of the sites of ``benchmarks/mission_items.py``),
planned at rho 80 m, 120 m, ``--airspeed`` for a stock PX4 (500 mission slots, a landing at the
end as MIS_TKO_LAND_REQ asks): the default guidance design and the geometry design, each
written mission flown by the PX4 model (NPFG, PX4 SITL's fixed wing:
``docs/px4-agreement.md``) from rest at home; a target's miss is the least distance of the
track after the take-off.  *flight / tour*: the guidance design's predicted flight (take-off to
the last target) against the tour the planner found.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

SITES = ("bundled", "uniform100", "uniform200", "uniform400", "clustered100", "clustered400",
         "dense100", "dense200")


def _flown(mission, targets, airframe) -> np.ndarray:
    from dtsp_mission.autopilot.navigation import closest_approach_m
    from dtsp_mission.sim.predict import predict_flight
    flight = predict_flight(mission.for_vehicle(), airframe, 0.02)
    start = dict(flight.reached).get(0, 0.0)
    xy = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    return closest_approach_m(flight.track[flight.track[:, 0] >= start, 1:3], xy)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--airspeed", type=float, default=18.0)
    parser.add_argument("--sites", default=",".join(SITES))
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "px4-missions.md")
    args = parser.parse_args()
    from design_time import sites
    from mission_items import CENTRE
    from dtsp_mission.api import plan_tour
    from dtsp_mission.errors import DtspError
    from dtsp_mission.files import write_atomic
    from dtsp_mission.mission import MissionSettings, build_mission
    lines = ["| site | targets | geometry: items / target | geometry: miss median / max m | "
             "guidance: items / target | guidance: miss median / p95 / max m | > 5 m | "
             "flight / tour km | design s |", "|---|---:|---|---|---:|---|---:|---|---:|"]
    rows = []
    for name, targets in sites(args.sites.split(",")):
        tour, frame = plan_tour(targets, 80.0)
        base = MissionSettings(altitude_m=120.0, airspeed_m_s=args.airspeed, autopilot="px4",
                               home_deg=None if name == "bundled" else CENTRE)
        cells = {}
        for design in ("geometry", "guidance"):
            settings = replace(base, design=design)
            started = time.perf_counter()
            try:
                mission = build_mission(tour, frame, targets, settings)
            except DtspError as error:
                cells[design] = (None, str(error))
                continue
            seconds = time.perf_counter() - started
            miss = _flown(mission, targets, settings.checked(80.0).design_airframe())
            cells[design] = (mission, miss, seconds)
        n = len(targets)
        geometry = cells["geometry"]
        g = (("does not fit", "-") if geometry[0] is None else
             (f"{len(geometry[0].items) / n:.2f}", f"{np.median(geometry[1]):.1f} / {geometry[1].max():.1f}"))
        mission, miss, seconds = cells["guidance"]
        prediction = mission.guidance
        flight = prediction.predicted_flight_m / 1e3
        rows.append((len(mission.items) / n, int((miss > 5).sum()), flight / (tour.length_m / 1e3)))
        lines.append(f"| {name} | {n} | {g[0]} | {g[1]} | {len(mission.items) / n:.2f} | "
                     f"{np.median(miss):.1f} / {np.percentile(miss, 95):.1f} / {miss.max():.1f} | "
                     f"{int((miss > 5).sum())} | {flight:.2f} / {tour.length_m / 1e3:.2f} "
                     f"({100 * (flight / (tour.length_m / 1e3) - 1):+.0f} %) | {seconds:.1f} |")
        print(lines[-1], flush=True)
    intro = __doc__.split("\n\n", 2)[2].strip()
    summary = (f"Guidance design: at most {max(r[0] for r in rows):.2f} items per target, "
               f"{sum(r[1] for r in rows)} targets beyond 5 m in the model over all sites, "
               f"predicted flight at most {100 * (max(r[2] for r in rows) - 1):+.1f} % of the tour.")
    text = (f"# PX4 missions\n\nMade by `benchmarks/px4_missions.py --airspeed {args.airspeed:g}` "
            f"(rho 80 m, 120 m, stock PX4 parameters: the airspeed asked is flown as PX4 SITL's "
            f"fixed wing flies it).\n\n{intro}\n\n{summary}\n\n" + "\n".join(lines) + "\n")
    write_atomic(args.out, text)
    print(text)


if __name__ == "__main__":
    main()
