"""Record ``tests/data/arduplane-sitl-speed-steps``: the real ArduPlane SITL (stock, calm)
flying airspeed steps (DO_CHANGE_SPEED 22 <-> 16.5 m/s) on long straight legs and into 90 deg
turns, for fitting and testing how the flight model's airspeed follows a change.

Needs the SITL binaries (``../shared/`` or ``DTSP_SITL_DIR``); a minute of wall time."""

from __future__ import annotations

import copy
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from dtsp_mission.export import read_mission  # noqa: E402
from dtsp_mission.frame import LocalFrame  # noqa: E402
from dtsp_mission.sitl import find_binaries, fly_real  # noqa: E402

#: The slow-zone recording's home and take-off are reused: its mission file is the template.
TEMPLATE = ROOT / "tests" / "data" / "arduplane-sitl-speed" / "mission.plan"
OUT = ROOT / "tests" / "data" / "arduplane-sitl-speed-steps"
FAST_M_S, SLOW_M_S, ALTITUDE_M = 22.0, 16.5, 120.0
#: After the take-off to the north: (east m, north m) of a waypoint, or an airspeed (m/s).
LEGS = [FAST_M_S, (0, 800), SLOW_M_S, (0, 2600), FAST_M_S, (0, 3800), SLOW_M_S, (0, 5000),
        FAST_M_S, (600, 5000), (600, 6200), SLOW_M_S, (0, 6200), (0, 7500)]


def mission_plan() -> dict:
    """The QGC plan: the template's take-off, then ``LEGS`` (5 m acceptance radius)."""
    plan = copy.deepcopy(json.loads(TEMPLATE.read_text()))
    home = plan["mission"]["plannedHomePosition"]
    frame = LocalFrame(home[0], home[1])
    items = [plan["mission"]["items"][0]]
    for leg in LEGS:
        if isinstance(leg, tuple):
            lat, lon = frame.to_geodetic(np.array([leg], dtype=float))
            params = [0.0, 5.0, 0.0, 0.0, float(lat[0]), float(lon[0]), ALTITUDE_M]
            items.append({"type": "SimpleItem", "command": 16, "frame": 3, "params": params,
                          "autoContinue": True})
        else:
            items.append({"type": "SimpleItem", "command": 178, "frame": 2,
                          "params": [0.0, leg, -1.0, 0.0, 0.0, 0.0, 0.0], "autoContinue": True})
    for number, item in enumerate(items, start=1):
        item["doJumpId"] = number
    plan["mission"]["items"] = items
    return plan


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "mission.plan").write_text(json.dumps(mission_plan(), indent=1))
    flight = fly_real(read_mission(str(OUT / "mission.plan"), None), find_binaries(), {},
                      progress=print)
    with (OUT / "track.csv").open("w") as handle:
        handle.write("time_s,east_m,north_m,relative_alt_m\n")
        for t, x, y, h in flight.track[:, :4]:
            handle.write(f"{t:.2f},{x:.3f},{y:.3f},{h:.2f}\n")
    with (OUT / "reached.csv").open("w") as handle:
        handle.write("seq,time_s\n")
        for seq, t in sorted(flight.reached.items()):
            handle.write(f"{seq},{t:.2f}\n")
    print(f"wrote {OUT}: {len(flight.track)} positions, last waypoint reached: {flight.completed}")


if __name__ == "__main__":
    main()
