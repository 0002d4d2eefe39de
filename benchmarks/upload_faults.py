"""Uploads over a damaged link: ``dtsp-mission``'s pymavlink uploader through the fault proxy
(loss, duplicates, reordering, delay in both directions, seeded) to the simulated ArduPilot
vehicle, 20 runs per row, every upload verified by download as the CLI does.

For every run the vehicle itself is inspected afterwards: a reported success while the
vehicle differs from the plan is counted as a FALSE SUCCESS, and after a failure the
uploader's sentence about what the vehicle holds is checked against what it really holds.
Prints a Markdown table; ``--markdown FILE`` writes it there.

Run: python benchmarks/upload_faults.py --markdown docs/upload-faults.md   (about 30 minutes)
"""

from __future__ import annotations

import argparse
import statistics
from collections import Counter
import sys
import time

from dtsp_mission.errors import LinkError
from dtsp_mission.files import write_atomic
from dtsp_mission.mission import Autopilot, Home, VehicleMission
from dtsp_mission.mission.model import waypoint
from dtsp_mission.sim.fault_proxy import FaultProxy, Faults
from dtsp_mission.sim.vehicle import SimulatedVehicle, VehicleSettings
from dtsp_mission.upload import upload_mission
from dtsp_mission.autopilot.wire import describe_vehicle, differences, to_wire

HOME = Home(46.8, 6.95, 450.0)
#: Mission slots of the vehicle: an ArduPilot board with SD storage (a stock one holds 655).
STORAGE = 4000

#: (mission slots, loss, duplicates, reordering, delay_s[, transfer timeout_s]): the issue's
#: rows, the clean references the time ratio is taken against, and a link so bad (with a short
#: --timeout) that uploads fail, to check what the failures say against what the vehicle holds.
ROWS = [
    (100, 0.0, 0.0, 0.0, 0.0),
    (100, 0.05, 0.0, 0.0, 0.0),
    (100, 0.20, 0.0, 0.0, 0.0),
    (100, 0.05, 0.10, 0.10, 0.020),
    (1000, 0.0, 0.0, 0.0, 0.0),
    (1000, 0.05, 0.0, 0.0, 0.0),
    (1000, 0.05, 0.10, 0.10, 0.020),
    (1000, 0.20, 0.0, 0.0, 0.0),
    (1000, 0.20, 0.10, 0.10, 0.0),
    (300, 0.50, 0.0, 0.0, 0.0, 3.0),
]


