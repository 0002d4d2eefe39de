"""Upload time on loopback UDP to the simulated vehicle (its own ArduPilot-like mission
server), for 100, 1000 and 5000 items, each uploader, with and without datagram loss.

Prints a Markdown table (median of the repeats; failures are shown, not hidden) and, with
``--markdown FILE``, writes it there.  Run: python benchmarks/upload_times.py --markdown docs/upload-benchmark.md
"""

from __future__ import annotations

import argparse
import statistics
import time

from dtsp_mission.errors import LinkError
from dtsp_mission.files import write_atomic
from dtsp_mission.mission import Autopilot, Home, VehicleMission
from dtsp_mission.mission.model import waypoint
from dtsp_mission.sim.fault_proxy import FaultProxy, Faults
from dtsp_mission.sim.vehicle import SimulatedVehicle, VehicleSettings
from dtsp_mission.upload import upload_mission
from dtsp_mission.autopilot.wire import differences, to_wire

HOME = Home(46.8, 6.95, 450.0)


def synthetic_mission(count: int) -> VehicleMission:
    """``count`` items (home included) of waypoints on a 10 m grid."""
    items = tuple(waypoint(HOME.latitude_deg + 1e-4 * (k // 100), HOME.longitude_deg + 1e-4 * (k % 100),
                           100.0) for k in range(count - 1))
    return VehicleMission(items, HOME, Autopilot.ARDUPILOTMEGA)


def one_upload(mission: VehicleMission, via: str, loss: float, seed: int) -> tuple[float, str]:
    with SimulatedVehicle(VehicleSettings(HOME, mission.autopilot, max_items=6000)) as vehicle:
        target = ("127.0.0.1", vehicle.port)
        faults = Faults(drop=loss, seed=seed)
        with FaultProxy(target, faults) as proxy:
            port = proxy.port if loss else vehicle.port
            started = time.perf_counter()
            try:
                upload_mission(mission, f"udpout:127.0.0.1:{port}", via=via, verify=False)
                elapsed = time.perf_counter() - started
                waited = time.monotonic() + 5     # the vehicle stores the mission after its ACK
                while not vehicle.uploads and time.monotonic() < waited:
                    time.sleep(0.01)
                same = not differences(to_wire(mission), vehicle.mission, mission.autopilot)
                return elapsed, "ok" if same else "vehicle differs"
            except LinkError as error:
                return time.perf_counter() - started, f"failed: {error.reason[:60]}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    cases = [(100, 0.0), (1000, 0.0), (5000, 0.0), (100, 0.05), (1000, 0.05), (100, 0.2)]
    lines = ["| items | loss each way | uploader | median time (s) | items/s | runs ok |",
             "|---:|---:|---|---:|---:|---|"]
    for count, loss in cases:
        mission = synthetic_mission(count)
        for via in ("pymavlink", "mavsdk"):
            if via == "mavsdk" and loss:
                continue     # MAVSDK's own retry timing; measured without loss only
            repeats = 1 if count >= 5000 else args.repeats
            runs = [one_upload(mission, via, loss, seed) for seed in range(repeats)]
            good = [t for t, status in runs if status == "ok"]
            statuses = sorted({s for _, s in runs if s != "ok"})
            median = statistics.median(good) if good else float("nan")
            line = (f"| {count} | {loss:.0%} | {via} | {median:.2f} | {count / median:.0f} | "
                    f"{len(good)}/{repeats}{'; ' + '; '.join(statuses) if statuses else ''} |")
            print(line, flush=True)
            lines.append(line)
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        write_atomic(args.markdown, "# Upload times on loopback\n\nProduced by "
                     "`python benchmarks/upload_times.py --markdown docs/upload-benchmark.md` "
                     "(upload only, no verification download; the simulated vehicle serves the "
                     "mission protocol as ArduPilot does, with 6,000 slots; loss is the fault "
                     "proxy dropping datagrams in both directions; the verified, faulty-link "
                     "figures are in upload-faults.md).\n\n" + table + "\n")


if __name__ == "__main__":
    main()
