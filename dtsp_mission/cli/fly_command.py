"""``dtsp-mission fly``: fly a mission file in the simulator and report how close it passed
each target -- the check before a real flight."""

from __future__ import annotations

import click
import numpy as np

from ..autopilot.navigation import CALM, check_wind
from ..sim.fly import (FlightCheck, check_targets_near, estimated_flight_m, fly_mission,
                       targets_from, targets_in)
from . import console
from .console import console_options, note, record, say
from .options import (UserError, apply, progress_reporter, reports_errors, simulation_options,
                      vehicle_options)
from .sim_command import airframe_from


def run_flight_check(mission, targets, airframe, via: str, speedup: float,
                     max_miss_m: float | None, max_items: int | None = None,
                     wind=None) -> FlightCheck:
    """Fly, print the report, and fail (exit 1) when ``max_miss_m`` is exceeded (shared with
    ``plan --simulate``)."""
    _say_estimate(mission, airframe, speedup)
    progress, close = progress_reporter("flying")
    try:
        check = fly_mission(mission, targets, airframe, via=via, speedup=speedup, max_items=max_items,
                            wind=wind or CALM,
                            progress=lambda stage, done, total: progress(done, total)
                            if stage == "flight" else None)
    finally:
        close()
    print_check(check)
    if max_miss_m is not None and check.max_miss_m > max_miss_m:
        raise click.ClickException(f"a target was missed by {check.max_miss_m:.1f} m, more than "
                                   f"--max-miss {max_miss_m:g} m")
    return check


def _say_estimate(mission, airframe, speedup: float) -> None:
    """Say up front how long the flight will take (flight time, and the wait at ``speedup``)."""
    length = estimated_flight_m(mission, airframe.loiter_radius_m)
    flight_s = length / airframe.airspeed_m_s
    wait = (f"about {_duration(flight_s / speedup)} to simulate at --speedup {speedup:g}"
            if speedup > 0 else "simulated as fast as it computes")
    say(f"flying about {length / 1000:,.1f} km, {_duration(flight_s)} of flight; {wait}")


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    minutes = int(round(seconds / 60))
    return f"{minutes // 60} h {minutes % 60:02d} min" if minutes >= 60 else f"{minutes} min"


def print_check(check: FlightCheck) -> None:
    minutes = check.flight_time_s / 60
    state = "completed" if check.completed else "NOT completed"
    record(flight={"completed": check.completed, "items_reached": check.items_reached,
                   "items": check.items, "flight_time_s": check.flight_time_s,
                   "min_turn_radius_m": check.min_turn_radius_m, "position_reports": check.samples,
                   "targets": [{"name": name, "miss_m": miss,
                                "altitude_error_m": altitude if np.isfinite(altitude) else None}
                               for name, miss, altitude in zip(check.names, check.miss_m,
                                                               check.altitude_error_m)],
                   "max_miss_m": check.max_miss_m})
    say(f"simulated flight {state}: {check.items_reached} of {check.items} items, "
               f"{minutes:.1f} min of flight (L1 period {check.airframe.l1_period_s:g} s, "
               f"min turn radius {check.airframe.min_turn_radius_m:g} m)")
    say(f"uploaded via {check.upload.via} in {check.upload.seconds:.2f} s; "
               f"{check.samples} position reports received")
    say(f"smallest turn radius in the telemetry: {check.min_turn_radius_m:.1f} m")
    if len(check.miss_m):
        say(f"targets passed within: median {np.median(check.miss_m):.2f} m, max "
                   f"{check.max_miss_m:.2f} m")
        say("target\tmiss_m\taltitude_error_m")
        for name, miss, altitude in zip(check.names, check.miss_m, check.altitude_error_m):
            say(f"{name}\t{miss:.2f}\t" + (f"{altitude:+.1f}" if np.isfinite(altitude)
                                            else "-"))    # no altitude given for the target


@click.command()
@click.argument("mission_file", type=click.Path(dir_okay=False))
@apply(vehicle_options)
@apply(simulation_options)
@click.option("--via", default="pymavlink", show_default=True, help="Uploader to use.")
@click.option("--format", "format_name", help="Format of MISSION_FILE, whatever its extension.")
@click.option("--max-miss", "max_miss_m", type=float, metavar="METRES",
              help="Exit with status 1 if any target is missed by more than this.")
@click.option("--max-items", type=int, metavar="N", help="Mission slots of the simulated "
              "vehicle (default: a stock vehicle's, ArduPlane 655, PX4 500).")
@click.option("--targets", "targets_file", type=click.Path(dir_okay=False), metavar="FILE",
              help="Measure the misses to these targets (the file the mission was planned "
                   "from), named as in it; default: to the target waypoints in the mission.")
@apply(console_options)
@reports_errors
def fly(mission_file, rho_m, airspeed_m_s, max_bank_deg, speedup, vehicle_params_file,
        l1_period_s, wind, via, format_name, max_miss_m, max_items, targets_file, quiet,
        as_json) -> None:
    """Upload MISSION_FILE to the simulated fixed wing, fly it, and print per-target miss
    distances and the flight time.

    The targets are those of --targets FILE, or else the waypoints with an acceptance radius
    (how dtsp-mission writes the targets' waypoints; the guidance design aims them off the
    targets, so give --targets to measure what matters).
    The aircraft navigates like an ArduPlane with --vehicle-params (a stock one without);
    --radius or --max-bank limit its bank, --airspeed sets its cruise speed.

    Example: dtsp-mission fly mission.plan --radius 80 --airspeed 22
    """
    from ..export import read_mission
    console.start(quiet, as_json)
    mission = read_mission(mission_file, format_name)
    airframe, _, _ = airframe_from(vehicle_params_file, airspeed_m_s, max_bank_deg, l1_period_s,
                                   rho_m)
    try:
        if targets_file is None:
            targets = targets_in(mission)
            note("misses are measured to the target waypoints of the file (the guidance design "
                 "aims them off the targets): give --targets FILE to measure to the targets")
        else:
            targets = targets_from(read_geodetic_targets(targets_file))
            check_targets_near(mission, targets, f"--targets {targets_file}")
        if wind is not None:
            check_wind(wind, airframe.airspeed_m_s)
            say(f"wind {wind}")
        run_flight_check(mission, targets, airframe, via, speedup, max_miss_m, max_items, wind)
    finally:
        console.finish()       # the summary also when --max-miss fails the check


def read_geodetic_targets(path):
    """The targets of a targets file, in degrees (UserError for local x/y metres)."""
    from ..targets import GeoTargets, read_targets
    targets = read_targets(path)
    if not isinstance(targets, GeoTargets):
        raise UserError(f"{path}: the targets are local x/y metres; --targets needs lat/lon")
    return targets