def synthetic_mission(slots: int, altitude_m: float = 100.0) -> VehicleMission:
    """``slots`` mission slots (ArduPilot's home included) of waypoints on a 10 m grid."""
    items = tuple(waypoint(HOME.latitude_deg + 1e-4 * (k // 100), HOME.longitude_deg + 1e-4 * (k % 100),
                           altitude_m) for k in range(slots - 1))
    return VehicleMission(items, HOME, Autopilot.ARDUPILOTMEGA)


def one_run(mission: VehicleMission, faults: Faults, earlier: VehicleMission,
            timeout_s: float | None = None) -> dict:
    """One verified upload over the damaged link to a vehicle that holds ``earlier``."""
    wire = to_wire(mission)
    with SimulatedVehicle(VehicleSettings(HOME, mission.autopilot, max_items=STORAGE)) as vehicle:
        vehicle.mission = to_wire(earlier)
        with FaultProxy(("127.0.0.1", vehicle.port), faults) as proxy:
            started = time.perf_counter()
            try:
                report = upload_mission(mission, f"udpout:127.0.0.1:{proxy.port}", timeout_s=timeout_s,
                                        heartbeat_timeout_s=20.0)
            except LinkError as error:
                elapsed = time.perf_counter() - started
                while vehicle.server.receiving:        # until it gives the upload up itself
                    time.sleep(0.1)
                truth = describe_vehicle(vehicle.mission, wire, mission.autopilot)
                said = error.on_vehicle
                # honest: the true state, or a plain "unknown" / "not verified"
                honest = said == truth or "unknown" in said or "not verified" in said
                return {"ok": False, "seconds": elapsed, "reason": error.reason[:70],
                        "honest": honest, "said": said, "truth": truth}
            holds = not differences(wire, vehicle.mission, mission.autopilot)
            return {"ok": holds, "false_success": not holds, "seconds": report.seconds,
                    "transfer_s": report.transfer_s, "resent": report.resent,
                    "fresh": report.fresh_starts, "rtt": report.round_trip_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown")
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--rows", help="comma-separated row numbers (1-based) to run")
    args = parser.parse_args()
    chosen = [ROWS[int(k) - 1] for k in args.rows.split(",")] if args.rows else ROWS
    earlier = synthetic_mission(30, altitude_m=150.0)
    lines = ["| slots | loss each way | duplicates | reordering | delay | verified | false successes "
             "| failures: what the vehicle was said to hold | median transfer (s) | max (s) "
             "| median total (s) | x clean | resent per slot | fresh starts |",
             "|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
    clean: dict[int, float] = {}
    for slots, loss, duplicate, reorder, delay, *timeout in chosen:
        mission = synthetic_mission(slots)
        runs = []
        for seed in range(args.runs):
            faults = Faults(drop=loss, duplicate=duplicate, reorder=reorder, delay_s=delay, seed=seed)
            runs.append(one_run(mission, faults, earlier, *timeout))
            print(f"  {slots} {loss:.0%} {duplicate:.0%} {reorder:.0%} {delay * 1000:.0f} ms seed {seed}: "
                  f"{runs[-1]}", file=sys.stderr, flush=True)
        good = [r for r in runs if r["ok"]]
        false = sum(r.get("false_success", False) for r in runs)
        failures = [r for r in runs if not r["ok"] and "honest" in r]
        said = "; ".join(f"{count}x {text}" for text, count in sorted(Counter(
            ("" if r["honest"] else f"WRONG (it held: {r['truth']}): ") + r["said"]
            for r in failures).items())) or "-"
        transfer = statistics.median(r["transfer_s"] for r in good) if good else float("nan")
        total = statistics.median(r["seconds"] for r in good) if good else float("nan")
        worst = max((r["transfer_s"] for r in good), default=float("nan"))
        if loss == duplicate == reorder == delay == 0:
            clean[slots] = transfer
        ratio = f"{transfer / clean[slots]:.1f}" if slots in clean and good else "-"
        resent = statistics.median(r["resent"] / slots for r in good) if good else float("nan")
        fresh = sum(r["fresh"] for r in good)
        limit = f" (--timeout {timeout[0]:g})" if timeout else ""
        line = (f"| {slots}{limit} | {loss:.0%} | {duplicate:.0%} | {reorder:.0%} | {delay * 1000:.0f} ms | "
                f"{len(good)}/{len(runs)} | {false} | {said} | {transfer:.2f} | {worst:.2f} | {total:.2f} | "
                f"{ratio} | {resent:.2f} | {fresh} |")
        print(line, flush=True)
        lines.append(line)
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        write_atomic(args.markdown, "# Uploads over a damaged link\n\nProduced by "
                     "`python benchmarks/upload_faults.py --markdown docs/upload-faults.md`: the "
                     "pymavlink uploader through the fault proxy (seeded; loss, duplicates and "
                     "reordering per datagram in both directions, delay uniform up to the value) "
                     "to the simulated ArduPilot vehicle (4,000 slots, as a board with SD storage) holding an "
                     "earlier 30-slot mission; "
                     f"{args.runs} runs per row, each upload verified by download.  *Transfer*: "
                     "the upload and its verification download; *total*: with connecting and the "
                     "vehicle checks (heartbeat, parameters, home); *x clean*: median transfer "
                     "against the clean row of the same size.  *False successes*: runs reported "
                     "verified while the vehicle, inspected afterwards, held something else.\n\n"
                     + table + "\n")


if __name__ == "__main__":
    main()
