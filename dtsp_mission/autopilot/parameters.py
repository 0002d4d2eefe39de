"""A vehicle's navigation parameters, from the parameter file ArduPilot and MAVProxy write.

A ``.parm`` file is one ``NAME VALUE`` per line (``#`` comments, commas accepted as the
separator, as Mission Planner writes them).  :class:`VehicleParameters` keeps the values the
flight model uses, under ArduPlane's names; :data:`ARDUPLANE_DEFAULTS` are those of a stock
ArduPlane SITL (firmware defaults with ArduPilot's standard ``plane.parm``), the vehicle every
flight in ``tests/data/arduplane-sitl`` was recorded with.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, fields, replace
from pathlib import Path

from ..errors import FileAccessError, FileFormatError


class _NamedValues:
    """Parameters by their autopilot's names: what differs between two sets."""

    def differing(self, other: "_NamedValues") -> list[tuple[str, float, float]]:
        """(name, ours, theirs) of every parameter whose values differ."""
        return [(f.name, getattr(self, f.name), getattr(other, f.name)) for f in fields(self)
                if not math.isclose(getattr(self, f.name), getattr(other, f.name),
                                    rel_tol=1e-6, abs_tol=1e-9)]

    def with_values(self, values: dict[str, float]):
        """These parameters with every one found in ``values`` (others are ignored)."""
        return replace(self, **{f.name: values[f.name] for f in fields(self) if f.name in values})


@dataclass(frozen=True)
class VehicleParameters(_NamedValues):
    """The navigation parameters of an ArduPlane, by their ArduPilot names (units as there)."""

    NAVL1_PERIOD: float = 15.0        # s
    NAVL1_DAMPING: float = 0.75
    NAVL1_XTRACK_I: float = 0.02
    WP_RADIUS: float = 50.0           # m
    WP_MAX_RADIUS: float = 0.0        # m, 0: no limit
    WP_LOITER_RAD: float = 80.0       # m
    AIRSPEED_CRUISE: float = 22.0     # m/s
    ROLL_LIMIT_DEG: float = 65.0
    TECS_CLMB_MAX: float = 5.0        # m/s
    TECS_SINK_MAX: float = 5.0        # m/s
    TECS_TIME_CONST: float = 5.0      # s
    TKOFF_LVL_PITCH: float = 15.0     # deg
    RTL_ALTITUDE: float = 100.0       # m
    RTL_RADIUS: float = 0.0           # m, 0: WP_LOITER_RAD
    SCHED_LOOP_RATE: float = 50.0     # Hz, the main loop (navigation runs in it)
    RLL2SRV_RMAX: float = 90.0        # deg/s, the most roll rate asked for (0: no limit;
                                      # ArduPlane SITL's stock plane.parm: 90)

    def l1_distance_m(self, speed_m_s: float) -> float:
        """ArduPlane's L1 distance at this ground speed."""
        return self.NAVL1_DAMPING * self.NAVL1_PERIOD * speed_m_s / math.pi


ARDUPLANE_DEFAULTS = VehicleParameters()
NAMES = tuple(f.name for f in fields(VehicleParameters))

#: The values each parameter may take (ArduPlane's documented ranges, narrowed where the
#: documented value cannot fly a mission: a roll limit below 10 deg, an airspeed below 5 m/s).
RANGES: dict[str, tuple[float, float]] = {
    "NAVL1_PERIOD": (1.0, 60.0), "NAVL1_DAMPING": (0.6, 1.0), "NAVL1_XTRACK_I": (0.0, 0.1),
    "WP_RADIUS": (1.0, 32767.0), "WP_MAX_RADIUS": (0.0, 32767.0),
    "WP_LOITER_RAD": (-32767.0, 32767.0), "AIRSPEED_CRUISE": (5.0, 100.0),
    "ROLL_LIMIT_DEG": (10.0, 90.0), "TECS_CLMB_MAX": (0.1, 20.0), "TECS_SINK_MAX": (0.1, 20.0),
    "TECS_TIME_CONST": (3.0, 10.0), "TKOFF_LVL_PITCH": (0.0, 30.0),
    "RTL_ALTITUDE": (-1.0, 32767.0), "RTL_RADIUS": (-32767.0, 32767.0),
    "SCHED_LOOP_RATE": (50.0, 400.0), "RLL2SRV_RMAX": (0.0, 180.0),
}


def check_parameters(values: dict[str, float], where: str = "parameters") -> None:
    """:class:`FileFormatError` for a navigation parameter out of its range (or not a number)
    and for a name that is not one but nearly spells one (a typo that would silently leave
    the parameter at its default)."""
    import difflib
    for name, value in values.items():
        if name in RANGES:
            low, high = RANGES[name]
            if not (math.isfinite(value) and low <= value <= high):
                raise FileFormatError(f"{where}: {name} {value:g} is out of its range "
                                      f"{low:g} .. {high:g}")
            if name == "WP_LOITER_RAD" and abs(value) < 1.0:
                raise FileFormatError(f"{where}: WP_LOITER_RAD must be at least 1 m either way, "
                                      f"got {value:g}")
        elif name not in NAMES:
            close = difflib.get_close_matches(name, NAMES, n=1, cutoff=0.9)
            if close:
                raise FileFormatError(f"{where}: {name} is not an ArduPlane parameter; did you "
                                      f"mean {close[0]}?")


