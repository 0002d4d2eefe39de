"""Options shared by several commands, defined once so a flag means the same everywhere, and
the one place where library errors become CLI errors."""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, replace
import sys
import time
from typing import Callable

import click

from ..errors import DtspError
from .console import in_cli_terms


class UserError(click.ClickException):
    """A message for the user and exit code 2, with nothing half-written; the parameters the
    library names (in backticks) are printed as the options that set them."""

    exit_code = 2

    def __init__(self, message: str) -> None:
        super().__init__(in_cli_terms(message))


def reports_errors(function: Callable) -> Callable:
    """Turn :class:`DtspError` raised inside a command into a :class:`UserError`."""
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except DtspError as error:
            raise UserError(str(error)) from None
    return wrapper


class FiniteFloatRange(click.FloatRange):
    """A :class:`click.FloatRange` that also refuses NaN and infinities."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number


class Quantity(click.ParamType):
    """A finite number of ``unit`` within ``[low, high]`` (``low_open``: above ``low``;
    ``zero``: 0 also allowed, with its meaning), refused with the range and the unit.  Every
    option that takes a quantity uses one of :data:`LIMITS`, so a flag has the same limits in
    every command."""

    def __init__(self, unit: str, low: float, high: float, low_open: bool = False,
                 zero: str | None = None, integer: bool = False) -> None:
        self.unit, self.low, self.high, self.low_open = unit, low, high, low_open
        self.zero, self.integer = zero, integer
        self.name = "integer" if integer else "number"

    def describe(self) -> str:
        shown = (lambda v: f"{v:,}") if self.integer else (lambda v: f"{v:g}")
        unit = f" {self.unit}" if self.unit else ""
        text = (f"above {shown(self.low)} and at most {shown(self.high)}{unit}" if self.low_open
                else f"from {shown(self.low)} to {shown(self.high)}{unit}")
        return f"0 ({self.zero}) or {text}" if self.zero else text

    def convert(self, value, param, ctx):
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            number = value
        else:
            text = str(value).strip()
            try:
                number = int(text) if self.integer else float(text)
            except ValueError:
                self.fail(f"{value!r} is not {'a whole number' if self.integer else 'a number'}"
                          f" ({self.describe()})", param, ctx)
        if self.zero and number == 0:
            return number
        inside = (math.isfinite(number)
                  and (number > self.low if self.low_open else number >= self.low)
                  and number <= self.high)
        if not inside:
            self.fail(f"{value} is out of range: {self.describe()}", param, ctx)
        return number


#: The limits of every quantity an option takes, shared by all commands (`plan`, `fly`,
#: `sim`, `upload`, `dubins`, ...).  Where an autopilot parameter sets the same value, its
#: range is checked as well once the aircraft is put together.
LIMITS = {
    "radius": Quantity("m", 0.1, 20_000.0),          # pipeline.MAX_PLAN_RADIUS_M
    "airspeed": Quantity("m/s", 5.0, 100.0),          # ArduPlane's AIRSPEED_CRUISE range
    "max_bank": Quantity("deg", 10.0, 89.0),          # ROLL_LIMIT_DEG (90: no finite radius)
    "period": Quantity("s", 1.0, 100.0),              # NAVL1_PERIOD 1-60, NPFG_PERIOD 1-100
    "speedup": Quantity("x real time", 0.1, 10_000.0, zero="as fast as possible"),
    "distance": Quantity("m", 0.0, 10_000.0, low_open=True),
    "altitude": Quantity("m", 0.0, 10_000.0, low_open=True),   # targets.model.MAX_ALTITUDE_M
    "home_amsl": Quantity("m above mean sea level", -1_000.0, 9_000.0),
    "bearing": Quantity("deg", -360.0, 360.0),
    "wind_spread": Quantity("m/s", 0.0, 50.0),
    "max_items": Quantity("mission items", 2, 65_535, integer=True),
    "seconds": Quantity("s", 0.0, 86_400.0, low_open=True),
    "seed": Quantity("", 0, 2**32 - 1, integer=True),
    "count": Quantity("targets", 1, 1_000_000, integer=True),
    "pitch": Quantity("deg", -90.0, 90.0),
    "extent": Quantity("m", 0.0, 1_000_000.0, low_open=True),   # a benchmark site's size
}

radius_option = click.option(
    "--radius", "rho_m", type=LIMITS["radius"], required=True, metavar="METRES",
    help="Minimum turn radius rho of the aircraft, in metres.")
seed_option = click.option("--seed", type=LIMITS["seed"], default=0, show_default=True,
                           help="Seed of every random choice; the same seed gives the same result.")


class LatLonType(click.ParamType):
    """``LAT,LON`` in decimal degrees."""

    name = "LAT,LON"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        try:
            latitude, longitude = (float(part) for part in str(value).split(","))
        except ValueError:
            self.fail(f"{value!r} is not LAT,LON in decimal degrees (for example 47.3977,8.5456)",
                      param, ctx)
        if not (-90 <= latitude <= 90 and -180 <= longitude <= 180):
            self.fail(f"{value!r}: latitude must be within [-90, 90] and longitude within "
                      "[-180, 180] degrees", param, ctx)
        return latitude, longitude


LAT_LON = LatLonType()


class WindType(click.ParamType):
    """``SPEED@FROM_DEG``: m/s, and degrees true the wind comes from (as in a METAR)."""

    name = "SPEED@FROM_DEG"

    def convert(self, value, param, ctx):
        from ..autopilot.navigation import Wind, check_wind
        from ..errors import InputError
        if isinstance(value, Wind):
            return value
        try:
            speed, direction = (float(part) for part in str(value).split("@"))
        except ValueError:
            self.fail(f"{value!r} is not SPEED@FROM_DEG (m/s @ degrees true the wind comes "
                      "from, for example 6@270 for 6 m/s from the west)", param, ctx)
        try:
            return check_wind(Wind(speed, direction % 360.0 if math.isfinite(direction) else direction))
        except InputError as error:
            self.fail(in_cli_terms(str(error)), param, ctx)


WIND = WindType()

#: The vehicle, defined once for every command that plans or flies.
vehicle_options = [
    click.option("--radius", "rho_m", type=LIMITS["radius"], metavar="METRES",
                 help="Minimum turn radius rho of the aircraft, in metres (or give --airspeed "
                      "and --max-bank)."),
    click.option("--airspeed", "airspeed_m_s", type=LIMITS["airspeed"], metavar="M/S",
                 help="Cruise airspeed in m/s: sets the mission speed and the flight time; with "
                      "--max-bank it gives rho, the radius the aircraft turns at that bank."),
    click.option("--max-bank", "max_bank_deg", type=LIMITS["max_bank"], metavar="DEG",
                 help="Largest bank angle in degrees, used with --airspeed to compute rho."),
]


#: How a tour becomes a mission, defined once for every command that builds one.
mission_options = [
    click.option("--alt", "altitude_m", type=LIMITS["altitude"], default=100.0, show_default=True,
                 metavar="METRES", help="Cruise altitude above home (targets with an 'alt' use theirs)."),
    click.option("--min-alt", "min_altitude_m", type=LIMITS["altitude"], default=30.0, show_default=True,
                 metavar="METRES", help="Altitude floor above home: no cruise or target altitude "
                 "below it (lower it only where the site is clear that low)."),
    click.option("--home", "home_deg", type=LAT_LON,
                 help="Launch and home position (default: the centre of the targets)."),
    click.option("--home-amsl", "home_altitude_amsl_m", type=LIMITS["home_amsl"], default=0.0, show_default=True,
                 metavar="METRES", help="Home altitude above mean sea level (for the .plan)."),
    click.option("--launch-bearing", "launch_bearing_deg", type=LIMITS["bearing"], metavar="DEG",
                 help="Take-off direction, compass degrees (default: towards the first target)."),
    click.option("--landing-bearing", "landing_bearing_deg", type=LIMITS["bearing"], metavar="DEG",
                 help="Landing direction, compass degrees (default: the launch bearing)."),
    click.option("--autopilot", type=click.Choice(["ardupilot", "px4"]), default="ardupilot",
                 show_default=True, help="Autopilot flavour of the mission."),
    click.option("--return", "return_mode", type=click.Choice(["rtl", "land", "none"]),
                 help="After the last target: RTL, a landing at home, or nothing "
                       "(default: rtl for ArduPilot, land for PX4)."),
    click.option("--design", type=click.Choice(["guidance", "geometry"]), default="guidance",
                 show_default=True,
                 help="Waypoints for the autopilot's guidance: one per target, aimed so that "
                      "ArduPlane's navigation (the flight model, with --vehicle-params) passes "
                      "each within --max-miss, plus shaping waypoints where needed; or a "
                      "polyline within --tolerance of the exact path (PX4 always)."),
    click.option("--max-miss", "max_miss_m", type=LIMITS["distance"], default=5.0, show_default=True,
                 metavar="METRES", help="How close the predicted flight must pass each target "
                 "(the guidance design; with --simulate also the flight check's limit)."),
    click.option("--wind-spread", "wind_spread_m_s", type=LIMITS["wind_spread"], metavar="M/S",
                 help="How far the real wind may be from --wind: the guidance design also "
                      "holds every target within --max-miss in winds this much stronger and "
                      "weaker and turned 20 deg each way (default a quarter of the wind, at "
                      "least 1 m/s; 0: the forecast only)."),
    click.option("--tolerance", "tolerance_m", type=LIMITS["distance"], metavar="METRES",
                 help="--design geometry: largest distance between the exact path and the "
                      "waypoint polyline (default 2 % of rho; a quarter of it when the item "
                      "budget allows)."),
    click.option("--max-items", type=LIMITS["max_items"], metavar="N",
                 help="Mission slots of the vehicle (default a stock vehicle's: 655 for "
                      "ArduPlane, home included; 500 for PX4; at most 65535)."),
]


def mission_settings(**values):
    """The :class:`MissionSettings` of option values named as its fields (``vehicle``: the
    :class:`~dtsp_mission.autopilot.parameters.VehicleParameters` the mission is for; a value
    of None takes the field's default)."""
    from ..mission import MissionSettings
    return MissionSettings(**{name: value for name, value in values.items() if value is not None})


def apply(options: list) -> Callable:
    """Decorate a command with a list of click options, in order."""
    def decorate(function: Callable) -> Callable:
        for option in reversed(options):
            function = option(function)
        return function
    return decorate


def turn_radius_from(rho_m: float | None, airspeed_m_s: float | None,
                     max_bank_deg: float | None, parameters=None) -> tuple[float, str]:
    """The turn radius and where it came from, from the vehicle options: ``--radius``, or the
    radius the aircraft (``parameters``: a stock ArduPlane's unless given) turns at
    ``--max-bank`` and ``--airspeed``.  UserError for options that do not go together;
    InputError for a radius the aircraft cannot turn at ``--airspeed``."""
    from ..autopilot.navigation import Airframe, bank_for_radius_deg, check_turn_radius
    from ..autopilot.parameters import ARDUPLANE_DEFAULTS
    parameters = parameters or ARDUPLANE_DEFAULTS
    if max_bank_deg is not None:
        if rho_m is not None:
            raise UserError("give either --radius or --airspeed with --max-bank, not both")
        if airspeed_m_s is None:
            raise UserError("--max-bank needs --airspeed to compute the turn radius")
        if not (math.isfinite(max_bank_deg) and 0 < max_bank_deg < 90):
            raise UserError(f"--max-bank must be between 0 and 90 degrees, got {max_bank_deg:g}")
        if not (math.isfinite(airspeed_m_s) and airspeed_m_s > 0):
            raise UserError(f"--airspeed must be a number above 0 m/s, got {airspeed_m_s:g}")
        rho = Airframe.from_parameters(parameters, airspeed_m_s).turn_radius_m(max_bank_deg)
        return rho, (f"rho {rho:.1f} m: the aircraft's turn at {airspeed_m_s:g} m/s and "
                     f"{max_bank_deg:g} deg bank")
    if rho_m is None:
        raise UserError("give the turn radius: --radius METRES, or --airspeed and --max-bank")
    if airspeed_m_s is not None and rho_m > 0 and airspeed_m_s > 0:
        check_turn_radius(rho_m, parameters, airspeed_m_s)
        bank = bank_for_radius_deg(rho_m, airspeed_m_s)
        return rho_m, (f"rho {rho_m:g} m (a {bank:.0f} deg bank at {airspeed_m_s:g} m/s)")
    return rho_m, f"rho {rho_m:g} m"


#: How to reach a vehicle, defined once for every command that uploads.
link_options = [
    click.option("--via", default="pymavlink", show_default=True,
                 help="Uploader: pymavlink (MAVLink 2, signing) or mavsdk (MAVSDK mission_raw), "
                      "or an installed plugin."),
    click.option("--verify/--no-verify", default=True, show_default=True,
                 help="Download the mission after the upload and compare it item by item."),
    click.option("--signing-key", "signing_key_file", type=click.Path(dir_okay=False),
                 metavar="FILE", help="Sign with this MAVLink 2 key: 32 bytes, 64 hex digits, "
                                      "or a passphrase (its SHA-256)."),
    click.option("--timeout", "transfer_timeout_s", type=LIMITS["seconds"], metavar="S",
                 help="Give up a transfer (the upload, the verification download) after this "
                      "long.  Default: 30 s + 0.1 s per item."),
]

#: The simulated aircraft's autopilot, defined once for `sim`, `fly` and `plan --simulate`.
simulation_options = [
    click.option("--speedup", type=LIMITS["speedup"], default=50.0, show_default=True,
                 help="Simulated seconds per wall-clock second (0: as fast as possible)."),
    click.option("--vehicle-params", "vehicle_params_file", type=click.Path(dir_okay=False),
                 metavar="FILE.parm", help="The vehicle's parameters (NAME VALUE lines, as "
                 "ArduPilot and MAVProxy write them): the flight model navigates with its "
                 "NAVL1_*, WP_RADIUS, ROLL_LIMIT_DEG, AIRSPEED_CRUISE, TECS_*; for a PX4 "
                 "mission its NPFG_PERIOD, NPFG_DAMPING, NPFG_SW_DST_MLT, NAV_ACC_RAD, FW_R_LIM, "
                 "FW_AIRSPD_TRIM, FW_T_*; default a stock vehicle's."),
    click.option("--l1-period", "l1_period_s", type=LIMITS["period"], metavar="S",
                 help="Override NAVL1_PERIOD, the L1 navigation period of the simulated "
                      "autopilot (NPFG_PERIOD for PX4)."),
    click.option("--wind", type=WIND, metavar="SPEED@FROM_DEG",
                 help="Steady wind: m/s @ degrees true it comes from (6@270: 6 m/s from the "
                      "west), full strength above 60 m.  The simulated aircraft flies in it; "
                      "`plan` also designs the mission for it.  Default calm."),
]


def progress_reporter(label: str):
    """A ``progress(done, total[, resent])`` callback drawing a bar on stderr (with the rate
    and, for transfers, the messages sent again), and its closer; nothing is drawn when stderr
    is not a terminal (a log file gets no bar fragments)."""
    state: dict = {}
    stream = sys.stderr

    def progress(done: int, total: int, resent: int | None = None) -> None:
        if not (hasattr(stream, "isatty") and stream.isatty()):
            return
        if "bar" not in state:
            state["bar"] = click.progressbar(length=total, label=label, file=stream)
            state["bar"].__enter__()
            state["done"], state["since"] = 0, time.monotonic()
        if resent is not None:
            rate = done / max(1e-9, time.monotonic() - state["since"])
            state["bar"].label = f"{label} ({rate:.0f} items/s, {resent} resent)"
        state["bar"].update(done - state["done"])
        state["done"] = done

    def close() -> None:
        """End the bar (once: closing again does nothing)."""
        bar = state.pop("bar", None)
        if bar is not None:
            bar.__exit__(None, None, None)

    return progress, close


def airframe_from(vehicle_params_file, airspeed_m_s, max_bank_deg, l1_period_s,
                  rho_m=None, autopilot="ardupilot", base=None):
    """The simulated aircraft: an ArduPlane (or, for ``autopilot`` PX4, a PX4 flying PX4
    SITL's fixed wing) with the parameters of ``vehicle_params_file`` (a stock one without),
    overridden by the options given: ``--airspeed`` (cruise, PX4's trim), ``--max-bank`` (roll
    limit), ``--radius`` (a roll limit that turns no tighter than it), ``--l1-period`` (PX4's
    NPFG_PERIOD); and the one-line description of it the commands print.  ``base``: the
    parameters to start from without a file (a plan's designed aircraft; stock if None)."""
    from ..autopilot.commands import Autopilot
    from ..autopilot.navigation import Airframe, parameters_with
    from ..autopilot.parameters import ARDUPLANE_DEFAULTS
    origin = (f"parameters from {vehicle_params_file}" if vehicle_params_file
              else "the parameters the plan was designed for" if base is not None
              else "stock parameters")
    if autopilot in ("px4", Autopilot.PX4):
        from ..autopilot.navigation import px4_parameters_with
        from ..autopilot.parameters import PX4_DEFAULTS
        px4 = designed_for(vehicle_params_file, autopilot) or (
            base if isinstance(base, type(PX4_DEFAULTS)) else PX4_DEFAULTS)
        px4 = checked_aircraft(px4_parameters_with(px4, airspeed_m_s, max_bank_deg, l1_period_s,
                                                   rho_m))
        airframe = Airframe.from_px4_parameters(px4)
        source = (f"PX4 navigation (NPFG): {origin}, trim airspeed {px4.FW_AIRSPD_TRIM:g} m/s "
                  f"({airframe.airspeed_m_s:.1f} m/s true, as PX4 SITL's fixed wing flies it), "
                  f"roll limit {px4.FW_R_LIM:.0f} deg, NPFG_PERIOD {px4.NPFG_PERIOD:g} s, "
                  f"NAV_ACC_RAD {px4.NAV_ACC_RAD:g} m")
        return airframe, px4, source
    parameters = designed_for(vehicle_params_file) or (
        base if isinstance(base, type(ARDUPLANE_DEFAULTS)) else ARDUPLANE_DEFAULTS)
    parameters = checked_aircraft(parameters_with(parameters, airspeed_m_s, max_bank_deg,
                                                  l1_period_s, rho_m))
    source = (f"ArduPlane navigation: {origin}, cruise {parameters.AIRSPEED_CRUISE:g} m/s, roll "
              f"limit {parameters.ROLL_LIMIT_DEG:.0f} deg, NAVL1_PERIOD "
              f"{parameters.NAVL1_PERIOD:g} s, WP_RADIUS {parameters.WP_RADIUS:g} m")
    return Airframe.from_parameters(parameters), parameters, source


def designed_for(vehicle_params_file, autopilot="ardupilot", l1_period_s=None):
    """The parameters a mission for ``autopilot`` is designed for: the file's (by ArduPlane's
    or PX4's names) with ``--l1-period`` laid over them (NAVL1_PERIOD, PX4's NPFG_PERIOD), or
    None (a stock vehicle's) when neither is given."""
    if not vehicle_params_file and l1_period_s is None:
        return None
    from ..autopilot.commands import Autopilot
    from ..autopilot.parameters import (ARDUPLANE_DEFAULTS, PX4_DEFAULTS, read_parameters,
                                        read_px4_parameters)
    px4 = autopilot in ("px4", Autopilot.PX4)
    if px4:
        parameters = read_px4_parameters(vehicle_params_file) if vehicle_params_file else PX4_DEFAULTS
    else:
        parameters = read_parameters(vehicle_params_file) if vehicle_params_file else ARDUPLANE_DEFAULTS
    if l1_period_s is not None:
        parameters = checked_aircraft(
            replace(parameters, **{"NPFG_PERIOD" if px4 else "NAVL1_PERIOD": l1_period_s}))
    return parameters


def checked_aircraft(parameters):
    """``parameters`` (ArduPlane's or PX4's) once options are laid over them, each value
    checked against the autopilot's range (InputError naming the parameter and its option)."""
    from ..autopilot.parameters import PX4Parameters, check_parameters, check_px4_parameters
    values = asdict(parameters)
    where = "the aircraft (--vehicle-params and the options laid over them)"
    if isinstance(parameters, PX4Parameters):
        check_px4_parameters(values, where)
    else:
        check_parameters(values, where)
    return parameters
