"""The Python API in one script: plan, inspect, export, upload -- and read back what the vehicle
holds.  Uploads go to a simulated fixed wing started here on 127.0.0.1 (to fly a real one, give
its connection string instead, e.g. ``udpout:192.168.1.10:14550``).

Run: python examples/api_quickstart.py [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from dtsp_mission.api import plan_mission
from dtsp_mission.export import exporter_for
from dtsp_mission.mission import MissionSettings
from dtsp_mission.planning.lower_bounds import lower_bound
from dtsp_mission.autopilot.navigation import Airframe
from dtsp_mission.sim.vehicle import SimulatedVehicle, VehicleSettings
from dtsp_mission.targets import GeoTargets
from dtsp_mission.upload import download_mission, to_wire, upload_mission
from dtsp_mission.autopilot.wire import differences

# Twelve survey markers (WGS84 degrees) on a 2 km field, each with a name.
LATITUDES = [46.8012, 46.8031, 46.8055, 46.8074, 46.8090, 46.8102,
             46.8081, 46.8060, 46.8043, 46.8025, 46.8008, 46.8047]
LONGITUDES = [6.9401, 6.9458, 6.9432, 6.9497, 6.9441, 6.9512,
              6.9560, 6.9533, 6.9588, 6.9547, 6.9499, 6.9489]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("."))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    targets = GeoTargets(np.array(LATITUDES), np.array(LONGITUDES),
                         tuple(f"marker-{k + 1:02d}" for k in range(len(LATITUDES))))
    settings = MissionSettings(autopilot="ardupilot", altitude_m=100.0, airspeed_m_s=20.0)
    mission = plan_mission(targets, rho_m=70.0, settings=settings)     # planner "auto"

    # Inspect: the tour (local metres), its checker report and the mission items.
    tour = mission.tour
    bound = lower_bound(tour.targets_m, tour.rho_m, np.ptp(tour.targets_m, axis=0).prod())
    print(f"planner {tour.planner}: tour {tour.length_m:,.0f} m "
          f"({tour.length_m / bound.value_m:.2f} x the {bound.kind} lower bound)")
    order = np.argsort(mission.path.target_s_m)
    print("visiting order:", ", ".join(mission.target_names[k] for k in order))
    print(f"{len(mission.items)} mission items, {mission.summary.get('flight_time_s', 0) / 60:.1f} min")

    # Export: any installed exporter, chosen by extension.
    for name in ("survey.plan", "survey.waypoints", "survey.geojson"):
        written = exporter_for(name).write(mission, args.out / name)
        print("wrote", written)

    # Upload to a vehicle and read back what it holds.
    vehicle = SimulatedVehicle(VehicleSettings(mission.home, mission.autopilot, Airframe.turning_at(70.0, 20.0)))
    with vehicle:
        connection = f"udpout:127.0.0.1:{vehicle.port}"
        report = upload_mission(mission.for_vehicle(), connection, via="pymavlink")
        print(f"uploaded {report.items} items via {report.via} in {report.seconds:.1f} s; "
              f"verified by download: {report.verified}")
        aboard = download_mission(connection)
        mismatches = differences(to_wire(mission.for_vehicle()), aboard, mission.autopilot)
        print(f"the vehicle holds {len(aboard)} items; differences from the plan: {mismatches or 'none'}")
        if mismatches:
            raise SystemExit(1)


if __name__ == "__main__":
    main()
