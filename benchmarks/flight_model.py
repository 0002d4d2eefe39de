"""How fast the compiled flight model flies a whole mission; prints a table.

    python benchmarks/flight_model.py [MISSION.plan ...] [--repeats 7] [--step 0.02]

Without missions, the recorded ArduPlane SITL missions of ``tests/data/arduplane-sitl`` and
the bundled site's mission (planned first at rho 80 m, 22 m/s, 120 m with the guidance design)
are flown.  Per mission: the flown length, the median over the repeats of one whole flight
(kernel only: the state stepped from take-off to the last item with every target's closest
approach kept; and the whole ``predict_flight``, which also converts the mission and records
the track), and steps per second.  The first, compiling flight is not counted.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from dtsp_mission.autopilot import Command, stored_item  # noqa: E402
from dtsp_mission.autopilot.navigation import (MODEL_STEP_S, Airframe, MissionFlight,  # noqa: E402
                                               local_items)
from dtsp_mission.export import read_mission  # noqa: E402
from dtsp_mission.frame import LocalFrame  # noqa: E402
from dtsp_mission.sim.predict import predict_flight  # noqa: E402
from dtsp_mission.autopilot.wire import first_mission_seq, to_wire  # noqa: E402


def bundled_mission(folder: Path) -> Path:
    """The README's mission of the bundled site, planned into ``folder``."""
    out = folder / "site.plan"
    if not out.exists():
        from click.testing import CliRunner
        from dtsp_mission.cli.main import cli
        result = CliRunner().invoke(cli, ["plan", str(ROOT / "examples" / "site-inspection.csv"),
                                          "--radius", "80", "--alt", "120", "--airspeed", "22",
                                          "-o", str(out), "--quiet"])
        if result.exit_code != 0:
            raise SystemExit(result.output)
    return out


def measure(path: Path, repeats: int, step_s: float) -> list[str]:
    mission = read_mission(path)
    airframe = Airframe.from_parameters()
    frame = LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg)
    wire = [stored_item(item, mission.autopilot) for item in to_wire(mission)]
    items = local_items(wire, frame, mission.home.altitude_amsl_m)
    targets = np.array([(i.x_m, i.y_m) for i in items if i.command == Command.NAV_WAYPOINT
                        and i.params[1] > 0]).reshape(-1, 2)
    first = first_mission_seq(mission.autopilot)
    last = max(i.seq for i in items if i.command == Command.NAV_WAYPOINT)
    heading = float(np.arctan2(items[first].y_m, items[first].x_m)) if items[first].x_m == items[first].x_m else 0.0

    def kernel_only():
        flight = MissionFlight(items, airframe, heading, first)
        run = flight.run(step_s, last, track=False, points_m=targets, measure_from_seq=first + 1)
        return flight, run

    flight, run = kernel_only()              # compiles (or loads the cache)
    predict_flight(mission, airframe, step_s)
    kernel, whole = [], []
    for _ in range(repeats):
        started = time.perf_counter()
        flight, run = kernel_only()
        kernel.append(time.perf_counter() - started)
        started = time.perf_counter()
        predict_flight(mission, airframe, step_s)
        whole.append(time.perf_counter() - started)
    tracemalloc.start()
    predict_flight(mission, airframe, step_s)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    steps = flight.time_s / step_s
    k = statistics.median(kernel)
    return [path.parent.name if path.name == "mission.plan" else path.name, f"{len(items)}",
            f"{len(targets)}", f"{run.measured_length_m / 1e3:.1f}", f"{1e3 * k:.1f}",
            f"{1e3 * statistics.median(whole):.1f}", f"{steps / k / 1e6:.2f}",
            f"{peak / 2**20:.1f}"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("missions", nargs="*", type=Path)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--step", type=float, default=MODEL_STEP_S)
    parser.add_argument("--work", type=Path, default=Path("/tmp/dtsp-flight-model-bench"))
    args = parser.parse_args()
    missions = args.missions
    if not missions:
        args.work.mkdir(parents=True, exist_ok=True)
        data = ROOT / "tests" / "data" / "arduplane-sitl"
        missions = [p / "mission.plan" for p in sorted(data.iterdir()) if (p / "mission.plan").exists()]
        missions.append(bundled_mission(args.work))
    header = ["mission", "items", "targets", "flown km", "flight (kernel) ms",
              "predict_flight ms", "M steps/s", "peak MiB"]
    print(f"step {args.step} s, median of {args.repeats} runs, one core")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for path in missions:
        print("| " + " | ".join(measure(path, args.repeats, args.step)) + " |", flush=True)


if __name__ == "__main__":
    main()
