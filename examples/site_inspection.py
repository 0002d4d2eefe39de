"""Inspection of a site: 272 points (pylons, tank rims, a fence line; each with its own
overflight altitude) planned for an aircraft whose limit is 72 m turns, checked in the simulated
aircraft before anyone flies it.

Plans with rho about 10 % above the aircraft's tightest turn (80 m for 72 m) and the geometric
design (the waypoint polyline of the exact path, with room for 4,000 items: seconds, where the
guidance design of ``dtsp-mission plan`` takes a minute or two), writes the mission for
QGroundControl (with a geofence, if the ``dtsp-mission-fence`` plugin is installed) and for
Google Earth (``dtsp-mission-kml``), then ``--fly`` uploads it to the simulator and reports how
close the aircraft passed each point: ArduPlane's L1 guidance cuts the polyline's corners, up
to 30-40 m on this site (docs/mission-items.md) -- what ``--design guidance`` is for.

Run: python examples/site_inspection.py [--out DIR] [--fly] [--speedup 50]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from dtsp_mission.api import plan_mission
from dtsp_mission.export import exporter_for, exporters
from dtsp_mission.mission import MissionSettings
from dtsp_mission.plugins import working
from dtsp_mission.autopilot.navigation import Airframe
from dtsp_mission.sim.fly import fly_mission, targets_in
from dtsp_mission.targets import read_targets

HERE = Path(__file__).resolve().parent
AIRCRAFT_MIN_TURN_M = 72.0
AIRSPEED_M_S = 22.0
PLANNED_RHO_M = 80.0            # ~10 % above the aircraft's limit: room for the guidance to catch up


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("."))
    parser.add_argument("--fly", action="store_true", help="fly it in the simulator")
    parser.add_argument("--speedup", type=float, default=50.0)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    site = read_targets(HERE / "site-inspection.csv")     # lat, lon, alt (above home), name
    mission = plan_mission(site, PLANNED_RHO_M, MissionSettings(
        altitude_m=120.0, airspeed_m_s=AIRSPEED_M_S, max_items=4000))
    print(f"{len(site)} points: tour {mission.tour.length_m:,.0f} m by {mission.tour.planner}, "
          f"{len(mission.items)} items, {mission.summary['flight_time_s'] / 60:.1f} min")

    installed = working(exporters())
    names = ["site.plan", "site.waypoints"]
    names += [name for name, plugin in (("site.fence.plan", "plan-fence"), ("site.kml", "kml"))
              if plugin in installed]
    for name in names:
        print("wrote", exporter_for(name).write(mission, args.out / name))

    if args.fly:
        vehicle_mission = mission.for_vehicle()
        check = fly_mission(vehicle_mission, targets_in(vehicle_mission, mission.target_names),
                            Airframe.turning_at(AIRCRAFT_MIN_TURN_M, AIRSPEED_M_S),
                            speedup=args.speedup, max_items=4000)     # SD storage, as planned
        worst = int(np.argmax(check.miss_m))
        print(f"flown: completed {check.completed}, {check.items_reached}/{check.items} items, "
              f"{check.flight_time_s / 60:.1f} min; miss median {np.median(check.miss_m):.2f} m, "
              f"worst {check.miss_m[worst]:.1f} m at {check.names[worst]}")
        if not check.completed:
            raise SystemExit("the simulated flight did not complete the mission")


if __name__ == "__main__":
    main()
