"""``dtsp-mission sim``: a simulated fixed-wing vehicle on a UDP port, until Ctrl-C."""

from __future__ import annotations

import time

import click

from ..autopilot.navigation import CALM, check_wind
from ..mission import AUTOPILOTS
from ..mission.model import Home
from ..sim.vehicle import SimulatedVehicle, VehicleSettings
from ..upload.connection import read_signing_key
from .options import (LAT_LON, LIMITS, UserError, airframe_from, apply, reports_errors,
                      simulation_options, vehicle_options)


@click.command()
@click.option("--listen", default="tcp:127.0.0.1:5760", show_default=True, metavar="LINK",
              help="Where the vehicle listens: HOST:PORT or udp:HOST:PORT (ground stations "
                   "connect with udpout:HOST:PORT), tcp:HOST:PORT (as ArduPilot SITL's "
                   "tcp:127.0.0.1:5760), or pty (a pseudo-terminal: ground stations open the "
                   "printed device as a serial port).  The default is ArduPilot SITL's, so a "
                   "ground station's SITL link works unchanged; UDP 14550 is QGroundControl's own "
                   "port and cannot be shared with it.")
@click.option("--gcs", metavar="HOST:PORT", help="Also send to a ground station listening here "
              "(QGroundControl listens on 127.0.0.1:14550) before it speaks.")
@click.option("--home", "home_deg", type=LAT_LON, required=True, help="Where the vehicle stands.")
@click.option("--home-amsl", "home_amsl_m", type=LIMITS["home_amsl"], default=0.0, show_default=True,
              metavar="METRES")
@click.option("--autopilot", type=click.Choice(sorted(AUTOPILOTS)), default="ardupilot",
              show_default=True, help="Autopilot the vehicle claims to be (ArduPilot keeps home "
                                      "at seq 0).")
@apply(vehicle_options)
@apply(simulation_options)
@click.option("--max-items", type=LIMITS["max_items"], metavar="N",
              help="Mission slots (home included on ArduPilot); a longer upload gets "
                   "MAV_MISSION_NO_SPACE.  Default: a stock vehicle's (ArduPlane 655, PX4 500).")
@click.option("--signing-key", "signing_key_file", type=click.Path(dir_okay=False),
              metavar="FILE", help="Accept only messages signed with this MAVLink 2 key.")
@click.option("--autostart", is_flag=True, help="Fly as soon as a mission arrives (otherwise on "
              "MAV_CMD_MISSION_START).")
@reports_errors
def sim(listen, gcs, home_deg, home_amsl_m, autopilot, rho_m, airspeed_m_s, max_bank_deg,
        speedup, vehicle_params_file, l1_period_s, wind, max_items, signing_key_file,
        autostart) -> None:
    """Run a simulated fixed-wing vehicle that accepts missions over MAVLink and flies them.

    Example: dtsp-mission sim --home 46.805,6.941 --radius 80 --airspeed 22 --autostart
    (then: dtsp-mission upload mission.plan --connect tcp:127.0.0.1:5760)
    """
    airframe, parameters, source = airframe_from(vehicle_params_file, airspeed_m_s, max_bank_deg,
                                                 l1_period_s, rho_m, autopilot)
    settings = VehicleSettings(Home(*home_deg, home_amsl_m), AUTOPILOTS[autopilot], airframe,
                               speedup, max_items=max_items, autostart=autostart,
                               signing_key=read_signing_key(signing_key_file) if signing_key_file else None,
                               parameters=parameters,
                               wind=check_wind(wind or CALM, airframe.airspeed_m_s))
    try:
        vehicle = SimulatedVehicle(settings, gcs=_address(gcs) if gcs else None, listen=listen)
    except ValueError as error:
        raise UserError(str(error)) from None
    except OSError as error:
        raise UserError(f"cannot listen on {listen}: {error.strerror}") from None
    with vehicle:
        click.echo(f"simulated {autopilot} fixed wing at {home_deg[0]:.6f},{home_deg[1]:.6f}; "
                   f"{source}; wind {settings.wind}; connect with {vehicle.connection} (Ctrl-C stops)")
        uploads, reached = 0, 0
        try:
            while True:
                time.sleep(0.2)
                if vehicle.uploads != uploads:
                    uploads = vehicle.uploads
                    click.echo(f"mission received: {len(vehicle.mission)} items")
                if len(vehicle.log.reached) > reached:
                    reached = len(vehicle.log.reached)
                    seq, at = vehicle.log.reached[-1]
                    if vehicle.finished.is_set():
                        click.echo(f"mission complete after {at:.0f} s of simulated flight")
                    elif reached % 50 == 0:
                        click.echo(f"item {seq} reached at {at:.0f} s")
        except KeyboardInterrupt:
            click.echo("stopped")


def _address(text: str) -> tuple[str, int]:
    host, _, port = text.rpartition(":")
    if not host or not port.isdigit():
        raise UserError(f"{text!r} is not HOST:PORT")
    return host, int(port)
