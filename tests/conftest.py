"""Shared test helpers: every tour any test builds goes through the same checker."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import settings

from dtsp_mission.tour import Tour, check_tour

settings.register_profile("ci", deadline=None, derandomize=True, print_blob=True)
settings.load_profile("ci")


def environment_with_distribution(directory, name: str, entry_points: str) -> dict[str, str]:
    """Process environment in which an installed distribution ``name`` 1.0 with the given
    ``entry_points.txt`` text is on the path (how a third-party plugin looks to Python)."""
    import os
    dist = directory / f"{name.replace('-', '_')}-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(entry_points)
    return dict(os.environ, PYTHONPATH=str(directory) + os.pathsep + os.environ.get("PYTHONPATH", ""))


def assert_valid_tour(tour: Tour) -> None:
    """Fail with the checker's own list of problems unless ``tour`` is valid."""
    report = check_tour(tour)
    assert report.ok, report.summary() + "\n" + "\n".join(report.problems)


_WARM_UP_TARGETS = "lat,lon\n" + "".join(
    f"{47.3977 + 0.004 * (k % 4):.6f},{8.5456 + 0.006 * (k // 4):.6f}\n" for k in range(12))


def pytest_configure(config) -> None:
    """On a machine where the compiled kernels are not cached yet (a fresh clone), compile
    them once before the workers start: otherwise each worker and each command a test runs
    compiles them at the same time (about 80 s of CPU each)."""
    import os
    import subprocess
    import sys
    import tempfile
    from dtsp_mission.compiled import kernels_cached
    if hasattr(config, "workerinput") or kernels_cached():
        return
    with tempfile.TemporaryDirectory() as folder:
        targets = os.path.join(folder, "targets.csv")
        with open(targets, "w") as file:
            file.write(_WARM_UP_TARGETS)
        plan = [sys.executable, "-m", "dtsp_mission.cli", "plan", targets, "--radius", "80", "-q"]
        # two processes at once, one per core, each compiling its part (51 s instead of 82 s
        # in one on 2 cores): the tour's improver (the planner's own kernels) and, from the
        # Alternating Algorithm's tour, a guidance design in wind (the Dubins, wind tour and
        # flight model kernels)
        parts = [plan + ["-o", os.path.join(folder, "warm.json")],
                 plan + ["--algorithm", "alternating", "--airspeed", "22", "--alt", "120",
                         "--wind", "5@90", "-o", os.path.join(folder, "warm.plan")]]
        running = [subprocess.Popen(part, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                   for part in parts]
        for process in running:
            try:
                process.wait(timeout=600)
            except subprocess.TimeoutExpired:
                process.kill()


def pytest_collection_modifyitems(items: list) -> None:
    """The tests marked ``heavy`` first, longest first (``seconds``: as measured on 2 cores),
    then the rest: started last, a test of minutes would keep one worker busy long after the
    others are done."""
    def key(item) -> tuple[bool, float]:
        heavy = item.get_closest_marker("heavy")
        return heavy is None, -(heavy.kwargs.get("seconds", 0.0) if heavy else 0.0)
    items.sort(key=key)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


def make_mission(count: int = 40, seed: int = 7, rho_m: float = 80.0, centre=(46.8, 6.95),
                 span_m: float = 3000.0, **settings):
    """A small planned mission around ``centre``: ``count`` seeded random targets."""
    from dtsp_mission.frame import LocalFrame
    from dtsp_mission.mission import MissionSettings, build_mission
    from dtsp_mission.planning import get_planner
    from dtsp_mission.targets.model import local_targets

    frame = LocalFrame(*centre)
    positions = np.random.default_rng(seed).uniform(-span_m / 2, span_m / 2, (count, 2))
    targets = local_targets(positions).to_geodetic(frame)
    targets = type(targets)(targets.latitudes_deg, targets.longitudes_deg,
                            tuple(f"t{i}" for i in range(count)), 0, settings.pop("altitudes", None))
    local = targets.in_frame(frame)
    tour = get_planner("alternating").plan(local.positions_m, rho_m)
    return build_mission(tour, frame, targets, MissionSettings(**settings))


def free_udp_port() -> int:
    import socket
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.fixture(scope="session")
def mavsdk_mission_raw():
    """MAVSDK's ``MissionRaw`` plugin of a ground station connected over loopback UDP to a
    MAVSDK autopilot component: the real importers (QGC .plan, Mission Planner text) need a
    system, and this is the smallest real one."""
    from mavsdk import ComponentType, Configuration, Mavsdk
    from mavsdk.plugins.mission_raw import MissionRaw
    from dtsp_mission.mavsdk_log import quiet_mavsdk_log

    # Once per process, before any MAVSDK instance runs: subscribing again while MAVSDK's
    # threads log frees the callback they are calling (a segfault seen in a test run).
    quiet_mavsdk_log()
    port = free_udp_port()
    ground = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
    ground.add_any_connection(f"udpin://127.0.0.1:{port}")
    vehicle = Mavsdk(Configuration.create_with_component_type(ComponentType.AUTOPILOT))
    vehicle.add_any_connection(f"udpout://127.0.0.1:{port}")
    vehicle.server_component()
    system = ground.first_autopilot(10.0)
    assert system is not None, "the loopback MAVSDK autopilot did not appear"
    yield MissionRaw(system)
    vehicle.destroy()
    ground.destroy()


@pytest.fixture
def start_vehicle():
    """``start_vehicle(mission, **settings)``: a simulated vehicle at the mission's home on a
    free loopback port, stopped when the test ends."""
    from dtsp_mission.autopilot.navigation import Airframe
    from dtsp_mission.sim.vehicle import SimulatedVehicle, VehicleSettings
    started = []

    def start(mission, **settings):
        settings.setdefault("airframe", Airframe.turning_at(80.0, 20.0))
        settings.setdefault("autopilot", mission.autopilot)
        vehicle = SimulatedVehicle(VehicleSettings(mission.home, **settings))
        started.append(vehicle.start())
        return vehicle

    yield start
    for vehicle in started:
        vehicle.stop()


def fence_poses(posts_per_side: int = 8, gap_m: float = 40.0):
    """Posts of a square fence ``gap_m`` apart, visited along its sides: (points (n, 2),
    headings (n,)) in a local frame.  Each corner is a sharp turn between close posts -- a
    loop of the exact Dubins path, as at the bundled site's fence."""
    import math
    side = posts_per_side * gap_m
    points, headings = [], []
    for (x, y), (dx, dy) in (((0, 0), (1, 0)), ((side, 0), (0, 1)), ((side, side), (-1, 0)),
                             ((0, side), (0, -1))):
        for j in range(posts_per_side):
            points.append((x + dx * gap_m * j, y + dy * gap_m * j))
            headings.append(math.atan2(dy, dx))
    return np.array(points), np.array(headings)

