"""``dtsp-mission fly``: fly a mission file in the simulator and report how close it passed
each target -- the check before a real flight."""

from __future__ import annotations

import click

from ..autopilot.navigation import check_wind
from ..sim.fly import check_targets_near, targets_from, targets_in
from . import console
from .console import console_options, note, say
from .options import (LIMITS, UserError, airframe_from, apply, reports_errors, simulation_options,
                      vehicle_options)
from .runs import run_flight_check


@click.command()
@click.argument("mission_file", type=click.Path(dir_okay=False))
@apply(vehicle_options)
@apply(simulation_options)
@click.option("--via", default="pymavlink", show_default=True, help="Uploader to use.")
@click.option("--format", "format_name", help="Format of MISSION_FILE, whatever its extension.")
@click.option("--max-miss", "max_miss_m", type=LIMITS["distance"], metavar="METRES",
              help="Exit with status 1 if any target is missed by more than this.")
@click.option("--max-items", type=LIMITS["max_items"], metavar="N", help="Mission slots of the simulated "
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

    The targets are those of --targets FILE, or else those a .plan written by dtsp-mission
    carries, or else the waypoints with an acceptance radius (how dtsp-mission writes the
    targets' waypoints; the guidance design aims them off the targets, so give --targets to
    measure what matters).
    The aircraft is the one the plan was designed for (a .plan written by dtsp-mission
    records its navigation parameters), else a stock one of the plan's autopilot;
    --vehicle-params flies another, --radius or --max-bank limit its bank, --airspeed sets its
    cruise speed (each said when it changes the designed aircraft).

    Example: dtsp-mission fly mission.plan
    """
    from ..export import read_mission
    console.start(quiet, as_json)
    mission = read_mission(mission_file, format_name)
    designed = None if vehicle_params_file else mission.designed_for
    airframe, flown, _ = airframe_from(vehicle_params_file, airspeed_m_s, max_bank_deg, l1_period_s,
                                       rho_m, mission.autopilot, base=designed)
    if designed is not None:
        changed = [f"{name} {theirs:g} (designed for {ours:g})"
                   for name, ours, theirs in designed.differing(flown)]
        if changed:
            note("flying another aircraft than the plan was designed for: " + ", ".join(changed))
    elif mission.designed_for is not None and mission.designed_for.differing(flown):
        note("flying the aircraft of --vehicle-params, not the one the plan was designed for: "
             + ", ".join(f"{n} {t:g} (designed for {o:g})"
                         for n, o, t in mission.designed_for.differing(flown)))
    try:
        if targets_file is None:
            targets = targets_in(mission)
            if mission.targets:
                check_targets_near(mission, targets, f"{mission_file}: the targets it carries")
            else:
                note("misses are measured to the target waypoints of the file (the guidance "
                     "design aims them off the targets): give --targets FILE to measure to the "
                     "targets")
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
