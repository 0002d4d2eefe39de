"""A fleet batch: the bundled site's inspection points shared between three aircraft of
different types, one mission each, planned in one go.

The targets are split into sectors around the site's centre holding equal numbers of targets
(a simple, deterministic split: each aircraft works one side of the site); each aircraft plans
with its own turn radius (from airspeed and bank) and item budget, and gets its own ``.plan``.
A summary table goes to stdout and ``fleet.csv``.

Run: python examples/fleet_batch.py [--out DIR]
"""

from __future__ import annotations

import argparse
import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dtsp_mission.api import local_frame_for, plan_mission
from dtsp_mission.export import exporter_for
from dtsp_mission.files import write_atomic
from dtsp_mission.mission import MissionSettings
from dtsp_mission.targets import read_targets
from dtsp_mission.autopilot.navigation import Airframe

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Aircraft:
    name: str
    autopilot: str
    airspeed_m_s: float
    max_bank_deg: float
    max_items: int


FLEET = (Aircraft("uav-1", "ardupilot", 18.0, 35.0, 700),
         Aircraft("uav-2", "ardupilot", 22.0, 40.0, 4000),
         Aircraft("uav-3", "px4", 20.0, 35.0, 2000))


def sectors(positions_m: np.ndarray, count: int) -> list[np.ndarray]:
    """Indices of the targets in ``count`` angular sectors around their centre, equal in size."""
    centred = positions_m - positions_m.mean(axis=0)
    order = np.argsort(np.arctan2(centred[:, 1], centred[:, 0]), kind="stable")
    return [np.sort(part) for part in np.array_split(order, count)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("."))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    site = read_targets(HERE / "site-inspection.csv")
    _, local = local_frame_for(site)
    rows = []
    for aircraft, members in zip(FLEET, sectors(local.positions_m, len(FLEET))):
        # the radius the aircraft turns at its largest bank (the flight model's answer)
        rho = Airframe(aircraft.airspeed_m_s, aircraft.max_bank_deg).tightest_turn_m
        mission = plan_mission(site.subset(members), rho, MissionSettings(
            autopilot=aircraft.autopilot, altitude_m=120.0, airspeed_m_s=aircraft.airspeed_m_s,
            max_items=aircraft.max_items))
        path = exporter_for("x.plan").write(mission, args.out / f"{aircraft.name}.plan")
        rows.append({"aircraft": aircraft.name, "autopilot": aircraft.autopilot,
                     "targets": len(members), "rho_m": round(rho, 1),
                     "tour_m": round(mission.tour.length_m), "items": len(mission.items),
                     "flight_min": round(mission.summary["flight_time_s"] / 60, 1),
                     "file": path.name})
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
    write_atomic(args.out / "fleet.csv", text.getvalue())
    for row in rows:
        print("  ".join(f"{k}={v}" for k, v in row.items()))
    assert sum(r["targets"] for r in rows) == len(site)
    longest = max(r["flight_min"] for r in rows)
    print(f"{len(site)} targets on {len(rows)} aircraft; the fleet is done in {longest} min "
          f"(one aircraft: about {math.fsum(r['flight_min'] for r in rows):.0f} min of flying)")


if __name__ == "__main__":
    main()
