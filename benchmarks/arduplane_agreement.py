"""The flight model against every recorded ArduPlane SITL flight; writes
``docs/arduplane-agreement.md``.

    python benchmarks/arduplane_agreement.py [--data tests/data/arduplane-sitl] [--out docs/arduplane-agreement.md]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from dtsp_mission.bench.arduplane_agreement import cases, compare_case, markdown_table
from dtsp_mission.files import write_atomic

ROOT = Path(__file__).resolve().parents[1]

INTRO = """# Flight model against real ArduPlane flights

Made by `benchmarks/arduplane_agreement.py` from the recorded ArduPlane SITL flights in
`tests/data/arduplane-sitl` (ArduPlane 4.7.0-dev, stock `plane.parm`, no wind). Each mission is
flown by `dtsp_mission.autopilot.navigation.MissionFlight` as the vehicle stored it, with the
case's recorded `params.parm`, from rest at home facing the take-off item.

- *timing*: per item, |model - real| of the MISSION_ITEM_REACHED time after take-off, the
  model's times scaled to the real flight's duration (median and max over the items).
- *track*: distance of each real 10 Hz position, take-off end to the last item, from the
  model's track (median, 95th percentile, max).
- *closest*: per waypoint (hand-made cases) or per target (dtsp cases), least distance of the
  whole track after take-off; the real and the model's median, and |model - real|.
- *flown*: track length over the same span.

Goals of the simulator issue: timing within 2 s, track within 3 m (median) and 10 m (max),
closest approach within 1 m (median) and 3 m (max); the last column names those a case
misses. What the model takes from the recordings (each fitted once, on all cases): the roll
response (4.4 rad/s, damping 0.6, from the recorded roll steps), the turn rate of the SITL
airframe at 0.73 of the coordinated-turn rate for its bank (regression of course rate on roll
gave 0.73-0.80 per case), the take-off run and climb; everything else is ArduPlane's L1 law
and mission logic with the case's `params.parm`.

Known differences: `dtsp_u40_margin`'s 72 m is one place (target at seq 217, acceptance 5 m)
where ArduPlane passed the target just outside its acceptance radius and turned back for it,
while the model passed within it; the loiter exits leave 3-4 m to one side of the real ones.

"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=ROOT / "tests" / "data" / "arduplane-sitl")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "arduplane-agreement.md")
    args = parser.parse_args()
    started = time.perf_counter()
    results = []
    for folder in cases(args.data):
        results.append(compare_case(folder))
        print(f"{folder.name}: done", flush=True)
    table = markdown_table(results)
    print(table)
    write_atomic(args.out, INTRO + table + f"\n{len(results)} cases in "
                      f"{time.perf_counter() - started:.0f} s.\n")
    print("wrote", args.out)


if __name__ == "__main__":
    main()
