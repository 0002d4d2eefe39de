"""Items per target and predicted misses of the two waypoint designs, per kind of site;
writes ``docs/mission-items.md``.

    python benchmarks/mission_items.py [--seeds 2] [--out docs/mission-items.md]

Every mission is flown by the ArduPlane flight model (stock parameters, 22 m/s; the model
agrees with recorded ArduPlane flights, ``docs/arduplane-agreement.md``) from rest at home;
a target's miss is the least distance of the predicted track (after take-off) to it.
``geometry`` is the waypoint polyline within the default tolerance of the exact path (given
room for 4,000 items); ``guidance`` is the default design within a stock ArduPlane's 655 slots (robust over 1 m/s of
wind from each quarter, within 3.5 m in calm air), planned with a wider turn radius (1.3 or
1.6 rho) where that holds more targets, as `plan` does; its flight is set against the tour the
planner found at rho 80 m.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from dtsp_mission.api import plan_tour
from dtsp_mission.autopilot.navigation import Airframe, closest_approach_m
from dtsp_mission.errors import InputError
from dtsp_mission.files import write_atomic
from dtsp_mission.frame import LocalFrame
from dtsp_mission.mission import MissionSettings, build_mission
from dtsp_mission.mission.widening import targets_beyond, with_turn_margin
from dtsp_mission.sim.predict import predict_flight
from dtsp_mission.targets import read_targets
from dtsp_mission.targets.model import local_targets

ROOT = Path(__file__).resolve().parents[1]
RHO_M, AIRSPEED_M_S, ALTITUDE_M = 80.0, 22.0, 120.0
CENTRE = (47.3977, 8.5456)


def _site(kind: str, n: int, seed: int):
    rng = np.random.default_rng(seed)
    if kind == "uniform":
        side = 350.0 * np.sqrt(n)            # the density of the recorded dtsp_u40 flight
        points = rng.uniform(-side / 2, side / 2, (n, 2))
    elif kind == "dense":
        points = rng.uniform(-750.0, 750.0, (n, 2))
    elif kind == "clustered":                # Gaussian clusters among sparse targets
        centres = rng.uniform(-2500.0, 2500.0, (max(2, n // 40), 2))
        clustered = centres[rng.integers(0, len(centres), n * 3 // 4)] + rng.normal(0, 120.0, (n * 3 // 4, 2))
        points = np.vstack([clustered, rng.uniform(-3000.0, 3000.0, (n - len(clustered), 2))])
    else:
        raise ValueError(kind)
    return local_targets(points).to_geodetic(LocalFrame(*CENTRE))


def _evaluate(mission, targets, airframe) -> dict:
    flight = predict_flight(mission.for_vehicle(), airframe, 0.02)
    track = flight.track
    after = track[:, 0] >= flight.reached.get(1, 0.0)
    xy = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    miss = closest_approach_m(track[after, 1:3], xy)
    return {"items": len(mission.items), "per_target": len(mission.items) / len(xy),
            "median": float(np.median(miss)), "p95": float(np.percentile(miss, 95)),
            "max": float(miss.max()), "beyond5": int((miss > 5.0).sum())}


LIMITS = """
## What limits it

