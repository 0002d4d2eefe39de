"""``dtsp-mission upload``: send a mission file to a vehicle and prove it arrived."""

from __future__ import annotations

import click

from ..upload import to_wire, upload_mission
from ..upload.connection import read_signing_key
from . import console
from .console import console_options, note, record, say
from .options import (UserError, apply, link_options, mission_options, mission_settings,
                      progress_reporter, reports_errors, vehicle_options)


def run_upload(mission, connection: str, via: str, verify: bool, signing_key_file: str | None,
               heartbeat_timeout_s: float | None = None, designed_for=None,
               transfer_timeout_s: float | None = None) -> None:
    """Upload with a progress bar and print what happened (shared with ``plan --upload``)."""
    key = read_signing_key(signing_key_file) if signing_key_file else None
    progress, close = progress_reporter("uploading")
    slots = len(to_wire(mission))
    if not mission.autopilot_stated:      # the vehicle's autopilot decides the home slot
        what = f"{len(mission.items)} mission items (and a home slot if the vehicle is ArduPilot)"
    elif slots > len(mission.items):
        what = f"{len(mission.items)} mission items and the home slot ({slots} mission slots)"
    else:
        what = f"{len(mission.items)} mission items ({slots} mission slots)"
    say(f"uploading {what} to {connection} via {via}")
    try:
        report = upload_mission(mission, connection, via=via, verify=verify, signing_key=key,
                                progress=progress, heartbeat_timeout_s=heartbeat_timeout_s,
                                designed_for=designed_for, timeout_s=transfer_timeout_s)
    finally:
        close()
    for warning in report.warnings:
        note(f"warning: {warning}")
    fresh = f", {report.fresh_starts} fresh starts" if report.fresh_starts else ""
    line = (f"the vehicle accepted {report.items} mission slots in {report.seconds:.2f} s "
            f"({report.resent} messages resent{fresh})")
    held = ("exactly the planned mission" if not mission.not_carried else
            "exactly the planned mission items (not what was not sent: "
            + ", ".join(mission.not_carried) + ")")
    say(line + (f"; downloaded back: it holds {held}" if report.verified
                else "; not verified (--no-verify)"))
    if report.note:
        note(report.note)
    record(upload={"via": report.via, "mission_slots": report.items, "seconds": report.seconds,
                   "transfer_s": report.transfer_s, "resent": report.resent,
                   "fresh_starts": report.fresh_starts, "verified": report.verified,
                   "round_trip_s": report.round_trip_s})


@click.command()
@click.argument("mission_file", type=click.Path(dir_okay=False))
@click.option("--connect", "connection", required=True, metavar="CONNECTION",
              help="The vehicle: udpout:HOST:PORT, udpin:HOST:PORT, tcp:HOST:PORT or a serial "
                   "device like /dev/ttyACM0,57600.")
@apply(link_options)
@click.option("--format", "format_name", help="Format of MISSION_FILE, whatever its extension.")
@click.option("--heartbeat-timeout", "heartbeat_timeout_s", type=float, default=5.0,
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
    from .plan_command import _designed_for
    run_upload(mission, connection, via, verify, signing_key_file, heartbeat_timeout_s,
               _designed_for(vehicle_params_file), transfer_timeout_s)
    console.finish()


def _tour_mission(path, settings):
    """The mission of a tour file placed on the earth by its frame origin."""
    import json

    from ..files import read_text
    from ..frame import LocalFrame
    from ..mission import build_mission
    from ..targets.model import local_targets
    from ..tour import read_tour
    from ..tour.json_form import origin_from_dict
    tour = read_tour(path)
    origin = origin_from_dict(json.loads(read_text(path)))
    if origin is None:
        raise UserError(f"{path}: the tour has no frame origin, so it cannot be placed on the "
                        "earth; plan from lat/lon targets (or with --origin) and write the .json again")
    frame = LocalFrame(*origin)
    targets = local_targets(tour.targets_m).to_geodetic(frame)
    mission = build_mission(tour, frame, targets, settings)
    say(f"mission from the tour: {len(mission.items)} items")
    return mission.for_vehicle()
