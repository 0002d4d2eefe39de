"""The guidance design in wind, flown in the wind it was designed for and in winds off that
forecast; writes ``docs/wind-design.md`` (and a CSV of every flight beside it).

    python benchmarks/wind_design.py [--sites bundled,uniform100,clustered100,dense100]
        [--speeds 0,5,8] [--directions 8] [--spread 2] [--out docs/wind-design.md]

Per site (the README's bundled site and seed 0 of the sites of ``benchmarks/mission_items.py``)
and per forecast wind (each speed from ``--directions`` directions, 0 deg first; calm once):
the mission is designed as ``plan --wind SPEED@FROM --wind-spread SPREAD`` does (rho 80 m,
22 m/s, 120 m, stock ArduPlane parameters; the wider-turn stage included, its tours planned
once per radius and site), then flown by the flight model in the forecast wind and in the four
winds around it the design is judged in (the forecast +- ``--spread`` m/s and turned +- 20 deg;
in calm air ``--spread`` m/s from the four quarters).  A target's miss is the least distance
of the track after take-off.  *flight* is the time from the take-off to the last target item
in the forecast wind, against the time the tour the planner found (in calm air: the planner
has no wind-aware tours yet) takes at the airspeed.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

RHO_M, AIRSPEED_M_S, ALTITUDE_M, LIMIT_M = 80.0, 22.0, 120.0, 5.0


def _flown(mission, targets, airframe, wind) -> tuple[np.ndarray, float]:
    """Per-target misses of ``mission`` flown in ``wind``, and its time from the take-off's
    end to the last item reached."""
    from dtsp_mission.autopilot.navigation import closest_approach_m
    from dtsp_mission.sim.predict import predict_flight
    flight = predict_flight(mission.for_vehicle(), airframe, 0.02, wind=wind)
    start = flight.reached.get(1, 0.0)
    after = flight.track[:, 0] >= start
    xy = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    return closest_approach_m(flight.track[after, 1:3], xy), max(flight.reached.values()) - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sites", default="bundled,uniform100,clustered100,dense100")
    parser.add_argument("--speeds", default="0,5,8")
    parser.add_argument("--directions", type=int, default=8)
    parser.add_argument("--spread", type=float, default=2.0)
    parser.add_argument("--cores", type=int, default=1)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "wind-design.md")
    args = parser.parse_args()
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[: args.cores]))
    from design_time import sites
    from mission_items import CENTRE
    from dtsp_mission.api import plan_tour
    from dtsp_mission.autopilot.navigation import Airframe, Wind
    from dtsp_mission.errors import DtspError
    from dtsp_mission.files import write_atomic
    from dtsp_mission.mission import MissionSettings, build_mission
    from dtsp_mission.mission.widening import targets_beyond, with_turn_margin
    airframe = Airframe.from_parameters(airspeed_m_s=AIRSPEED_M_S)
    winds = []
    for speed in (float(s) for s in args.speeds.split(",")):
        winds += ([Wind()] if speed == 0 else
                  [Wind(speed, 360.0 * k / args.directions) for k in range(args.directions)])
    csv_path = args.out.with_suffix(".csv")
    rows, records = [], []

    def write() -> str:
        """Writes the table and the CSV of what is measured so far; returns the table."""
        lines = ["| site | targets | forecast wind | > 5 m in the forecast (worst m) | > 5 m in any "
                 "wind off it (worst m) | judged beyond | planned rho m | items | flight s / tour s | "
                 "design s |", "|---|---:|---|---|---|---:|---:|---:|---|---:|"]
        for name, n, wind, row in rows:
            if row is None:
                lines.append(f"| {name} | {n} | {wind} | refused | | | | | | |")
                continue
            lines.append(
                f"| {name} | {n} | {wind} | {row['forecast_beyond']} ({row['forecast_worst']:.1f}) | "
                f"{row['any_beyond']} ({row['any_worst']:.1f}) | {row['judged_beyond']} | "
                f"{row['rho']:g} | {row['items']} | {row['flight_s']:.0f} / {row['tour_s']:.0f} "
                f"({100 * (row['flight_s'] / row['tour_s'] - 1):+.0f} %) | {row['design_s']:.0f} |")
        done = [row for *_, row in rows if row is not None]
        summary = (f"Over {len(done)} designs: {sum(r['forecast_beyond'] == 0 for r in done)} hold every "
                   f"target within 5 m in the forecast wind, {sum(r['any_beyond'] == 0 for r in done)} in "
                   f"every wind off it; flight over the calm tour's time: median "
                   f"{100 * (np.median([r['flight_s'] / r['tour_s'] for r in done]) - 1):+.0f} %, max "
                   f"{100 * (max(r['flight_s'] / r['tour_s'] for r in done) - 1):+.0f} %." if done else "")
        intro = __doc__.split("\n\n", 2)[2].strip()
        text = ("# The guidance design in wind\n\n"
                f"Made by `benchmarks/wind_design.py --sites {args.sites} --speeds {args.speeds} "
                f"--directions {args.directions} --spread {args.spread:g}` (one core).\n\n"
                + intro + "\n\n" + summary + "\n\n" + "\n".join(lines) + "\n\n"
                f"Every flight (forecast and the winds off it) is in `{csv_path.name}`.\n")
        buffer = [",".join(records[0].keys())] if records else []
        for record in records:
            buffer.append(",".join(str(v) for v in record.values()))
        write_atomic(csv_path, "\n".join(buffer) + "\n")
        write_atomic(args.out, text)
        return text
    for name, targets in sites(args.sites.split(",")):
        tours = {}

        def tour_at(rho: float):
            if rho not in tours:
                tours[rho] = plan_tour(targets, rho)
            return tours[rho]
        tour, frame = tour_at(RHO_M)
        tour_s = tour.length_m / AIRSPEED_M_S
        for wind in winds:
            settings = MissionSettings(altitude_m=ALTITUDE_M, airspeed_m_s=AIRSPEED_M_S,
                                       design="guidance", wind=wind, wind_spread_m_s=args.spread,
                                       home_deg=None if name == "bundled" else CENTRE)
            started = time.perf_counter()
            try:
                mission = with_turn_margin(build_mission(tour, frame, targets, settings),
                                           lambda rho: tour_at(rho)[0], targets, settings)
            except DtspError as error:
                print(f"{name} {wind}: {error}", flush=True)
                rows.append((name, len(targets), str(wind), None))
                continue
            design_s = time.perf_counter() - started
            flights = [_flown(mission, targets, airframe, w) for w in settings.design_winds()]
            misses = np.array([miss for miss, _ in flights])
            for w, (miss, seconds) in zip(settings.design_winds(), flights):
                records.append({"site": name, "forecast": str(wind), "flown_in": str(w),
                                "beyond_5m": int((miss > LIMIT_M).sum()),
                                "worst_m": round(float(miss.max()), 2),
                                "median_m": round(float(np.median(miss)), 2),
                                "flight_s": round(seconds, 1)})
            row = {"forecast_beyond": int((misses[0] > LIMIT_M).sum()),
                   "forecast_worst": float(misses[0].max()),
                   "any_beyond": int((misses.max(axis=0) > LIMIT_M).sum()),
                   "any_worst": float(misses.max()),
                   "judged_beyond": targets_beyond(mission), "rho": mission.rho_m,
                   "flight_s": flights[0][1], "tour_s": tour_s, "design_s": design_s,
                   "items": len(mission.items)}
            rows.append((name, len(targets), str(wind), row))
            print(name, wind, {k: round(v, 2) if isinstance(v, float) else v for k, v in row.items()},
                  flush=True)
        write()                                     # what is measured so far, site by site
    print(write())


if __name__ == "__main__":
    main()