- The design is judged robustly (`docs/missions.md`, step 7): within 3.5 m (`--max-miss` 5 m
  less the model's 1.5 m margin) in the forecast wind -- calm here -- and within 5 m in 1 m/s
  of wind from each quarter. *beyond limit* counts the targets that fail that; *> 5 m* those the
  calm flight misses by more than 5 m.
- Targets the local repair leaves beyond are passed again (revisits, then detours with a
  straight lead-in: `docs/missions.md`, step 8) before the whole tour is planned again wider
  (1.3, then 1.6 rho, step 9). The second passes are what the flight costs now: the bundled
  site at rho 80 flies 24.8 km with 10 targets beyond, 27.3 km after the revisits (3 beyond)
  and 32.0 km after two detours (none) -- against 34.0 km at rho 128 before detours existed.
  Widening only the legs into and out of the stuck targets (same headings) was tried on the
  bundled site and dropped: 10 stuck targets' legs at 1.3 rho made the tour 6.2 km longer and
  left 6 others beyond (1.6 rho: +10.3 km, 5 beyond).
- The margin comes from the recorded flights (`calibration` below): of the targets the model
  passed within 3.5 m, a real ArduPlane missed 2.9 % by more than 5 m (7 of 245).
- Only seed 0 of each random site was measured; `--seeds 2` measures more. The sites' home is
  their generation centre here (`benchmarks/design_time.py` takes the mission's centre), and
  the designs differ with it: clustered 100 holds at rho 80 from the mission's centre (42.1 km)
  but widens to 104 from here (38.0 km).
"""


def calibration() -> str:
    """How the real misses of the recorded planned missions depend on the model's."""
    from dtsp_mission.bench.arduplane_agreement import _rows, fly_recorded_mission
    data = ROOT / "tests" / "data"
    real, model = [], []
    for folder in sorted(data.glob("arduplane-sitl*/*")):
        if not (folder / "misses.csv").exists():
            continue
        flight, track, frame = fly_recorded_mission(folder)
        rows = _rows(folder / "misses.csv")
        xy = frame.to_local(np.array([float(r["lat"]) for r in rows]),
                            np.array([float(r["lon"]) for r in rows]))
        model.append(closest_approach_m(track[track[:, 0] >= dict(flight.reached)[1], 1:3], xy))
        real.append(np.array([float(r["miss_m"]) for r in rows]))
    real, model = np.concatenate(real), np.concatenate(model)
    lines = ["## Calibration: real misses against the model's",
             "",
             f"{len(real)} targets of the planned missions flown by a real ArduPlane SITL "
             "(`tests/data/arduplane-sitl*`, every wind and tuning), each flown by the model with "
             "the case's parameters and wind.",
             "",
             "| model's miss m | targets | real miss p95 m | real max m | real > 5 m |",
             "|---|---:|---:|---:|---:|"]
    for low, high in ((0, 1), (1, 2), (2, 3), (3, 3.5), (3.5, 4.5), (4.5, 5)):
        chosen = (model >= low) & (model < high)
        if chosen.any():
            lines.append(f"| {low:g}-{high:g} | {chosen.sum()} | {np.percentile(real[chosen], 95):.1f} | "
                         f"{real[chosen].max():.1f} | {(real[chosen] > 5).sum()} "
                         f"({100 * (real[chosen] > 5).mean():.1f} %) |")
    within = model < 3.5
    lines += ["", f"Within 3.5 m in the model: {(real[within] > 5).sum()} of {within.sum()} "
              f"({100 * (real[within] > 5).mean():.1f} %) beyond 5 m for real; "
              f"|real - model| p90 {np.percentile(np.abs(real - model), 90):.1f} m, "
              f"p95 {np.percentile(np.abs(real - model), 95):.1f} m.", ""]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=1)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "mission-items.md")
    args = parser.parse_args()
    airframe = Airframe.from_parameters(airspeed_m_s=AIRSPEED_M_S)
    sites = [("bundled site (272)", None, 0)]
    for kind, sizes in (("uniform", (100, 200, 400)), ("clustered", (100, 400)), ("dense", (100, 200))):
        sites += [(f"{kind} {n}", (kind, n), s) for n in sizes for s in range(args.seeds)]
    rows = []
    for label, spec, seed in sites:
        targets = (read_targets(ROOT / "examples" / "site-inspection.csv") if spec is None
                   else _site(*spec, seed))
        tour, frame = plan_tour(targets, RHO_M)
        base = MissionSettings(altitude_m=ALTITUDE_M, airspeed_m_s=AIRSPEED_M_S,
                               home_deg=None if spec is None else CENTRE)
        row = [label if spec is None else f"{label} (seed {seed})", len(targets)]
        for design, budget in (("geometry", 4000), ("guidance", None)):
            started = time.perf_counter()
            settings = replace(base, design=design, max_items=budget)
            try:
                mission = build_mission(tour, frame, targets, settings)
                if design == "guidance":     # as `plan` does: a wider turn if it holds more
                    mission = with_turn_margin(mission, lambda r: plan_tour(targets, r)[0],
                                               targets, settings)
            except InputError as error:
                row.append({"error": str(error)})
                continue
            result = _evaluate(mission, targets, airframe)
            result["seconds"] = time.perf_counter() - started
            if design == "guidance":
                result["predicted_km"] = mission.summary["predicted_flight_m"] / 1e3
                result["tour_km"] = tour.length_m / 1e3
                result["rho"] = mission.rho_m
                result["beyond_limit"] = targets_beyond(mission)
            row.append(result)
        rows.append(row)
        print(label, seed, row[2:], flush=True)
    lines = ["| site | targets | geometry: items/target | geometry: miss median / p95 / max m | "
             "guidance: items/target | guidance: miss median / p95 / max m | guidance: > 5 m | "
             "guidance: beyond limit | guidance: planned rho m | guidance: predicted flight km / "
             "tour at rho 80 km | design time s |",
             "|---|---:|---:|---|---:|---|---:|---:|---:|---|---:|"]
    for label, n, geometry, guidance in rows:
        g = ("-" if "error" in geometry else f"{geometry['per_target']:.2f}",
             "-" if "error" in geometry else f"{geometry['median']:.1f} / {geometry['p95']:.1f} / {geometry['max']:.1f}")
        lines.append(f"| {label} | {n} | {g[0]} | {g[1]} | {guidance['per_target']:.2f} | "
                     f"{guidance['median']:.1f} / {guidance['p95']:.1f} / {guidance['max']:.1f} | "
                     f"{guidance['beyond5']} | {guidance['beyond_limit']} | {guidance['rho']:.0f} | "
                     f"{guidance['predicted_km']:.1f} / {guidance['tour_km']:.1f} "
                     f"({100 * (guidance['predicted_km'] / guidance['tour_km'] - 1):+.0f} %) | "
                     f"{guidance['seconds']:.0f} |")
    intro = (__doc__.split("\n\n", 2)[2] if __doc__.count("\n\n") >= 2 else "")
    text = ("# Mission items per target, and how close the predicted flight passes\n\n"
            "Made by `benchmarks/mission_items.py` (rho 80 m, 22 m/s, 120 m; seeds 0.."
            f"{args.seeds - 1}).\n\n" + intro.strip() + "\n\n" + "\n".join(lines) + "\n")
    text += LIMITS + "\n" + calibration()
    write_atomic(args.out, text)
    print(text)


if __name__ == "__main__":
    main()
