"""``dtsp-mission upload``: send a mission file to a vehicle and prove it arrived."""

from __future__ import annotations

import click

from . import console
from .console import console_options, say
from .options import (LIMITS, UserError, apply, designed_for, link_options, mission_options,
                      mission_settings, reports_errors, vehicle_options)
from .runs import run_upload


@click.command()
@click.argument("mission_file", type=click.Path(dir_okay=False))
@click.option("--connect", "connection", required=True, metavar="CONNECTION",
              help="The vehicle: udpout:HOST:PORT, udpin:HOST:PORT, tcp:HOST:PORT or a serial "
                   "device like /dev/ttyACM0,57600.")
@apply(link_options)
@click.option("--format", "format_name", help="Format of MISSION_FILE, whatever its extension.")
@click.option("--heartbeat-timeout", "heartbeat_timeout_s", type=LIMITS["seconds"], default=5.0,
              show_default=True, metavar="S", help="How long to wait for the vehicle.")
@apply(mission_options)
@vehicle_options[1]        # --airspeed, for the tour's mission
@click.option("--vehicle-params", "vehicle_params_file", type=click.Path(dir_okay=False),
              metavar="FILE.parm", help="The parameters the mission was designed for; each "
              "navigation parameter the vehicle has otherwise is warned about (default: a "
              "stock ArduPlane's).")
@apply(console_options)
@reports_errors
def upload(mission_file, connection, via, verify, signing_key_file, transfer_timeout_s,
           format_name, heartbeat_timeout_s, vehicle_params_file, quiet, as_json,
           **mission_option_values) -> None:
    """Upload MISSION_FILE (.plan, .waypoints, or a tour .json) to a vehicle over MAVLink.

    A tour .json (from `plan -o tour.json`, with its frame origin) becomes a mission here,
    with the same options as `plan` (--alt, --autopilot, --return, ...); .plan and
    .waypoints files are sent as they are.

    Before it, the vehicle's autopilot must be the plan's (ArduPilot or PX4), and its
    navigation parameters and home are compared with the plan's (warnings).  After the upload
    the mission is downloaded back and compared item by item, as the autopilot stores items
    (ArduPilot uploads are not atomic); on any failure the message says what the vehicle holds.

    Links: udpout:HOST:PORT (send to a vehicle listening there), udpin:0.0.0.0:PORT (listen
    for a vehicle sending here), tcp:HOST:PORT (ArduPilot SITL: tcp:127.0.0.1:5760), a
    serial device with its baud rate (/dev/ttyACM0,57600 or COM3,57600), as MAVProxy's
    --master writes them.  Lost, repeated and reordered messages are repeated and ignored as
    the link needs; a vehicle that gives an upload up gets a fresh one, within --timeout.

    Example: dtsp-mission upload mission.plan --connect udpout:127.0.0.1:14550
    """
    from ..export import exporter_for, read_mission
    console.start(quiet, as_json)
    if exporter_for(mission_file, format_name, reading=True).name == "tour":
        mission = _tour_mission(mission_file, mission_settings(**mission_option_values))
    else:
        mission = read_mission(mission_file, format_name)
        floor = mission_option_values["min_altitude_m"]
        low = mission.below_floor(floor)
        if low:
            raise UserError(f"{mission_file}: {len(low)} navigation item(s) below the altitude "
                            f"floor of {floor:g} m above home (--min-alt): {'; '.join(low[:3])}; "
                            "nothing was sent (if the site is clear that low, lower --min-alt)")
    run_upload(mission, connection, via, verify, signing_key_file, heartbeat_timeout_s,
               designed_for(vehicle_params_file, mission.autopilot), transfer_timeout_s)
    console.finish()


def _tour_mission(path, settings):
    """The mission of a tour file placed on the earth by its frame origin."""
    from ..files import read_json
    from ..frame import LocalFrame
    from ..mission import build_mission
    from ..targets.model import local_targets
    from ..tour import read_tour
    from ..tour.json_form import origin_from_dict
    tour = read_tour(path)
    origin = origin_from_dict(read_json(path))
    if origin is None:
        raise UserError(f"{path}: the tour has no frame origin, so it cannot be placed on the "
                        "earth; plan from lat/lon targets (or with --origin) and write the .json again")
    frame = LocalFrame(*origin)
    targets = local_targets(tour.targets_m).to_geodetic(frame)
    mission = build_mission(tour, frame, targets, settings)
    say(f"mission from the tour: {len(mission.items)} items")
    return mission.for_vehicle()
