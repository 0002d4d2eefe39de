"""Acceptance flights in the real autopilots: missions made by ``dtsp-mission plan`` (a real
process, default design) flown by ArduPlane SITL and PX4 SITL (SIH) to the end, every target
within 5 m of the real track.

Run where the SITL builds are (``DTSP_SITL_DIR`` or the workplace's ``shared/``: CI has them);
skipped with the reason elsewhere.  The sites here are none of the benchmark's
(``benchmarks/real_flights.py``), so the design is not tuned to them.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dtsp_mission.autopilot.navigation import Airframe, Wind
from dtsp_mission.autopilot.parameters import PX4_DEFAULTS
from dtsp_mission.export import read_mission
from dtsp_mission.frame import LocalFrame
from dtsp_mission.sitl import compare_with_model, find_binaries, fly_real
from dtsp_mission.targets.model import local_targets

BINARIES = find_binaries()
CLI = [sys.executable, "-m", "dtsp_mission.cli"]
HOME = (46.5197, 6.6323)          # none of the benchmark's sites
MAX_MISS_M = 5.0


def _needs(autopilot: str):
    why = BINARIES.missing(autopilot)
    return pytest.mark.skipif(why is not None, reason=f"real {autopilot} SITL not here: {why}")


def _plan(tmp_path: Path, count: int, seed: int, *options: str, side_m: float = 2000.0,
          alt_m: float = 120.0) -> Path:
    """A mission over ``count`` seeded uniform targets in a square of ``side_m`` at HOME,
    planned by the command line as an operator would."""
    points = np.random.default_rng(seed).uniform(-side_m / 2, side_m / 2, (count, 2))
    targets = local_targets(points).to_geodetic(LocalFrame(*HOME))
    csv = tmp_path / "targets.csv"
    csv.write_text("lat,lon,name\n" + "".join(
        f"{la:.8f},{lo:.8f},p{k}\n" for k, (la, lo) in enumerate(zip(targets.latitudes_deg,
                                                                     targets.longitudes_deg))))
    out = tmp_path / "mission.plan"
    done = subprocess.run(CLI + ["plan", str(csv), "--radius", "80", "--alt", str(alt_m),
                                 "--home", f"{HOME[0]},{HOME[1]}", "-q", "-o", str(out), *options],
                          capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stderr
    return out


def _instance() -> int:
    """A SITL instance (ports) of this test worker's own, apart from the benchmark's (0)."""
    import os
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    return 2 + int(worker[2:] or 0) if worker.startswith("gw") else 2


def _fly_and_check(plan: Path, wind: Wind = Wind(), parameters: dict | None = None,
                   airframe: Airframe = Airframe(), speedup: float | None = None):
    mission = read_mission(str(plan), None)
    flight = fly_real(mission, BINARIES, parameters, wind, speedup=speedup, instance=_instance(),
                      timeout_s=400)
    if not flight.reached:
        # the SITL never flew (a CI run once saw PX4's SIH end its flight 5 s after the upload,
        # nothing reached, on a busy machine): a start that failed, not a miss -- once more
        flight = fly_real(mission, BINARIES, parameters, wind, speedup=speedup,
                          instance=_instance(), timeout_s=400)
    assert flight.upload.verified
    assert flight.completed, f"the last waypoint was not reached: {sorted(flight.reached)[-3:]}"
    report = compare_with_model(mission, flight, airframe, wind)
    assert len(report.real_miss_m) == len(mission.targets) > 0
    beyond = [f"{n} {m:.1f} m (model {p:.1f})" for n, m, p in
              zip(report.names, report.real_miss_m, report.model_miss_m) if m > MAX_MISS_M]
    assert beyond == [], f"real {mission.autopilot.name} missed " + ", ".join(beyond)
    return report


@pytest.mark.heavy(seconds=22)
@_needs("ardupilot")
def test_arduplane_flies_every_target_within_5_m_in_calm_air(tmp_path):
    report = _fly_and_check(_plan(tmp_path, 30, 11, "--airspeed", "22"))
    # the flight is about as long as the model says it is
    assert abs(report.real_flown_m - report.model_flown_m) < 0.03 * report.model_flown_m


@pytest.mark.heavy(seconds=30)
@_needs("ardupilot")
def test_arduplane_flies_every_target_within_5_m_in_the_wind_it_was_designed_for(tmp_path):
    wind = Wind(5.0, 250.0)
    _fly_and_check(_plan(tmp_path, 25, 12, "--airspeed", "22", "--wind", "5@250"), wind)


@pytest.mark.heavy(seconds=75)
@_needs("px4")
def test_px4_flies_every_target_within_5_m_in_calm_air(tmp_path):
    # 20 targets over 1 km at 60 m: the flight is about 6 min (at 1.5 km and 120 m, 9.5 min)
    plan = _plan(tmp_path, 20, 13, "--airspeed", "18", "--autopilot", "px4", side_m=1000.0,
                 alt_m=60.0)
    # PX4's SIH runs on the wall clock: sped up only 6 times, so that the other test
    # worker's load does not change the flight
    _fly_and_check(plan, airframe=Airframe.from_px4_parameters(PX4_DEFAULTS), speedup=6.0)


def test_a_missing_autopilot_is_named_not_flown(tmp_path, monkeypatch):
    """Without the builds, a real flight says where it looked, and nothing is started."""
    from dtsp_mission.errors import LinkError
    from dtsp_mission.sitl.binaries import SitlBinaries
    from conftest import make_mission
    mission = make_mission(5, 3, 80.0, span_m=800.0, airspeed_m_s=22.0).for_vehicle()
    nowhere = SitlBinaries(None, None, (tmp_path,))
    with pytest.raises(LinkError, match="arduplane-sitl-bin"):
        fly_real(mission, nowhere)
