"""What a mission is to be: the settings of the mission stage, checked once, before planning.

:class:`MissionSettings` holds every choice (autopilot, altitudes, speed, return, design,
storage, actions, wind, the guidance design's tuning); :meth:`MissionSettings.checked` fills
the defaults and refuses what no autopilot would fly; :func:`check_altitude_floor` refuses
targets below the floor above home.  The design (:mod:`.build`) takes settings only in their
checked form.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from ..targets import GeoTargets
from ..targets.actions import check_gimbal_pitch
from ..targets.model import MAX_ALTITUDE_M
from ..autopilot.commands import AUTOPILOTS
from ..autopilot.navigation import (CALM, MAX_WIND_M_S, Airframe, Wind, check_turn_radius,
                                    check_wind)
from ..autopilot.parameters import ARDUPLANE_DEFAULTS, PX4Parameters, VehicleParameters, parameters_of
from ..autopilot.storage import MAVLINK_MAX_ITEMS, capacity
from .flight_path import TAKEOFF_CLIMB_DEG
from .guidance import DesignTuning

#: Default largest distance between the exact path and the waypoint polyline, in rho.
DEFAULT_TOLERANCE_RHO = 0.02
#: The discretiser first tries this fraction of the tolerance, and coarsens only to fit.
PREFERRED_TOLERANCE_FRACTION = 0.25
#: Mission slots a stock vehicle holds (home included on ArduPilot): ArduPlane answers
#: MISSION_COUNT 656 with NO_SPACE; PX4's default dataman holds 500.
DEFAULT_MAX_ITEMS = {name: capacity(autopilot) for name, autopilot in AUTOPILOTS.items()}
RETURN_MODES = ("rtl", "land", "none")
#: How waypoints are chosen: for the autopilot's guidance (predicted with the flight model),
#: or as a polyline within a tolerance of the exact path.
DESIGNS = ("guidance", "geometry")


#: The guidance design holds targets this much inside --max-miss in its model.  Measured over
#: the 480 targets of the nine planned missions flown by a real ArduPlane SITL (recorded with
#: stock and other tunings, with and without wind; docs/arduplane-agreement.md): of the targets
#: the model passed within 3.5 m, 2.9 % (7 of 245) were missed by more than 5 m, against 20 % of those
#: within 3.5-4.5 m (docs/mission-items.md has the table).
MODEL_MARGIN_M = 1.5
MIN_DESIGN_LIMIT_M = 0.5
#: The design is flown in the forecast wind and in winds this fraction stronger and weaker
#: (at least MIN_WIND_SPREAD_M_S: a calm forecast is flown in that much wind from the four
#: quarters) and turned WIND_SPREAD_DEG each way: a forecast is rarely closer, and an aim that
#: holds only for one exact waypoint switch fails in one of them.
DEFAULT_WIND_SPREAD = 0.25
MIN_WIND_SPREAD_M_S = 1.0
WIND_SPREAD_DEG = 20.0


#: No cruise or target altitude below this many metres above home unless the user lowers the
#: floor: below it a fixed wing meets trees, masts and buildings, and a mistyped ``alt`` (0.5,
#: a target at 0.001 m) is far likelier than a site that is clear at that height.
DEFAULT_MIN_ALTITUDE_M = 30.0


@dataclass(frozen=True)
class MissionSettings:
    """How to turn a tour into a mission.  ``None`` means the default stated in each note."""

    autopilot: str = "ardupilot"
    altitude_m: float = 100.0              # cruise altitude above home (at most MAX_ALTITUDE_M)
    airspeed_m_s: float | None = None
    home_deg: tuple[float, float] | None = None       # (lat, lon); default the mission centre
    home_altitude_amsl_m: float = 0.0
    launch_bearing_deg: float | None = None   # compass; default towards the first target
    landing_bearing_deg: float | None = None  # compass; default the launch bearing
    return_mode: str | None = None            # rtl | land | none; default rtl (ArduPilot), land (PX4)
    tolerance_m: float | None = None          # default DEFAULT_TOLERANCE_RHO * rho
    max_items: int | None = None              # default DEFAULT_MAX_ITEMS[autopilot]
    target_acceptance_m: float = 5.0          # acceptance radius of target waypoints
    takeoff_pitch_deg: float = TAKEOFF_CLIMB_DEG
    design: str = "geometry"                  # guidance | geometry (see DESIGNS)
    max_miss_m: float = 5.0                   # guidance: the predicted miss every target must hold
    vehicle: VehicleParameters | PX4Parameters | None = None  # the autopilot's parameters (stock if None)
    photo: bool = False                       # a picture at every target
    roi: bool = False                         # the camera pointed at every target
    gimbal_pitch_deg: float | None = None     # gimbal pitch for targets without their own
    loiter_radius_m: float | None = None      # default actions.LOITER_RADIUS_RHO * rho
    wind: Wind = CALM                         # guidance: the steady wind the mission is designed for
    wind_spread_m_s: float | None = None      # guidance: how far off the forecast the wind may be;
                                              # default DEFAULT_WIND_SPREAD of it, at least 1 m/s
    model_margin_m: float | None = None       # guidance: held this much inside max_miss_m in the
                                              # model; default MODEL_MARGIN_M
    tuning: DesignTuning = DesignTuning()     # guidance: the design's tuning (measured defaults)
    min_altitude_m: float = DEFAULT_MIN_ALTITUDE_M  # no target or cruise altitude below this
                                              # (above home); lower it only for a clear site

    def checked(self, rho_m: float) -> "MissionSettings":
        """The settings with defaults filled in, or :class:`InputError` saying what is wrong."""
        if self.autopilot not in AUTOPILOTS:
            raise InputError(f"unknown autopilot {self.autopilot!r}; choose ardupilot or px4")
        if not (math.isfinite(self.altitude_m) and self.altitude_m > 0):
            raise InputError(f"altitude must be a number above 0 m (above home), got "
                             f"{self.altitude_m!r}")
        if self.altitude_m > MAX_ALTITUDE_M:
            raise InputError(f"altitude {self.altitude_m:g} m above home is beyond "
                             f"{MAX_ALTITUDE_M:g} m, higher than the fixed wings this plans for "
                             "fly (a typo, or feet for metres?)")
        if not (math.isfinite(self.min_altitude_m) and 0 < self.min_altitude_m <= MAX_ALTITUDE_M):
            raise InputError(f"the altitude floor (`min_altitude_m`) must be a number of metres above 0, "
                             f"got {self.min_altitude_m!r}")
        if self.altitude_m < self.min_altitude_m:
            raise InputError(f"altitude {self.altitude_m:g} m above home is below the floor of "
                             f"{self.min_altitude_m:g} m (`min_altitude_m`); if the site is clear that "
                             "low, lower the floor explicitly")
        if self.airspeed_m_s is not None and not (math.isfinite(self.airspeed_m_s)
                                                  and self.airspeed_m_s > 0):
            raise InputError(f"airspeed must be a number above 0 m/s, got {self.airspeed_m_s!r}")
        return_mode = self.return_mode or ("land" if self.autopilot == "px4" else "rtl")
        if return_mode not in RETURN_MODES:
            raise InputError(f"unknown return {return_mode!r}; choose {', '.join(RETURN_MODES)}")
        tolerance = DEFAULT_TOLERANCE_RHO * rho_m if self.tolerance_m is None else self.tolerance_m
        if not (math.isfinite(tolerance) and 0 < tolerance <= rho_m):
            raise InputError(f"the waypoint tolerance must be above 0 and at most rho "
                             f"({rho_m:g} m), got {tolerance!r}")
        max_items = DEFAULT_MAX_ITEMS[self.autopilot] if self.max_items is None else self.max_items
        if max_items < 1:
            raise InputError(f"`max_items` must be at least 1, got {max_items}")
        if max_items > MAVLINK_MAX_ITEMS:
            raise InputError(f"`max_items` {max_items} is more than MAVLink can address: a "
                             f"mission has at most {MAVLINK_MAX_ITEMS} items (16-bit sequence numbers)")
        if self.design not in DESIGNS:
            raise InputError(f"unknown waypoint design {self.design!r}; choose {', '.join(DESIGNS)}")
        if not (math.isfinite(self.max_miss_m) and self.max_miss_m > 0):
            raise InputError(f"`max_miss_m` must be a number above 0 m, got {self.max_miss_m!r}")
        if not (math.isfinite(self.home_altitude_amsl_m) and abs(self.home_altitude_amsl_m) < 1e4):
            raise InputError(f"home altitude must be a number of metres above sea level, got "
                             f"{self.home_altitude_amsl_m!r}")
        if self.gimbal_pitch_deg is not None:
            check_gimbal_pitch(self.gimbal_pitch_deg, "`gimbal_pitch_deg`")
        if self.loiter_radius_m is not None and not (math.isfinite(self.loiter_radius_m)
                                                     and rho_m <= self.loiter_radius_m <= 2550.0):
            raise InputError(f"`loiter_radius_m` must be from the turn radius "
                             f"({rho_m:g} m) to 2,550 m (the most ArduPilot stores), got "
                             f"{self.loiter_radius_m!r}")
        airspeed = self.airspeed_m_s or self.design_airframe().airspeed_m_s
        check_wind(self.wind, airspeed)
        spread = (max(MIN_WIND_SPREAD_M_S, DEFAULT_WIND_SPREAD * self.wind.speed_m_s)
                  if self.wind_spread_m_s is None else self.wind_spread_m_s)
        if not (math.isfinite(spread) and 0 <= spread <= MAX_WIND_M_S):
            raise InputError(f"the wind spread (`wind_spread_m_s`) must be from 0 to "
                             f"{MAX_WIND_M_S:g} m/s, got {spread!r}")
        strongest = self.wind.speed_m_s + spread
        if strongest > 0.7 * airspeed:
            given = (f"the wind given ({self.wind.speed_m_s:g} m/s) plus " if self.wind.speed_m_s
                     else "in calm air, ")
            raise InputError(
                f"the guidance design also flies {given}its spread of {spread:g} m/s "
                f"(`wind_spread_m_s`{', by default a quarter of the wind and at least 1 m/s' if self.wind_spread_m_s is None else ''}): "
                f"{strongest:g} m/s is more than 70 % of the airspeed ({airspeed:g} m/s); "
                f"give a smaller `wind_spread_m_s` (at most "
                f"{max(0.0, 0.7 * airspeed - self.wind.speed_m_s):.1f} m/s) or a faster `airspeed_m_s`")
        if self.autopilot == "ardupilot" and (self.vehicle is not None or self.design == "guidance"
                                              or self.airspeed_m_s is not None):
            check_turn_radius(rho_m, self.vehicle or ARDUPLANE_DEFAULTS, self.airspeed_m_s)
        margin = MODEL_MARGIN_M if self.model_margin_m is None else self.model_margin_m
        if not (math.isfinite(margin) and 0 <= margin <= self.max_miss_m - MIN_DESIGN_LIMIT_M):
            raise InputError(f"the model margin must be from 0 m to {MIN_DESIGN_LIMIT_M:g} m "
                             f"less than `max_miss_m` ({self.max_miss_m:g} m), got {margin!r}")
        for name in ("launch_bearing_deg", "landing_bearing_deg"):
            value = getattr(self, name)
            if value is not None and not math.isfinite(value):
                raise InputError(f"{name.replace('_deg', '').replace('_', ' ')} must be a number "
                                 "of degrees")
        if self.landing_bearing_deg is not None and return_mode != "land":
            raise InputError(f"a landing bearing is for `return_mode` land; with {return_mode} "
                             "the mission has no landing of its own (RTL lands as the autopilot's "
                             "RTL does): leave it out or return with land")
        if self.tolerance_m is not None and self.design == "guidance":
            raise InputError("the waypoint tolerance (`tolerance_m`) is for `design` geometry; the "
                             "guidance design places its waypoints by the predicted flight, held "
                             "within `max_miss_m`: leave it out or design the geometry")
        bearings = {name: getattr(self, name) % 360.0 for name in
                    ("launch_bearing_deg", "landing_bearing_deg") if getattr(self, name) is not None}
        return replace(self, return_mode=return_mode, tolerance_m=tolerance, max_items=max_items,
                       wind_spread_m_s=spread, model_margin_m=margin, **bearings)

    def design_airframe(self) -> Airframe:
        """The aircraft the guidance design flies: the autopilot's navigation with the
        vehicle's parameters (a stock vehicle's if None) at the airspeed asked for."""
        parameters = parameters_of(self.autopilot, self.vehicle)
        if isinstance(parameters, PX4Parameters):
            return Airframe.from_px4_parameters(parameters, self.airspeed_m_s)
        return Airframe.from_parameters(parameters, self.airspeed_m_s)

    @property
    def design_limit_m(self) -> float:
        """The guidance design holds every target this close in the model, in every wind of
        :meth:`design_winds`: ``max_miss_m`` less the model's measured error margin."""
        margin = MODEL_MARGIN_M if self.model_margin_m is None else self.model_margin_m
        return self.max_miss_m - margin

    def design_winds(self) -> tuple[Wind, ...]:
        """The winds the guidance design is flown in: the forecast first, then the forecast
        stronger and weaker by the spread and turned by :data:`WIND_SPREAD_DEG` each way (in
        calm air: the spread from the four quarters)."""
        spread = (max(MIN_WIND_SPREAD_M_S, DEFAULT_WIND_SPREAD * self.wind.speed_m_s)
                  if self.wind_spread_m_s is None else self.wind_spread_m_s)
        w = self.wind
        if spread <= 0:
            return (w,)
        if w.speed_m_s <= 0:
            return (w, *(Wind(spread, d, w.full_altitude_m) for d in (0.0, 90.0, 180.0, 270.0)))
        return (w, Wind(w.speed_m_s + spread, w.from_deg, w.full_altitude_m),
                Wind(max(w.speed_m_s - spread, 0.0), w.from_deg, w.full_altitude_m),
                Wind(w.speed_m_s, (w.from_deg + WIND_SPREAD_DEG) % 360, w.full_altitude_m),
                Wind(w.speed_m_s, (w.from_deg - WIND_SPREAD_DEG) % 360, w.full_altitude_m))


def check_altitude_floor(targets: GeoTargets, settings: MissionSettings) -> None:
    """:class:`InputError` naming the first target whose altitude is below the settings'
    floor (``min_altitude_m`` above home)."""
    if targets.altitudes_m is None:
        return
    altitudes = np.asarray(targets.altitudes_m, dtype=float)
    low = np.flatnonzero(~np.isnan(altitudes) & (altitudes < settings.min_altitude_m))
    if len(low):
        raise InputError(
            f"{len(low)} target(s) below the altitude floor of {settings.min_altitude_m:g} m "
            f"above home (`min_altitude_m`), first {targets.label(int(low[0]))} at "
            f"{altitudes[low[0]]:g} m; if the site is clear that low, lower the floor "
            "explicitly")
