"""``dtsp-mission sim``: a simulated fixed-wing vehicle on a UDP port, until Ctrl-C."""

from __future__ import annotations

import time

import click

from ..mission import AUTOPILOTS
from ..mission.model import Home
from ..sim.flight import Airframe
from ..sim.vehicle import SimulatedVehicle, VehicleSettings
from ..upload.connection import read_signing_key
from .options import (LAT_LON, UserError, apply, reports_errors, simulation_options,
                      turn_radius_from, vehicle_options)


def airframe_from(rho_m, airspeed_m_s, max_bank_deg, l1_period_s) -> tuple[Airframe, str]:
    """The simulated airframe from the vehicle options (airspeed default 20 m/s)."""
    rho, source = turn_radius_from(rho_m, airspeed_m_s, max_bank_deg)
    if not rho > 0:
        raise UserError(f"the turn radius must be above 0 m, got {rho:g}")
    if not l1_period_s > 0:
        raise UserError(f"--l1-period must be above 0 s, got {l1_period_s:g}")
    return Airframe(airspeed_m_s or 20.0, rho, l1_period_s), source


@click.command()
@click.option("--listen", default="127.0.0.1:14550", show_default=True, metavar="HOST:PORT",
              help="UDP address the vehicle listens on (ground stations use udpout:HOST:PORT).")
@click.option("--gcs", metavar="HOST:PORT", help="Also send to a ground station listening here "
              "(QGroundControl listens on 127.0.0.1:14550) before it speaks.")
@click.option("--home", "home_deg", type=LAT_LON, required=True, help="Where the vehicle stands.")
@click.option("--home-amsl", "home_amsl_m", type=float, default=0.0, show_default=True,
              metavar="METRES")
@click.option("--autopilot", type=click.Choice(sorted(AUTOPILOTS)), default="ardupilot",
              show_default=True, help="Autopilot the vehicle claims to be (ArduPilot keeps home "
                                      "at seq 0).")
@apply(vehicle_options)
@apply(simulation_options)
@click.option("--max-items", type=int, metavar="N",
              help="Mission slots; a longer upload gets MAV_MISSION_NO_SPACE.")
@click.option("--signing-key", "signing_key_file", type=click.Path(dir_okay=False),
              metavar="FILE", help="Accept only messages signed with this MAVLink 2 key.")
@click.option("--autostart", is_flag=True, help="Fly as soon as a mission arrives (otherwise on "
              "MAV_CMD_MISSION_START).")
@reports_errors
def sim(listen, gcs, home_deg, home_amsl_m, autopilot, rho_m, airspeed_m_s, max_bank_deg,
        speedup, l1_period_s, max_items, signing_key_file, autostart) -> None:
    """Run a simulated fixed-wing vehicle that accepts missions over MAVLink and flies them.

    Example: dtsp-mission sim --home 46.805,6.941 --radius 80 --airspeed 22 --autostart
    """
    airframe, source = airframe_from(rho_m, airspeed_m_s, max_bank_deg, l1_period_s)
    host, port = _address(listen)
    settings = VehicleSettings(Home(*home_deg, home_amsl_m), AUTOPILOTS[autopilot], airframe,
                               speedup, max_items=max_items, autostart=autostart,
                               signing_key=read_signing_key(signing_key_file) if signing_key_file else None)
    try:
        vehicle = SimulatedVehicle(settings, port, host, _address(gcs) if gcs else None)
    except OSError as error:
        raise UserError(f"cannot listen on {listen}: {error.strerror}") from None
    with vehicle:
        click.echo(f"simulated {autopilot} fixed wing at {home_deg[0]:.6f},{home_deg[1]:.6f}; "
                   f"{source}; listening on udp {vehicle.host}:{vehicle.port} (Ctrl-C stops)")
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