def parameter_name(param_id: str | bytes) -> str:
    """A PARAM_* message's ``param_id`` as text (pymavlink gives str or bytes, NUL-padded)."""
    text = param_id.decode("ascii", "replace") if isinstance(param_id, bytes) else param_id
    return text.rstrip("\0")


def parse_parameters(text: str, where: str = "parameters") -> dict[str, float]:
    """Every ``NAME VALUE`` of a parameter file's text, by name: ArduPilot's and MAVProxy's
    ``.parm`` lines, or QGroundControl's saved ``.params`` lines (``VEHICLE COMPONENT NAME
    VALUE TYPE``, tab-separated).  A byte-order mark is skipped; :class:`FileFormatError` for
    a name given twice with two values (which one the vehicle has is anyone's guess) and for
    a ``.params`` file that holds more than one vehicle's parameters."""
    values: dict[str, float] = {}
    lines: dict[str, int] = {}
    vehicles: set[str] = set()
    for number, line in enumerate(text.lstrip("\ufeff").splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.replace(",", " ").split()
        if len(parts) >= 4 and parts[0].isdigit() and parts[1].isdigit():
            vehicles.add(parts[0])
            parts = parts[2:4]                  # QGroundControl: vehicle, component, name, value
        if len(parts) < 2:
            raise FileFormatError(f"{where}, line {number}: expected NAME VALUE, got {line!r}")
        name = parts[0].upper()
        try:
            value = float(parts[1])
        except ValueError:
            raise FileFormatError(f"{where}, line {number}: {parts[1]!r} is not a number") from None
        if name in values and not (value == values[name] or (math.isnan(value)
                                                              and math.isnan(values[name]))):
            raise FileFormatError(f"{where}: {name} is given twice, {values[name]:g} (line "
                                  f"{lines[name]}) and {value:g} (line {number}); keep the "
                                  "vehicle's one value")
        values[name], lines[name] = value, number
    if len(vehicles) > 1:
        raise FileFormatError(f"{where}: holds the parameters of {len(vehicles)} vehicles (ids "
                              f"{', '.join(sorted(vehicles, key=int))}); save one vehicle's")
    return values


#: ArduPlane's names before 4.5 for parameters it has renamed: (new name, factor to its unit).
ARDUPLANE_OLD_NAMES = {"TRIM_ARSPD_CM": ("AIRSPEED_CRUISE", 0.01),
                       "LIM_ROLL_CD": ("ROLL_LIMIT_DEG", 0.01)}


def with_current_names(values: dict[str, float], where: str = "parameters") -> dict[str, float]:
    """``values`` with ArduPlane's pre-4.5 names (``TRIM_ARSPD_CM``, ``LIM_ROLL_CD``) read as
    today's (``AIRSPEED_CRUISE``, ``ROLL_LIMIT_DEG``, in their units); :class:`FileFormatError`
    when a file gives both names different values."""
    values = dict(values)
    for old, (new, factor) in ARDUPLANE_OLD_NAMES.items():
        if old not in values:
            continue
        converted = values.pop(old) * factor
        if new in values and not math.isclose(values[new], converted, rel_tol=1e-6):
            raise FileFormatError(f"{where}: {old} {converted / factor:g} (the name before "
                                  f"ArduPlane 4.5) and {new} {values[new]:g} disagree")
        values[new] = converted
    return values


def check_autopilot_names(values: dict[str, float], autopilot: str, where: str) -> None:
    """:class:`FileFormatError` when a parameter file for ``autopilot`` ("ardupilot" or
    "px4") holds the other autopilot's navigation parameters and none of its own: they would
    be ignored, and the mission designed for a stock aircraft."""
    foreign, theirs, ours = ((PX4_NAMES, "PX4", "ardupilot") if autopilot != "px4"
                             else (NAMES + tuple(ARDUPLANE_OLD_NAMES), "ArduPlane", "px4"))
    own = PX4_NAMES if autopilot == "px4" else NAMES + tuple(ARDUPLANE_OLD_NAMES)
    found = [name for name in values if name in foreign]
    if found and not any(name in own for name in values):
        other = "px4" if ours == "ardupilot" else "ardupilot"
        raise FileFormatError(f"{where}: holds {theirs} parameters ({', '.join(found[:3])}), "
                              f"but the mission is for {'PX4' if ours == 'px4' else 'ArduPilot'}: "
                              f"give that vehicle's parameters, or plan with `autopilot` {other}")


def parameters_from(values: dict[str, float], base: VehicleParameters = ARDUPLANE_DEFAULTS) -> VehicleParameters:
    """``base`` with every navigation parameter found in ``values`` (others are ignored)."""
    return base.with_values(values)


def read_parameters(path: str | os.PathLike) -> VehicleParameters:
    """The navigation parameters in a ``.parm`` file; the stock defaults for any it lacks."""
    try:
        text = Path(path).read_text(encoding="utf-8", errors="replace")
    except OSError as error:
        raise FileAccessError(f"cannot read the vehicle parameters {path}: {error.strerror}") from None
    values = with_current_names(parse_parameters(text, str(path)), str(path))
    check_autopilot_names(values, "ardupilot", str(path))
    check_parameters(values, str(path))
    return parameters_from(values)


@dataclass(frozen=True)
class PX4Parameters(_NamedValues):
    """The fixed-wing navigation parameters of a PX4 (v1.16), by their PX4 names (units as
    there); the defaults are PX4's stock values, as a stock PX4 SITL reports them
    (``tests/data/px4-sitl/*/params.parm``)."""

    NPFG_PERIOD: float = 10.0         # s
    NPFG_DAMPING: float = 0.7
    NPFG_SW_DST_MLT: float = 0.32     # the switch distance over the track error bound
    NAV_ACC_RAD: float = 10.0         # m
    NAV_LOITER_RAD: float = 80.0      # m
    FW_AIRSPD_TRIM: float = 15.0      # m/s
    FW_AIRSPD_MAX: float = 20.0       # m/s
    FW_R_LIM: float = 50.0            # deg
    FW_T_CLMB_MAX: float = 5.0        # m/s
    FW_T_SINK_MAX: float = 5.0        # m/s


PX4_DEFAULTS = PX4Parameters()
PX4_NAMES = tuple(f.name for f in fields(PX4Parameters))
PX4_RANGES: dict[str, tuple[float, float]] = {
    "NPFG_PERIOD": (1.0, 100.0), "NPFG_DAMPING": (0.1, 1.0), "NPFG_SW_DST_MLT": (0.0, 1.0),
    "NAV_ACC_RAD": (0.05, 200.0), "NAV_LOITER_RAD": (25.0, 1000.0),
    "FW_AIRSPD_TRIM": (0.5, 40.0), "FW_AIRSPD_MAX": (0.5, 40.0), "FW_R_LIM": (35.0, 65.0), "FW_T_CLMB_MAX": (0.5, 15.0),
    "FW_T_SINK_MAX": (0.5, 15.0),
}


def read_px4_parameters(path: str | os.PathLike) -> PX4Parameters:
    """The fixed-wing navigation parameters in a parameter file (``NAME VALUE`` lines, as
    the SITL's and QGroundControl's exports give them once reduced to name and value); PX4's
    stock values for any it lacks.  :class:`FileFormatError` for a value out of PX4's range."""
    try:
        text = Path(path).read_text(encoding="utf-8", errors="replace")
    except OSError as error:
        raise FileAccessError(f"cannot read the vehicle parameters {path}: {error.strerror}") from None
    values = parse_parameters(text, str(path))
    check_autopilot_names(values, "px4", str(path))
    check_px4_parameters(values, str(path))
    return PX4_DEFAULTS.with_values(values)


def check_px4_parameters(values: dict[str, float], where: str = "parameters") -> None:
    """:class:`FileFormatError` for a PX4 navigation parameter out of its range."""
    for name, (low, high) in PX4_RANGES.items():
        if name in values and not (math.isfinite(values[name]) and low <= values[name] <= high):
            raise FileFormatError(f"{where}: {name} {values[name]:g} is out of its range "
                                  f"{low:g} .. {high:g}")


def checked_parameters(autopilot, values: dict[str, float], where: str = "parameters"
                       ) -> VehicleParameters | PX4Parameters:
    """``autopilot``'s stock navigation parameters with ``values`` laid over them, each
    checked against its range (:class:`FileFormatError` naming ``where`` otherwise)."""
    if autopilot == "px4" or autopilot == 12:
        check_px4_parameters(values, where)
        return PX4_DEFAULTS.with_values(values)
    check_parameters(values, where)
    return ARDUPLANE_DEFAULTS.with_values(values)


def parameters_of(autopilot, given: VehicleParameters | PX4Parameters | None = None
                  ) -> VehicleParameters | PX4Parameters:
    """The navigation parameters of a vehicle running ``autopilot`` ("px4" or MAV_AUTOPILOT
    12 for PX4, else ArduPilot): ``given`` if it is that autopilot's set, else its stock values."""
    if autopilot == "px4" or autopilot == 12:            # MAV_AUTOPILOT_PX4
        return given if isinstance(given, PX4Parameters) else PX4_DEFAULTS
    return given if isinstance(given, VehicleParameters) else ARDUPLANE_DEFAULTS
