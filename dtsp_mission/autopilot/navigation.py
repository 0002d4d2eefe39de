"""Flying a mission the way ArduPlane navigates it: a fixed-wing point mass in coordinated
turns, steered by ArduPlane's L1 guidance (``AP_L1_Control``: the leg between waypoints, the
loiter circle), with its waypoint completion (acceptance radius scaled by the turn, the finish
line), LOITER_TURNS with fractional turns and the tangent exit, take-off and a TECS-like climb.

Pure computation, no network: :class:`MissionFlight` takes the mission's items in the local
frame (metres east/north of home, altitude above home) and advances by :meth:`step`.  The bank
angle is limited to the roll limit (``ROLL_LIMIT_DEG``), the aircraft turns at that bank with
the radius :meth:`Airframe.turn_radius_m` says, and the bank follows its command as a damped
second-order response, whose frequency and damping were fitted to ArduPlane SITL's roll
(``tests/data/arduplane-sitl``).  Its parameters come from :class:`Airframe`, usually made from
the vehicle's parameters (:meth:`Airframe.from_parameters`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from . import flight_kernel as K
from ..errors import InputError
from .commands import Command, Frame
from .parameters import ARDUPLANE_DEFAULTS, PX4_DEFAULTS, PX4Parameters, VehicleParameters

G = K.G
TAKEOFF_PITCH_DEG = 15.0
#: The roll response of ArduPlane SITL's stock plane: its roll controller asks for a roll rate
#: in proportion to the bank error (ROLL_NATURAL_RAD_S / (2 ROLL_DAMPING) per second, about
#: its 1 / RLL2SRV_TCONST), limited to ROLL_RATE_OVER_RMAX times RLL2SRV_RMAX (90 deg/s
#: stock), and the aircraft follows that rate with a lag of 1 / (2 ROLL_DAMPING
#: ROLL_NATURAL_RAD_S): a damped second-order response to small steps, slower than that
#: in the large ones (reversals).  The three fitted together to the recorded ArduPlane
#: flights (docs/arduplane-agreement.md) and to every target of the real flights of the
#: project's missions (docs/real-flights.md, 3,616 targets of 25 flights): model and real
#: differ there by more than 3 m at 33 targets, more than 4 m at 15, against 44 and 23 with
#: the second-order lag alone (4.4 rad/s, damping 0.6, no limit); the recorded design
#: flights of the bundled site (../shared/arduplane-sitl-designs) are passed within 3.0 and
#: 5.0 m of the real closest approach instead of 5.7 m.
ROLL_NATURAL_RAD_S = 4.4
ROLL_DAMPING = 0.5
ROLL_RATE_OVER_RMAX = 1.5
#: ArduPlane SITL's stock plane turns at this fraction of the coordinated-turn rate for its
#: bank at its airspeed (median of the recorded course rate over g tan(roll) / airspeed in the
#: calm recordings, banks of 5-70 deg in bins: 0.68-0.72; with the airspeed rising in a bank,
#: BANK_AIRSPEED_GAIN_M_S, 0.70 agrees best with the recorded tracks and the real flights of
#: the project's missions, docs/arduplane-agreement.md and docs/real-flights.md).
SITL_TURN_EFFICIENCY = 0.70
#: The time step the model's agreement with recorded ArduPlane flights was measured at
#: (docs/arduplane-agreement.md): the flight that predicts, verifies and simulates a mission.
MODEL_STEP_S = 0.02
#: No predicted flight goes on longer than this (s): the design's and the offline prediction's cap.
FLIGHT_LIMIT_S = 36000.0
#: The take-off run of ArduPlane SITL's stock plane (fitted to the recorded climbs: 43 m run
#: in the first 4 s, lift-off at 85 % of the cruise airspeed after about 3.5 s).
TAKEOFF_ACCEL_M_S2 = 5.3
#: ... and its climb-out: the take-off ends well above the cruise airspeed (1.265 of it), holds
#: it about 1.3 s and bleeds it off at about 1.67 m/s^2, at cruise 5 s after the take-off item
#: completed.  Fitted at cruise 22 m/s to the 31 flights of tests/data/arduplane-sitl*: their
#: peak 27.9-28.1 m/s (the model 27.8), RMS 0.3 m/s and at most 0.5-0.9 m/s per flight over
#: the 8 s after the take-off item completed.
TAKEOFF_END_AIRSPEED_RATIO = 1.265
TAKEOFF_END_HOLD_S = 1.3
TAKEOFF_END_DECAY_M_S2 = 1.67
#: ... and its airspeed in a bank: above the airspeed asked by this much per unit of the load
#: factor's excess (1 / cos(bank) - 1): +1 m/s at 60 deg.  Fitted to the 19 calm recordings of
#: tests/data/arduplane-sitl* (least squares 0.9 with the bank 0.5 s earlier; 1.0 agrees best
#: with the tracks): their airspeed rises from 21.9-22.0 m/s below 15 deg of bank to 22.3-22.9
#: at 45-55 deg and 22.8-23.5 above 55 deg (RMS about the cruise airspeed 0.31 m/s, about this
#: rule 0.25).  The turn rate is the airframe's fraction of the coordinated rate at that
#: airspeed, so a hard turn is flown wider than at the cruise airspeed (9 % at 60 deg).
BANK_AIRSPEED_GAIN_M_S = 1.0
#: PX4 SITL's SIH fixed wing (airframe 10041), fitted to the flights of tests/data/px4-sitl:
#: its true airspeed over the airspeed asked (13.9 m/s over the ground in calm air at
#: FW_AIRSPD_TRIM 15), its turn rate over the coordinated rate for its bank (regression of
#: the course rate on the roll: 1.09-1.19) and its roll response.
SIH_AIRSPEED_RATIO = 13.9 / 15.0
#: ... and the fastest it flies level at its stock throttle limit, whatever airspeed the mission
#: asks: asked 18 m/s (DO_CHANGE_SPEED) it flew 13.8 m/s over the ground in calm air 8 m below
#: the altitude asked (benchmarks/real_flights.py, px4/uniform100; ../px4-sitl/t12: 8.6 m
#: below), asked 15 m/s 13.9-14.0 m/s and 2-3 m below (the calibration flights).
SIH_MAX_AIRSPEED_M_S = 13.9
SIH_TURN_EFFICIENCY = 1.1
SIH_ROLL_NATURAL_RAD_S = 4.0
SIH_ROLL_DAMPING = 0.7
#: ... its take-off: the run at 5 m/s^2, lift-off and climb-out at 10 m/s (FW_AIRSPD_MIN),
#: climbing at FW_T_CLMB_MAX; after it the airspeed grows to cruise with an 18 s time constant.
SIH_TAKEOFF_ACCEL_M_S2 = 5.0
SIH_TAKEOFF_AIRSPEED_M_S = 10.0
SIH_AIRSPEED_TC_S = 18.0
#: LOITER_TURNS with the tangent exit leaves when the course is this close to the next waypoint.
LOITER_EXIT_HEADING_RAD = math.radians(10.0)

NAV_COMMANDS = {Command.NAV_WAYPOINT, Command.NAV_TAKEOFF, Command.NAV_LAND,
                Command.NAV_RETURN_TO_LAUNCH, Command.NAV_LOITER_TURNS, Command.NAV_LOITER_TIME}
#: ArduPilot's MAV_CMD_NAV_LAST: commands above it do not navigate (a DO_SET_ROI's location is
#: where the camera looks, not where the aircraft goes).
NAV_LAST = 95


@dataclass(frozen=True)
class Airframe:
    """The simulated aircraft and its autopilot tuning.  The defaults are the aircraft the
    product ships: ArduPlane SITL's stock plane with a stock ArduPlane's parameters
    (``Airframe() == Airframe.from_parameters()``); :meth:`turning_at` gives the same aircraft
    with a roll limit that turns no tighter than a radius."""

    airspeed_m_s: float = ARDUPLANE_DEFAULTS.AIRSPEED_CRUISE
    roll_limit_deg: float = ARDUPLANE_DEFAULTS.ROLL_LIMIT_DEG
    l1_period_s: float = ARDUPLANE_DEFAULTS.NAVL1_PERIOD
    wp_radius_m: float = ARDUPLANE_DEFAULTS.WP_RADIUS
    roll_natural_rad_s: float = ROLL_NATURAL_RAD_S
    roll_damping: float = ROLL_DAMPING
    l1_damping: float = ARDUPLANE_DEFAULTS.NAVL1_DAMPING
    loiter_radius_m: float = ARDUPLANE_DEFAULTS.WP_LOITER_RAD
    max_climb_m_s: float = ARDUPLANE_DEFAULTS.TECS_CLMB_MAX
    max_sink_m_s: float = ARDUPLANE_DEFAULTS.TECS_SINK_MAX
    altitude_time_constant_s: float = ARDUPLANE_DEFAULTS.TECS_TIME_CONST
    #: Take-off as ArduPlane SITL's stock plane flies it at full throttle (fitted to the
    #: recorded climbs): ground roll accelerating at this rate, lift-off at 85 % of the cruise
    #: airspeed, climb at this rate up to 116 % of it.  0: airborne at once, climbing at the
    #: take-off pitch.
    takeoff_accel_m_s2: float = TAKEOFF_ACCEL_M_S2
    takeoff_climb_m_s: float = 9.7
    #: Turn rate over the coordinated-turn rate g tan(bank) / v at the same bank: 1 for an
    #: ideal airframe; ArduPlane SITL's stock plane turns at SITL_TURN_EFFICIENCY of it.
    turn_efficiency: float = SITL_TURN_EFFICIENCY
    #: How often the navigation runs (lateral demand, waypoint completion); 0: every step.
    navigation_hz: float = ARDUPLANE_DEFAULTS.SCHED_LOOP_RATE
    #: ArduPlane's NAVL1_XTRACK_I: the cross-track integrator's gain (0: none).
    xtrack_i_gain: float = ARDUPLANE_DEFAULTS.NAVL1_XTRACK_I
    #: Whose navigation flies it: ArduPlane's (``"ardupilot"``) or PX4's (``"px4"``: NPFG
    #: path following, its waypoint switching; ``l1_period_s``/``l1_damping`` are then
    #: NPFG_PERIOD/NPFG_DAMPING, ``wp_radius_m`` NAV_ACC_RAD).  See :meth:`from_px4_parameters`.
    autopilot: str = "ardupilot"
    #: PX4's NPFG_SW_DST_MLT: it switches to the next waypoint this fraction of the track
    #: error bound before a waypoint (when that exceeds the acceptance radius).
    switch_distance_multiplier: float = PX4_DEFAULTS.NPFG_SW_DST_MLT
    #: The aircraft's true airspeed over an airspeed asked for (DO_CHANGE_SPEED).
    airspeed_ratio: float = 1.0
    #: The time constant its airspeed follows a change with (s; 0: at once).
    airspeed_time_constant_s: float = 0.0
    #: The airspeed it lifts off and climbs out at (0: ArduPlane SITL's: lift-off at 85 % of
    #: the cruise airspeed, accelerating on to 116 % in the climb).
    takeoff_airspeed_m_s: float = 0.0
    #: The most airspeed it flies, whatever is asked (0: no limit; PX4: FW_AIRSPD_MAX).
    max_airspeed_m_s: float = 0.0
    #: The airspeed a take-off ends at over the cruise airspeed, held ``takeoff_end_hold_s``
    #: and then bled off at ``takeoff_end_decay_m_s2`` (ArduPlane SITL's stock plane climbing
    #: out at full throttle; 0: at the cruise airspeed at once).  Only where the airspeed
    #: follows a change at once (``airspeed_time_constant_s`` 0).
    takeoff_end_airspeed_ratio: float = TAKEOFF_END_AIRSPEED_RATIO
    takeoff_end_hold_s: float = TAKEOFF_END_HOLD_S
    takeoff_end_decay_m_s2: float = TAKEOFF_END_DECAY_M_S2
    #: How much faster it flies in a bank, per unit of (1 / cos(bank) - 1) (ArduPlane SITL's
    #: stock plane; 0: the same airspeed at any bank).  Only where the airspeed follows a
    #: change at once (``airspeed_time_constant_s`` 0).
    bank_airspeed_gain_m_s: float = BANK_AIRSPEED_GAIN_M_S
    #: How fast the airspeed demand moves to a new airspeed asked for (DO_CHANGE_SPEED),
    #: m/s^2, faster and slower (0: at once): ArduPlane's TECS moves it at most this fast
    #: (faster: half TECS_CLMB_MAX's energy rate over the airspeed, 1.5 m/s^2 at 16.5 m/s;
    #: slower: fitted to ArduPlane SITL's stock plane at 120 m, 22 -> 16.5 m/s in 12-13 s).
    #: Only where the airspeed follows a change at once (``airspeed_time_constant_s`` 0).
    airspeed_up_m_s2: float = 1.5
    airspeed_down_m_s2: float = 0.48
    #: How the airspeed follows that demand when it rises: a second-order response of this
    #: natural frequency (rad/s) and damping (0: it is the demand).  ArduPlane SITL's stock
    #: plane gains 2 m/s in the first second under the throttle, holds near 20 m/s as TECS
    #: climbs, then overshoots to 23 m/s trading the height back.  Fitted to the speed steps
    #: of ``tests/data/arduplane-sitl-speed-steps`` (along the track within 20 s of a change:
    #: 5.3 m ahead or behind at most, against 10.5 m with the demand ramped at 0.8 / 0.4 m/s^2
    #: and followed at once) and checked against the designed missions' real flights (model
    #: against real per target, 12 wind flights: max 6.7 -> 4.5 m).
    airspeed_up_natural_rad_s: float = 1.6
    airspeed_up_damping: float = 0.5
    #: The most roll rate the model's roll response asks for, deg/s (0: no limit): see
    #: :data:`ROLL_RATE_OVER_RMAX`.
    roll_rate_max_deg_s: float = ROLL_RATE_OVER_RMAX * ARDUPLANE_DEFAULTS.RLL2SRV_RMAX

    @classmethod
    def from_parameters(cls, parameters: VehicleParameters = ARDUPLANE_DEFAULTS,
                        airspeed_m_s: float | None = None) -> "Airframe":
        """The airframe an ArduPlane with these parameters flies as (its cruise airspeed
        unless ``airspeed_m_s`` is given)."""
        return cls(airspeed_m_s or parameters.AIRSPEED_CRUISE, parameters.ROLL_LIMIT_DEG,
                   parameters.NAVL1_PERIOD, parameters.WP_RADIUS,
                   l1_damping=parameters.NAVL1_DAMPING, loiter_radius_m=parameters.WP_LOITER_RAD,
                   max_climb_m_s=parameters.TECS_CLMB_MAX, max_sink_m_s=parameters.TECS_SINK_MAX,
                   altitude_time_constant_s=parameters.TECS_TIME_CONST,
                   navigation_hz=parameters.SCHED_LOOP_RATE,
                   xtrack_i_gain=parameters.NAVL1_XTRACK_I,
                   roll_rate_max_deg_s=ROLL_RATE_OVER_RMAX * parameters.RLL2SRV_RMAX)

    @classmethod
    def from_px4_parameters(cls, parameters: PX4Parameters = PX4_DEFAULTS,
                            airspeed_m_s: float | None = None) -> "Airframe":
        """The airframe a PX4 with these parameters flies as: PX4 SITL's SIH fixed wing (its
        true airspeed, roll response and turn rate fitted to the flights of
        ``tests/data/px4-sitl``) under PX4's NPFG guidance; ``airspeed_m_s`` is the airspeed
        asked for (its trim airspeed, ``FW_AIRSPD_TRIM``, if None; PX4 flies no faster than
        ``FW_AIRSPD_MAX``, the SIH plane no faster than :data:`SIH_MAX_AIRSPEED_M_S`)."""
        asked = airspeed_m_s or parameters.FW_AIRSPD_TRIM
        top = min(parameters.FW_AIRSPD_MAX * SIH_AIRSPEED_RATIO, SIH_MAX_AIRSPEED_M_S)
        return cls(min(asked * SIH_AIRSPEED_RATIO, top), parameters.FW_R_LIM,
                   parameters.NPFG_PERIOD,
                   parameters.NAV_ACC_RAD, roll_natural_rad_s=SIH_ROLL_NATURAL_RAD_S,
                   roll_damping=SIH_ROLL_DAMPING, roll_rate_max_deg_s=0.0,
                   l1_damping=parameters.NPFG_DAMPING,
                   loiter_radius_m=parameters.NAV_LOITER_RAD,
                   max_climb_m_s=parameters.FW_T_CLMB_MAX, max_sink_m_s=parameters.FW_T_SINK_MAX,
                   takeoff_climb_m_s=parameters.FW_T_CLMB_MAX,
                   takeoff_accel_m_s2=SIH_TAKEOFF_ACCEL_M_S2,
                   turn_efficiency=SIH_TURN_EFFICIENCY, navigation_hz=0.0, xtrack_i_gain=0.0,
                   autopilot="px4", switch_distance_multiplier=parameters.NPFG_SW_DST_MLT,
                   airspeed_ratio=SIH_AIRSPEED_RATIO, airspeed_time_constant_s=SIH_AIRSPEED_TC_S,
                   takeoff_airspeed_m_s=SIH_TAKEOFF_AIRSPEED_M_S,
                   max_airspeed_m_s=top,
                   takeoff_end_airspeed_ratio=0.0, bank_airspeed_gain_m_s=0.0)

    @classmethod
    def turning_at(cls, rho_m: float, airspeed_m_s: float | None = None,
                   parameters: VehicleParameters = ARDUPLANE_DEFAULTS) -> "Airframe":
        """The aircraft of ``parameters`` (at ``airspeed_m_s``, else its cruise airspeed) with
        the roll limit at which it turns no tighter than ``rho_m`` in still air."""
        return cls.from_parameters(parameters_with(parameters, airspeed_m_s, rho_m=rho_m))

    def max_bank_rad(self, airspeed_m_s: float | None = None) -> float:
        return math.radians(self.roll_limit_deg)

    def l1_distance_m(self, speed_m_s: float) -> float:
        return max(self.l1_damping * self.l1_period_s * speed_m_s / math.pi, 1.0)

    def turn_radius_m(self, bank_deg: float, airspeed_m_s: float | None = None) -> float:
        """The radius (through the air) of this aircraft's steady turn at ``bank_deg`` and
        ``airspeed_m_s`` (its cruise airspeed if None): the radius the flight model flies."""
        v = self.airspeed_m_s if airspeed_m_s is None else airspeed_m_s
        if self.airspeed_time_constant_s <= 0.0:      # faster in the bank, as the model flies
            v += self.bank_airspeed_gain_m_s * (1.0 / math.cos(math.radians(bank_deg)) - 1.0)
        return v / K.turn_rate_rad_s(v, math.radians(bank_deg), self.turn_efficiency)

    @property
    def tightest_turn_m(self) -> float:
        """The smallest radius the model flies in still air at the cruise airspeed: its roll
        limit, at its turn efficiency."""
        return self.turn_radius_m(self.roll_limit_deg)


@dataclass(frozen=True)
class LocalItem:
    """A mission item in the local frame; ``x_m``/``y_m`` are NaN for items without position."""

    seq: int
    command: int
    x_m: float
    y_m: float
    alt_m: float
    params: tuple[float, float, float, float]


@dataclass
class AircraftState:
    x_m: float
    y_m: float
    alt_m: float
    heading_rad: float         # counter-clockwise from east
    airspeed_m_s: float
    bank_rad: float = 0.0
    bank_rate_rad_s: float = 0.0
    time_s: float = 0.0


#: Commands without a position, whatever frame a vehicle stores them in.
_NO_POSITION = {Command.NAV_RETURN_TO_LAUNCH}


def _overridden(parameters, airspeed_m_s, max_bank_deg, period_s, rho_m, names, radius_bank):
    """``parameters`` with the fields ``names`` (airspeed, period, roll limit) replaced where
    given; ``rho_m`` without ``max_bank_deg`` sets the roll limit to ``radius_bank(rho_m,
    parameters)``.  :class:`InputError` for a value out of range."""
    airspeed_name, period_name, bank_name = names
    if airspeed_m_s is not None:
        if not airspeed_m_s > 0:
            raise InputError(f"the airspeed must be above 0 m/s, got {airspeed_m_s:g}")
        parameters = replace(parameters, **{airspeed_name: airspeed_m_s})
    if period_s is not None:
        if not period_s > 0:
            raise InputError(f"the navigation period must be above 0 s, got {period_s:g}")
        parameters = replace(parameters, **{period_name: period_s})
    if max_bank_deg is not None or rho_m is not None:
        if max_bank_deg is None:
            if not rho_m > 0:
                raise InputError(f"the turn radius must be above 0 m, got {rho_m:g}")
            max_bank_deg = radius_bank(rho_m, parameters)
        if not 0 < max_bank_deg < 90:
            raise InputError(f"the maximum bank must be between 0 and 90 deg, got {max_bank_deg:g}")
        parameters = replace(parameters, **{bank_name: max_bank_deg})
    return parameters


def parameters_with(parameters: VehicleParameters, airspeed_m_s: float | None = None,
                    max_bank_deg: float | None = None, l1_period_s: float | None = None,
                    rho_m: float | None = None) -> VehicleParameters:
    """``parameters`` with the cruise airspeed, the roll limit and NAVL1_PERIOD replaced where
    given; ``rho_m`` without ``max_bank_deg`` sets the roll limit at which this model (turning
    at :data:`SITL_TURN_EFFICIENCY` of the coordinated rate) turns no tighter than ``rho_m``.
    :class:`InputError` for a value out of range."""
    return _overridden(parameters, airspeed_m_s, max_bank_deg, l1_period_s, rho_m,
                       ("AIRSPEED_CRUISE", "NAVL1_PERIOD", "ROLL_LIMIT_DEG"),
                       lambda rho, p: bank_for_radius_deg(rho, p.AIRSPEED_CRUISE))


def px4_parameters_with(parameters: PX4Parameters, airspeed_m_s: float | None = None,
                        max_bank_deg: float | None = None, period_s: float | None = None,
                        rho_m: float | None = None) -> PX4Parameters:
    """``parameters`` with the trim airspeed, the roll limit (``FW_R_LIM``) and NPFG_PERIOD
    replaced where given; ``rho_m`` without ``max_bank_deg`` sets the roll limit at which the
    PX4 model aircraft turns no tighter than ``rho_m``.  :class:`InputError` for a value out of
    range."""
    return _overridden(parameters, airspeed_m_s, max_bank_deg, period_s, rho_m,
                       ("FW_AIRSPD_TRIM", "NPFG_PERIOD", "FW_R_LIM"),
                       lambda rho, p: bank_for_radius_deg(
                           rho, min(p.FW_AIRSPD_TRIM, p.FW_AIRSPD_MAX) * SIH_AIRSPEED_RATIO,
                           SIH_TURN_EFFICIENCY, 0.0))


def check_turn_radius(rho_m: float, parameters: VehicleParameters = ARDUPLANE_DEFAULTS,
                      airspeed_m_s: float | None = None) -> None:
    """:class:`InputError` if the aircraft of ``parameters`` (at ``airspeed_m_s``, else its
    cruise airspeed) cannot turn at ``rho_m`` within its roll limit, naming the smallest
    radius it can."""
    airframe = Airframe.from_parameters(parameters, airspeed_m_s)
    tightest = airframe.tightest_turn_m
    if rho_m < tightest * (1 - 1e-9):
        raise InputError(
            f"the aircraft cannot turn at {rho_m:g} m: at {airframe.airspeed_m_s:g} m/s with a roll "
            f"limit of {parameters.ROLL_LIMIT_DEG:g} deg (ROLL_LIMIT_DEG) it turns no "
            f"tighter than {math.ceil(tightest):.0f} m; plan with a radius of at least that")


def bank_for_radius_deg(rho_m: float, airspeed_m_s: float,
                        turn_efficiency: float = SITL_TURN_EFFICIENCY,
                        bank_airspeed_gain_m_s: float = BANK_AIRSPEED_GAIN_M_S) -> float:
    """The bank at which the aircraft (turning at ``turn_efficiency`` of the coordinated
    rate, ``bank_airspeed_gain_m_s`` faster per unit of the load factor's excess) turns at
    ``rho_m`` asked to fly ``airspeed_m_s``: the inverse of :meth:`Airframe.turn_radius_m`
    (to the last bit; 89 deg where no bank turns that tight)."""
    if bank_airspeed_gain_m_s == 0.0:
        return math.degrees(math.atan(airspeed_m_s ** 2 / (G * rho_m * turn_efficiency)))

    def radius(bank: float) -> float:
        v = airspeed_m_s + bank_airspeed_gain_m_s * (1.0 / math.cos(bank) - 1.0)
        return v * v / (G * math.tan(bank) * turn_efficiency)

    low, high = 1e-9, math.radians(89.0)          # the radius falls over this range
    if radius(high) >= rho_m:
        return 89.0
    for _ in range(200):                             # to the last bit
        middle = 0.5 * (low + high)
        if middle in (low, high):
            break
        low, high = (middle, high) if radius(middle) > rho_m else (low, middle)
    return math.degrees(0.5 * (low + high))


def launch_heading_rad(items: list[LocalItem], first: int) -> float:
    """The heading an aircraft stands at home with before a mission: towards the first item
    from ``first`` on with a position more than 1 m from home (0, east, if none)."""
    ahead = next((i for i in items[first:] if not math.isnan(i.x_m)
                  and math.hypot(i.x_m, i.y_m) > 1.0), None)
    return math.atan2(ahead.y_m, ahead.x_m) if ahead is not None else 0.0


def local_items(wire: list, frame, home_amsl_m: float) -> list[LocalItem]:
    """Mission items (MISSION_ITEM_INT form, :class:`~dtsp_mission.autopilot.storage.WireItem`)
    in the local ``frame`` (a :class:`~dtsp_mission.frame.LocalFrame` at home), altitudes above
    home; items without a position get NaN coordinates."""
    items = []
    for item in wire:
        if item.frame == Frame.MISSION or item.command in _NO_POSITION or item.command > NAV_LAST:
            x = y = math.nan
        else:
            x, y = frame.to_local(np.array([item.x / 1e7]), np.array([item.y / 1e7]))[0]
        altitude = item.z - home_amsl_m if item.frame in (Frame.GLOBAL, Frame.GLOBAL_INT) else item.z
        items.append(LocalItem(item.seq, item.command, float(x), float(y), altitude,
                               (item.param1, item.param2, item.param3, item.param4)))
    return items


@dataclass(frozen=True)
class Wind:
    """A steady wind: ``speed_m_s`` from ``from_deg`` (degrees true the wind comes from, as in
    a METAR and ArduPilot's ``SIM_WIND_DIR``), at full strength above ``full_altitude_m``
    and weaker towards the ground as the square root of the height (ArduPilot SITL's default
    profile, ``SIM_WIND_T_ALT`` 60 m)."""

    speed_m_s: float = 0.0
    from_deg: float = 0.0
    full_altitude_m: float = 60.0

    @property
    def velocity_m_s(self) -> tuple[float, float]:
        """(east, north) velocity of the air mass, m/s."""
        towards = math.radians(self.from_deg + 180.0)
        return self.speed_m_s * math.sin(towards), self.speed_m_s * math.cos(towards)

    def __str__(self) -> str:
        return "calm" if self.speed_m_s == 0 else f"{self.speed_m_s:g} m/s from {self.from_deg:g} deg"


CALM = Wind()
#: The strongest wind the model takes: beyond it no small fixed wing flies a mission.
MAX_WIND_M_S = 30.0


def check_wind(wind: Wind, airspeed_m_s: float | None = None) -> Wind:
    """``wind``, or :class:`~dtsp_mission.errors.InputError` saying why it cannot be flown
    (not a number, negative, stronger than :data:`MAX_WIND_M_S` or than 70 % of the
    airspeed: the aircraft would make little or no headway against it)."""
    from ..errors import InputError
    if not (math.isfinite(wind.speed_m_s) and math.isfinite(wind.from_deg)):
        raise InputError(f"the wind must be finite numbers, got {wind.speed_m_s!r} m/s from "
                         f"{wind.from_deg!r} deg")
    if not 0.0 <= wind.speed_m_s <= MAX_WIND_M_S:
        raise InputError(f"the wind speed must be from 0 to {MAX_WIND_M_S:g} m/s, got "
                         f"{wind.speed_m_s:g}")
    if airspeed_m_s is not None and wind.speed_m_s > 0.7 * airspeed_m_s:
        raise InputError(f"a wind of {wind.speed_m_s:g} m/s is more than 70 % of the airspeed "
                         f"({airspeed_m_s:g} m/s): the aircraft would make too little headway "
                         "against it to fly a mission")
    return wind


def airframe_vector(airframe: Airframe, wind: Wind = CALM) -> np.ndarray:
    """The airframe, its tuning and the wind as the compiled model's vector."""
    v = np.zeros(K.AIRFRAME_SIZE)
    v[K.A_AIRSPEED] = airframe.airspeed_m_s
    v[K.A_L1_PERIOD] = airframe.l1_period_s
    v[K.A_WP_RADIUS] = airframe.wp_radius_m
    v[K.A_ROLL_W] = airframe.roll_natural_rad_s
    v[K.A_ROLL_Z] = airframe.roll_damping
    v[K.A_L1_DAMPING] = airframe.l1_damping
    v[K.A_ROLL_LIMIT] = airframe.roll_limit_deg
    v[K.A_LOITER_RADIUS] = airframe.loiter_radius_m
    v[K.A_CLIMB] = airframe.max_climb_m_s
    v[K.A_SINK] = airframe.max_sink_m_s
    v[K.A_ALT_TC] = airframe.altitude_time_constant_s
    v[K.A_TKO_ACCEL] = airframe.takeoff_accel_m_s2
    v[K.A_TKO_CLIMB] = airframe.takeoff_climb_m_s
    v[K.A_TURN_EFFICIENCY] = airframe.turn_efficiency
    v[K.A_NAV_HZ] = airframe.navigation_hz
    v[K.A_WIND_X], v[K.A_WIND_Y] = wind.velocity_m_s
    v[K.A_WIND_FULL_ALT] = wind.full_altitude_m
    v[K.A_TKO_PITCH] = TAKEOFF_PITCH_DEG
    v[K.A_XTRACK_I_GAIN] = airframe.xtrack_i_gain
    v[K.A_PX4] = 1.0 if airframe.autopilot == "px4" else 0.0
    v[K.A_SWITCH_MULT] = airframe.switch_distance_multiplier
    v[K.A_SPEED_RATIO] = airframe.airspeed_ratio
    v[K.A_SPEED_TC] = airframe.airspeed_time_constant_s
    v[K.A_TKO_SPEED] = airframe.takeoff_airspeed_m_s
    v[K.A_MAX_SPEED] = airframe.max_airspeed_m_s
    v[K.A_TKO_END_RATIO] = airframe.takeoff_end_airspeed_ratio
    v[K.A_TKO_END_HOLD] = airframe.takeoff_end_hold_s
    v[K.A_TKO_END_DECAY] = airframe.takeoff_end_decay_m_s2
    v[K.A_BANK_SPEED] = airframe.bank_airspeed_gain_m_s
    v[K.A_SPEED_UP] = airframe.airspeed_up_m_s2
    v[K.A_SPEED_DOWN] = airframe.airspeed_down_m_s2
    v[K.A_ROLL_RATE_MAX] = math.radians(airframe.roll_rate_max_deg_s)
    v[K.A_SPEED_UP_W] = airframe.airspeed_up_natural_rad_s
    v[K.A_SPEED_UP_Z] = airframe.airspeed_up_damping
    return v


@dataclass(frozen=True)
class MissionArrays:
    """A mission's items as the compiled model's columns."""

    seq: np.ndarray          # int64
    command: np.ndarray      # int64
    position: np.ndarray     # (n, 3): x, y, altitude above home; NaN x/y without a position
    params: np.ndarray       # (n, 4)
    following: np.ndarray    # int64: next navigation item with a position after each, or -1

    @classmethod
    def of(cls, items: list[LocalItem]) -> "MissionArrays":
        n = len(items)
        command = np.array([int(i.command) for i in items], dtype=np.int64)
        position = np.array([(i.x_m, i.y_m, i.alt_m) for i in items], dtype=float).reshape(n, 3)
        params = np.array([i.params for i in items], dtype=float).reshape(n, 4)
        following = np.full(n, -1, dtype=np.int64)
        after = -1
        for k in range(n - 1, -1, -1):
            following[k] = after
            if items[k].command in NAV_COMMANDS and not math.isnan(items[k].x_m):
                after = k
        return cls(np.array([i.seq for i in items], dtype=np.int64), command, position,
                   params, following)

    def with_positions(self, index: np.ndarray, xy_m: np.ndarray) -> "MissionArrays":
        """The same mission with items ``index`` moved to ``xy_m`` (local frame)."""
        position = self.position.copy()
        position[index, :2] = xy_m
        return replace(self, position=position)

    def index_of(self, seq: int) -> int:
        return int(np.searchsorted(self.seq, seq))


_TRACK_CHUNK = 1 << 16
#: Closest approaches are followed step by step only within this distance; a point never
#: passed within it is measured exactly by a second flight of its own (rare: a miss that large).
_APPROACH_CAP_M = 60.0


@dataclass(frozen=True)
class Checkpoint:
    """A flight as an item became current: the flight it was taken from and its state then
    (restored only when asked for: a run takes hundreds, a design uses few), the track rows of
    the run recorded before it, and the least distance to each point so far."""

    source: "MissionFlight"
    state: np.ndarray
    rows: int
    closest_m: np.ndarray

    @property
    def flight(self) -> "MissionFlight":
        """A new flight from the checkpoint on, continuing on its own."""
        return self.source._restored(self.state)

    def resumed(self, items: "list[LocalItem] | MissionArrays") -> "MissionFlight":
        """A new flight from the checkpoint on, flying ``items`` (the same seqs, other
        positions or parameters) from here instead of the flight's own."""
        return self.source._restored(self.state, items)


@dataclass(frozen=True)
class FlightRun:
    """What :meth:`MissionFlight.run` recorded: track rows (time, x, y, altitude), the
    least distance to each point, the ground distance flown since the points began to be
    measured (this flight's, from its start), and the checkpoints taken (seq -> checkpoint)."""

    track: np.ndarray
    closest_m: np.ndarray
    measured_length_m: float
    checkpoints: dict[int, Checkpoint]
    stopped: int


class MissionFlight:
    """Flies ``items`` from ``first_seq`` on, starting at home (0, 0) on the ground heading
    ``heading_rad``, in ``wind``: the compiled model of :mod:`.flight_kernel` behind a small
    object.  :attr:`reached` lists (seq, time) of every item completed, in order."""

    def __init__(self, items: list[LocalItem] | MissionArrays, airframe: Airframe,
                 heading_rad: float, first_seq: int = 0, wind: Wind = CALM) -> None:
        self.mission = items if isinstance(items, MissionArrays) else MissionArrays.of(items)
        self.airframe = airframe
        self.wind = wind
        self._af = airframe_vector(airframe, wind)
        n = len(self.mission.seq)
        self._state = K.new_state(heading_rad, airframe.airspeed_m_s,
                                  self.mission.index_of(first_seq) if n else 0)
        self._reached = np.zeros((n + 1, 2))
        self._counts = np.zeros(2, dtype=np.int64)
        if n:
            K.start(self._state, self._af, self.mission.command, self.mission.params,
                    self._reached, self._counts)
        else:
            self._state[K.S_FINISHED] = 1.0

    def copy(self, items: list[LocalItem] | MissionArrays | None = None) -> "MissionFlight":
        """The flight as it is now, continuing on its own from here: stepping the copy leaves
        this one as it is.  ``items`` (same seqs, other positions or parameters) are flown
        from here on instead of the flight's own."""
        other = MissionFlight.__new__(MissionFlight)
        other.mission = self.mission if items is None else (
            items if isinstance(items, MissionArrays) else MissionArrays.of(items))
        other.airframe, other.wind, other._af = self.airframe, self.wind, self._af
        other._state = self._state.copy()
        other._reached = self._reached.copy()
        other._counts = self._counts.copy()
        return other

    def _restored(self, state: np.ndarray, mission: MissionArrays | None = None) -> "MissionFlight":
        """A copy of this flight at the checkpoint ``state`` (reach events after it dropped)."""
        other = self.copy(mission)
        other._state = state[:K.STATE_SIZE].copy()
        time = other._state[K.S_TIME]
        k = int(np.searchsorted(other._reached[:other._counts[0], 1], time, side="right"))
        other._counts[0] = k
        return other

    @property
    def state(self) -> AircraftState:
        s = self._state
        return AircraftState(float(s[K.S_X]), float(s[K.S_Y]), float(s[K.S_ALT]),
                             float(s[K.S_HEADING]), float(s[K.S_AIRSPEED]), float(s[K.S_BANK]),
                             float(s[K.S_BANK_RATE]), float(s[K.S_TIME]))

    @property
    def time_s(self) -> float:
        return float(self._state[K.S_TIME])

    @property
    def ground_velocity_m_s(self) -> tuple[float, float]:
        """(east, north) velocity over the ground."""
        s = self._state
        scale = 1.0 if s[K.S_ALT] >= self.wind.full_altitude_m else (
            math.sqrt(max(s[K.S_ALT], 0.0) / self.wind.full_altitude_m))
        wx, wy = self.wind.velocity_m_s
        speed = s[K.S_AIRSPEED]
        return (speed * math.cos(s[K.S_HEADING]) + wx * scale,
                speed * math.sin(s[K.S_HEADING]) + wy * scale)

    @property
    def finished(self) -> bool:
        return bool(self._state[K.S_FINISHED])

    @property
    def reached(self) -> list[tuple[int, float]]:
        return self.reached_since(0)

    def reached_since(self, first: int) -> list[tuple[int, float]]:
        """The reach events (seq, time) from the ``first``-th on."""
        seqs = self.mission.seq
        return [(int(seqs[int(i)]), float(t)) for i, t in self._reached[first:int(self._counts[0])]]

    @property
    def current_seq(self) -> int | None:
        i = int(self._state[K.S_INDEX])
        return None if self.finished else int(self.mission.seq[i])

    def step(self, dt: float) -> None:
        """Advance ``dt`` seconds; completed items go to :attr:`reached`."""
        m = self.mission
        K.step(self._state, self._af, m.command, m.position, m.params, m.following,
               self._reached, self._counts, dt)

    def run(self, dt: float, stop_after_seq: int | None = None, until_s: float = math.inf,
            track: bool = True, marks: set[int] | None = None, points_m: np.ndarray | None = None,
            closest_m: np.ndarray | None = None, measure_from_seq: int = 0) -> FlightRun:
        """Steps of ``dt`` until item ``stop_after_seq`` is reached, the flight time reaches
        ``until_s`` or the mission ends.  Records the track rows (time, x, y, altitude) if
        ``track``; a checkpoint as each item of ``marks`` becomes current; and, from the moment
        item ``measure_from_seq`` or a later one is current, the exact least distance of the
        track (each step's chord) to each of ``points_m`` (local frame; starting from
        ``closest_m``, else infinity) and the ground distance flown."""
        m = self.mission
        n = len(m.seq)
        stop_index = -1 if stop_after_seq is None else m.index_of(stop_after_seq)
        points = np.zeros((0, 2)) if points_m is None else np.ascontiguousarray(points_m, float).reshape(-1, 2)
        best = (np.full(len(points), np.inf) if closest_m is None
                else np.array(closest_m, dtype=float))
        mark_array = np.zeros(n if marks else 0, dtype=np.bool_)
        if marks:
            for seq in marks:
                k = m.index_of(seq)
                if k < n and m.seq[k] == seq:
                    mark_array[k] = True
        saved = np.full((len(mark_array), K.STATE_SIZE + len(points)), np.nan)
        chunks = []
        buffer = np.empty((_TRACK_CHUNK if track else 0, 4))
        origin = self.copy() if len(points) else None
        measure_from = m.index_of(measure_from_seq)
        while True:
            counts = np.array([self._counts[0], 0], dtype=np.int64)
            stopped = K.run(self._state, self._af, m.command, m.position, m.params, m.following,
                            dt, stop_index, until_s, self._reached, counts, buffer,
                            mark_array, saved, points, best, measure_from, _APPROACH_CAP_M)
            self._counts[0] = counts[0]
            if track:
                chunks.append(buffer[:int(counts[1])].copy())
            if stopped != K.STOP_TRACK_FULL:
                break
        far = np.flatnonzero(best >= _APPROACH_CAP_M)
        if len(far):
            # Points never passed within the cap: the same flight again, exact for them alone.
            again = closest_m[far] if closest_m is not None else np.full(len(far), np.inf)
            again = np.array(again, dtype=float)
            count = np.zeros(2, dtype=np.int64)
            count[0] = origin._counts[0]
            K.run(origin._state, origin._af, m.command, m.position, m.params, m.following, dt,
                  stop_index, until_s, origin._reached, count, np.empty((0, 4)),
                  np.zeros(0, dtype=np.bool_), saved[:0, :K.STATE_SIZE + len(far)],
                  np.ascontiguousarray(points[far]), again, measure_from, math.inf)
            best[far] = again
        track_rows = np.concatenate(chunks) if chunks else np.zeros((0, 4))
        taken = np.flatnonzero(mark_array)
        taken = taken[~np.isnan(saved[taken, 0])]
        rows = np.searchsorted(track_rows[:, 0], saved[taken, K.S_TIME], side="right")
        # a checkpoint refers to this flight, which may fly on: restoring one copies the
        # saved state and drops the reach events after it
        checkpoints = {int(m.seq[k]): Checkpoint(self, saved[k, :K.STATE_SIZE],
                                                 int(r), saved[k, K.STATE_SIZE:])
                       for k, r in zip(taken, rows)}
        return FlightRun(track_rows, best, self.measured_length_m, checkpoints, int(stopped))

    @property
    def measured_length_m(self) -> float:
        """Ground distance flown since points began to be measured (0 before)."""
        start = self._state[K.S_MEASURE_START]
        return 0.0 if math.isnan(start) else float(self._state[K.S_ODOMETER] - start)


def closest_approach_m(track_xy: np.ndarray, points_xy: np.ndarray) -> np.ndarray:
    """For each point, the smallest distance to the polyline ``track_xy`` (exact per segment).

    A point's nearest segment has an end within (distance to the nearest vertex + the longest
    segment) of it, so only the segments at the vertices in that ball are measured."""
    from scipy.spatial import cKDTree
    track = np.asarray(track_xy, dtype=float).reshape(-1, 2)
    points = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    if len(track) == 0:
        return np.full(len(points), np.inf)
    if len(track) == 1:
        return np.hypot(*(points - track[0]).T)
    a, d = track[:-1], np.diff(track, axis=0)
    length2 = np.maximum((d * d).sum(axis=1), 1e-18)
    longest = float(np.sqrt(length2.max()))
    tree = cKDTree(track)
    nearest, _ = tree.query(points)
    result = np.empty(len(points))
    for k, (p, radius) in enumerate(zip(points, nearest)):
        vertices = np.asarray(tree.query_ball_point(p, radius + longest + 1e-9), dtype=np.int64)
        segments = np.unique(np.clip(np.concatenate([vertices - 1, vertices]), 0, len(a) - 1))
        t = np.clip(((p - a[segments]) * d[segments]).sum(axis=1) / length2[segments], 0.0, 1.0)
        q = a[segments] + t[:, None] * d[segments]
        result[k] = float(np.sqrt(((q - p) ** 2).sum(axis=1).min()))
    return result
