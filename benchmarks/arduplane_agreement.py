"""The flight model against every recorded ArduPlane SITL flight; writes
``docs/arduplane-agreement.md``.

    python benchmarks/arduplane_agreement.py [--data DIR ...] [--out docs/arduplane-agreement.md]

Default: the three recorded sets of ``tests/data`` (stock parameters without wind, in wind, and
with two other tunings), a table each.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from dtsp_mission.bench.arduplane_agreement import cases, compare_case, markdown_table
from dtsp_mission.files import write_atomic

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"

SETS = {
    "arduplane-sitl": "Stock parameters, no wind (ArduPlane 4.7.0-dev)",
    "arduplane-sitl-wind": "Stock parameters in steady wind (ArduPlane 4.8.0-dev; `SIM_WIND_SPD` / "
                           "`SIM_WIND_DIR` of each case, full strength above 60 m; `guide_u60` "
                           "is the same mission without wind)",
    "arduplane-sitl-tuned": "Other navigation tunings, no wind (ArduPlane 4.8.0-dev; `_p18`: "
                            "NAVL1_PERIOD 18, NAVL1_DAMPING 0.85, WP_RADIUS 80; `_p12`: "
                            "NAVL1_PERIOD 12, WP_RADIUS 30, ROLL_LIMIT_DEG 45)",
}

INTRO = """# Flight model against real ArduPlane flights

Made by `benchmarks/arduplane_agreement.py` from the recorded ArduPlane SITL flights in
`tests/data/arduplane-sitl*` (the sets of `../shared/arduplane-sitl*`). Each mission is flown by
the compiled flight model (`dtsp_mission.autopilot.navigation.MissionFlight`) as the vehicle
stored it, with the case's recorded `params.parm` and its wind (`SIM_WIND_SPD`,
`SIM_WIND_DIR`, `SIM_WIND_T_ALT`), from rest at home facing the take-off item.

- *timing*: per item, |model - real| of the MISSION_ITEM_REACHED time after take-off, the
  model's times scaled to the real flight's duration (median and max over the items).
- *track*: distance of each real 10 Hz position, take-off end to the last item, from the
  model's track (median, 95th percentile, max).
- *closest*: per waypoint (hand-made cases) or per target (dtsp and guide cases), least
  distance of the whole track after take-off; the real and the model's median, and
  |model - real|.
- *flown*: track length over the same span.

Goals: timing within 2 s, track within 3 m (median) and 10 m (max), closest approach within
1 m (median) and 3 m (max); the last column names those a case misses. What the model takes
from the recordings (each fitted once, on all cases): the roll response (a roll rate asked for
in proportion to the bank error and limited to 1.5 x `RLL2SRV_RMAX`, followed with a lag: 4.4
rad/s, damping 0.5, 135 deg/s on the stock plane; fitted together with the real flights of the
project's own missions, `docs/real-flights.md`), the turn rate of the SITL airframe at 0.70 of the coordinated-turn rate for its bank at
the airspeed it flies in that bank (1 m/s faster per unit of 1 / cos(bank) - 1: 22.3-22.9 m/s at
45-55 deg in the recordings),
the take-off run (5.3 m/s^2, lift-off at 85 % of the cruise airspeed) and climb, and the
climb-out's airspeed (the take-off ends at 1.265 of the cruise airspeed, held 1.3 s, then
bled off at 1.67 m/s^2; all 31 recordings, at cruise 22 m/s, peak at 27.9-28.1 m/s after the
take-off, the model at 27.8, RMS 0.3 m/s over the 8 s after it); everything else is
ArduPlane's L1 law (with its cross-track integrator `NAVL1_XTRACK_I` and its guard against
indecision), its waypoint completion (the turn angle towards the next navigation item,
loiters included) and mission logic, acting on the ground velocity, with the case's
parameters.

Known differences:
- the take-off: the real aircraft's climb-out and first turn towards the first waypoint are
  not the model's, so the track max of several cases (`zigzag*`, most wind cases: 8-29 m) is
  8-13 s after the take-off (`zigzag`: 21.3 m at 8.7 s, at most 6.3 m after 25 s; in wind at
  most 12.7 m after 25 s); no target lies there;
- `dtsp_u40_margin`'s 72 m is one place (target at seq 217, acceptance 5 m) where ArduPlane
  passed the target just outside its acceptance radius and turned back for it, while the
  model passed within it;
- `guide_u60_w9_40`'s 23.5 m is one target (t03) that the real aircraft missed by 45 m and the
  model by much less (37 m less before the model flew faster in banks; both count about 24 of
  the 60 targets beyond 5 m in that wind; the mission was designed for calm air).

"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, action="append",
                        help="a folder of recorded cases (repeatable; default the three sets)")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "arduplane-agreement.md")
    args = parser.parse_args()
    folders = args.data or [DATA / name for name in SETS]
    started = time.perf_counter()
    text = INTRO
    everything = []
    for folder in folders:
        results = []
        for case in cases(folder):
            results.append(compare_case(case))
            print(f"{folder.name}/{case.name}: done", flush=True)
        everything += results
        table = markdown_table(results)
        print(table)
        text += f"## {SETS.get(folder.name, folder.name)}\n\n`{folder.name}`\n\n{table}\n"
    approach = np.array([r.approach_max_m for r in everything])
    text += (f"Over all {len(everything)} cases: closest |diff| max median "
             f"{np.median(approach):.1f} m, 90th percentile {np.percentile(approach, 90):.1f} m; "
             f"{time.perf_counter() - started:.0f} s.\n")
    write_atomic(args.out, text)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
