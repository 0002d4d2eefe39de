"""``dtsp-mission sim``: a simulated fixed-wing vehicle on a UDP port, until Ctrl-C."""

from __future__ import annotations

import math
import time

import click

from ..mission import AUTOPILOTS
from ..mission.model import Home
from dataclasses import replace

from ..autopilot.navigation import G, SITL_TURN_EFFICIENCY, Airframe
from ..autopilot.parameters import ARDUPLANE_DEFAULTS, VehicleParameters, read_parameters
from ..sim.vehicle import SimulatedVehicle, VehicleSettings
from ..upload.connection import read_signing_key
from ..autopilot.navigation import CALM, check_wind
from .options import (LAT_LON, UserError, apply, reports_errors, simulation_options,
                      vehicle_options)


def airframe_from(vehicle_params_file, airspeed_m_s, max_bank_deg, l1_period_s,
                  rho_m=None) -> tuple[Airframe, VehicleParameters, str]:
    """The simulated aircraft: an ArduPlane with the parameters of ``vehicle_params_file``
    (a stock one without), overridden by the options given: ``--airspeed`` (cruise),
    ``--max-bank`` (roll limit), ``--radius`` (a roll limit that turns no tighter than it),
    ``--l1-period``."""
    parameters = read_parameters(vehicle_params_file) if vehicle_params_file else ARDUPLANE_DEFAULTS
    if airspeed_m_s is not None:
        if not airspeed_m_s > 0:
            raise UserError(f"--airspeed must be above 0 m/s, got {airspeed_m_s:g}")
        parameters = replace(parameters, AIRSPEED_CRUISE=airspeed_m_s)
    if l1_period_s is not None:
        if not l1_period_s > 0:
            raise UserError(f"--l1-period must be above 0 s, got {l1_period_s:g}")
        parameters = replace(parameters, NAVL1_PERIOD=l1_period_s)
    if max_bank_deg is not None or rho_m is not None:
        if max_bank_deg is None:
            if not rho_m > 0:
                raise UserError(f"the turn radius must be above 0 m, got {rho_m:g}")
            # the bank at which this airframe (turning at SITL_TURN_EFFICIENCY of the
            # coordinated rate) turns at rho_m
            speed = parameters.AIRSPEED_CRUISE
            max_bank_deg = math.degrees(math.atan(speed ** 2 / (G * rho_m * SITL_TURN_EFFICIENCY)))
        if not 0 < max_bank_deg < 90:
            raise UserError(f"--max-bank must be between 0 and 90 deg, got {max_bank_deg:g}")
        parameters = replace(parameters, ROLL_LIMIT_DEG=max_bank_deg)
    source = (f"ArduPlane navigation: {'parameters from ' + str(vehicle_params_file) if vehicle_params_file else 'stock parameters'}, "
              f"cruise {parameters.AIRSPEED_CRUISE:g} m/s, roll limit {parameters.ROLL_LIMIT_DEG:.0f} deg, "
              f"NAVL1_PERIOD {parameters.NAVL1_PERIOD:g} s, WP_RADIUS {parameters.WP_RADIUS:g} m")
    return Airframe.from_parameters(parameters), parameters, source


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
@click.option("--home-amsl", "home_amsl_m", type=float, default=0.0, show_default=True,
              metavar="METRES")
@click.option("--autopilot", type=click.Choice(sorted(AUTOPILOTS)), default="ardupilot",
              show_default=True, help="Autopilot the vehicle claims to be (ArduPilot keeps home "
                                      "at seq 0).")
@apply(vehicle_options)
@apply(simulation_options)
@click.option("--max-items", type=int, metavar="N",
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
                                                 l1_period_s, rho_m)
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
