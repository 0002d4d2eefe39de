"""The planning pipeline in one place: targets -> local frame -> checked tour -> mission (or
sorties).  The CLI's ``plan`` and the Python API (:mod:`dtsp_mission.api`) are its two faces:
both build a :class:`PlanRequest`, call :func:`run_plan` and read the :class:`PlanResult`.

Stages, each a module of its own: :mod:`.frame` (the local metric frame), :mod:`.planning`
(the tour, with the Alternating Algorithm as the fallback when the RBTA cannot tile),
:mod:`.mission` (the items; for the guidance design a wider turn radius where it holds more
targets; sorties when one mission does not fit the storage or the endurance).  Writing files,
drawing, uploading and flying read the result and are not part of it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable

import numpy as np

from .dubins.path import check_radius
from .errors import InputError, MissionTooLarge
from .frame import LocalFrame, mission_centre
from .mission import Mission, MissionSettings, build_mission
from .mission.build import check_storage
from .mission.widening import targets_beyond, with_turn_margin
from .mission.settings import check_altitude_floor
from .mission.sorties import Sortie, split_into_sorties
from .planning import TilingUnavailable, get_planner
from .planning.lower_bounds import LowerBound, lower_bound
from .planning.wind_tour import WindTour, plan_wind_tour
from .targets import GeoTargets, Targets
from .tour import Tour


#: What becomes of a mission too large for the vehicle (:attr:`PlanRequest.too_large`).
TOO_LARGE = ("split", "raise", "note")


@dataclass(frozen=True)
class PlanRequest:
    """What to plan.

    ``targets`` in degrees (:class:`GeoTargets`) or local metres (:class:`Targets`, placed on
    the earth by ``origin`` (lat, lon) if given).  ``algorithm`` and ``parameters`` choose the
    planner; ``fallback`` plans with the Alternating Algorithm when the RBTA cannot tile.
    ``settings`` ask for a mission (None: the tour only); ``too_large`` says what becomes of
    a mission too large for the vehicle: ``split`` into sorties, ``raise``
    :class:`~dtsp_mission.errors.MissionTooLarge`, or ``note`` it -- the caller wants only the
    tour, so the mission is not designed, only checked against the storage; ``endurance_s``
    splits a longer flight into sorties.
    """

    targets: GeoTargets | Targets
    rho_m: float
    algorithm: str = "auto"
    parameters: dict[str, Any] = field(default_factory=dict)
    fallback: bool = True
    origin: tuple[float, float] | None = None
    settings: MissionSettings | None = None
    too_large: str = "split"
    endurance_s: float | None = None

    def __post_init__(self) -> None:
        """:class:`InputError` for a ``too_large`` that is none of its three values (a typo
        would otherwise mean "split")."""
        if self.too_large not in TOO_LARGE:
            raise InputError(f"PlanRequest.too_large must be one of {', '.join(TOO_LARGE)}, "
                             f"got {self.too_large!r}")


@dataclass
class PlanResult:
    """Everything one plan produced.

    ``local`` are the targets in the frame (duplicates merged), ``geodetic`` the same in degrees
    and ``frame`` the frame (both None for local targets without an origin).  ``mission`` is
    the one mission (None without settings, or when it does not fit the storage);
    ``sorties``, when not empty, are to be flown instead (``split_reason`` says why).  ``notes`` are the decisions a user should know about, in
    the order they were taken.  ``tour`` is the tour at the radius asked for; the guidance
    design may have planned the mission with a wider one (``mission.tour``, ``mission.rho_m``).
    ``wind_tour`` is, for a mission in a forecast wind at a given airspeed, the tour for that
    wind (from the tour's order, headings and order improved for time; checked), the measure
    of what the flight costs in that wind.
    """

    local: Targets
    geodetic: GeoTargets | None
    frame: LocalFrame | None
    tour: Tour
    planning_s: float
    area_m: np.ndarray | None = None
    mission: Mission | None = None
    sorties: list[Sortie] = field(default_factory=list)
    split_reason: str | None = None
    notes: list[str] = field(default_factory=list)
    wind_tour: WindTour | None = None

    @cached_property
    def bound(self) -> LowerBound:
        """Lower bounds on the optimal tour (the 1-tree, certified; the estimate for uniform
        targets), at the radius asked for."""
        return _bound(self.local.positions_m, self.tour.rho_m, self.area_m)

    @property
    def product(self) -> Tour | Mission:
        """What a file writer renders: the mission if there is one, else the tour."""
        return self.mission if self.mission is not None else self.tour


def place(targets: GeoTargets | Targets,
          origin: tuple[float, float] | None = None) -> tuple[Targets, GeoTargets | None, LocalFrame | None]:
    """The targets in their local frame, in degrees, and the frame (the last two None for
    local targets without ``origin``); :class:`InputError` if they do not fit one frame."""
    if isinstance(targets, GeoTargets):
        if origin is not None:
            raise InputError("an `origin` is for targets in local x/y metres; these are in lat/lon")
        frame = LocalFrame(*mission_centre(targets.latitudes_deg, targets.longitudes_deg))
        return targets.in_frame(frame), targets, frame
    if origin is None:
        return targets, None, None
    frame = LocalFrame(*origin)
    geodetic = targets.to_geodetic(frame)
    frame.check_extent(geodetic.latitudes_deg, geodetic.longitudes_deg)
    return targets, geodetic, frame


def plan_tour_in(positions_m: np.ndarray, rho_m: float, algorithm: str = "auto",
                 parameters: dict[str, Any] | None = None, fallback: bool = True,
                 progress: Callable[[float], None] | None = None,
                 notes: list[str] | None = None) -> Tour:
    """The checked tour of one planner, or of the Alternating Algorithm when the RBTA cannot
    tile and ``fallback`` allows (said in ``notes``)."""
    try:
        planner = get_planner(algorithm, **(parameters or {}))
        if progress is not None and hasattr(planner, "progress"):
            planner.progress = progress
        return planner.plan(positions_m, rho_m)
    except TilingUnavailable as error:
        if not fallback:
            raise
        if notes is not None:
            notes.append(f"{error}; planning with the Alternating Algorithm instead")
        return get_planner("alternating").plan(positions_m, rho_m)


def _area_m(geodetic: GeoTargets | None, frame: LocalFrame | None) -> np.ndarray | None:
    if geodetic is None or geodetic.area_deg is None:
        return None
    return frame.to_local(geodetic.area_deg[:, 0], geodetic.area_deg[:, 1])


def _bound(positions: np.ndarray, rho_m: float, area_m: np.ndarray | None) -> LowerBound:
    if area_m is not None:
        import shapely
        area = float(shapely.Polygon(area_m).area)
    else:
        area = max(float(np.ptp(positions[:, 0]) * np.ptp(positions[:, 1])), 1.0)
    return lower_bound(positions, rho_m, area)


#: The widest turn radius a mission is planned with: a turn circle 40 km across already fills a
#: good part of the flat mission frame (about 150 km from its centre).
MAX_PLAN_RADIUS_M = 20_000.0


def check_request(request: PlanRequest) -> None:
    """:class:`InputError` for anything in ``request`` that cannot be planned, before any
    planning: the radius, targets that do not fit one frame or are fewer than 2, a mission
    for targets not on the earth, the mission's settings, the altitude floor, an endurance
    without an airspeed.  :func:`run_plan` makes exactly these checks first."""
    _checked(request)


def _checked(request: PlanRequest) -> tuple[Targets, GeoTargets | None, LocalFrame | None]:
    """:func:`check_request`, and the targets placed (:func:`place`)."""
    check_radius(request.rho_m)
    if request.rho_m > MAX_PLAN_RADIUS_M:
        raise InputError(f"a turn radius of {request.rho_m:g} m is beyond reason for a mission "
                         f"(at most {MAX_PLAN_RADIUS_M:,.0f} m: the turn alone would span more than "
                         "the mission frame holds); is it in metres?")
    settings = request.settings
    if request.endurance_s is not None and (settings is None or settings.airspeed_m_s is None):
        raise InputError("`endurance_s` needs `airspeed_m_s`: the flight time follows from it")
    local, geodetic, frame = place(request.targets, request.origin)
    if len(local) < 2:
        raise InputError(f"the targets hold {len(local)} target(s) after merging duplicates; a "
                         "tour needs at least 2 (for one point, fly a single waypoint)")
    if settings is not None and frame is None:
        raise InputError("a mission needs targets in degrees: these are local x/y metres, so "
                         "give `origin` LAT,LON (or ask for the tour only)")
    if settings is not None:
        settings.checked(request.rho_m)
        check_altitude_floor(geodetic, settings)
        if settings.home_deg is not None:
            try:
                frame.check_extent(*settings.home_deg, "targets and home")
            except InputError:
                km = float(np.hypot(*frame.to_local(*settings.home_deg)[0])) / 1000
                raise InputError(f"home ({settings.home_deg[0]:g}, {settings.home_deg[1]:g}) is "
                                 f"{km:,.0f} km from the targets: is `home_deg` right (latitude "
                                 "first)? A mission is flown from a home within about 150 km "
                                 "of its targets") from None
        actions = geodetic.actions
        if settings.loiter_radius_m is not None and (actions is None
                                                     or not actions.loiter_turns.any()):
            raise InputError("`loiter_radius_m` is the radius of the loiters at targets, and no "
                             "target loiters: give `loiter_turns` TARGET[:TURNS] (or a "
                             "loiter_turns column), or leave the radius out")
    return local, geodetic, frame


def run_plan(request: PlanRequest,
             progress: Callable[[float], None] | None = None,
             design_progress: Callable[[float], None] | None = None) -> PlanResult:
    """Plan ``request``: every stage in order, ``progress(fraction)`` while the tour improves
    and ``design_progress(fraction)`` while the guidance design flies its predictions.

    Guarantees: the tour passed the geometry checker; a mission (or each sortie's) fits the
    vehicle's storage; what was decided on the user's behalf is in ``notes``.  Bad input is an
    :class:`~dtsp_mission.errors.InputError` before any planning.
    """
    local, geodetic, frame = _checked(request)
    notes: list[str] = []
    if local.merged_duplicates:
        notes.append(f"{local.merged_duplicates} duplicate targets merged ({len(local)} remain)")
    area_m = _area_m(geodetic, frame)
    if area_m is not None:
        import shapely
        outside = int((~shapely.contains_xy(shapely.Polygon(area_m), *local.positions_m.T)).sum())
        if outside:
            notes.append(f"{outside} targets lie outside the survey area")
    started = time.perf_counter()
    tour = plan_tour_in(local.positions_m, request.rho_m, request.algorithm, request.parameters,
                        request.fallback, progress, notes)
    result = PlanResult(local, geodetic, frame, tour, time.perf_counter() - started, area_m,
                        notes=notes)
    settings = request.settings
    if settings is not None and settings.wind.speed_m_s > 0 and settings.airspeed_m_s:
        result.wind_tour = plan_wind_tour(tour.targets_m, tour.visit_order, tour.rho_m,
                                          settings.airspeed_m_s, settings.wind.velocity_m_s,
                                          ground_headings_rad=tour.visit_poses()[:, 2])
        result.wind_tour.check().raise_if_invalid()
    if request.settings is not None:
        _design_mission(request, result, design_progress)
    return result


def _design_mission(request: PlanRequest, result: PlanResult,
                    progress: Callable[[float], None] | None = None) -> None:
    """The mission stage: build, widen the turns for the guidance, split where needed."""
    settings, frame, geodetic, tour = request.settings, result.frame, result.geodetic, result.tour
    endurance_s = request.endurance_s
    # at most: the radius asked, then wider
    designs = 1 + len(settings.tuning.guidance_margins)

    def design_step(k: int) -> Callable[[int, int], None]:
        """Progress of the k-th design, as its share of all the designs' flights."""
        return lambda done, total: progress((k + done / total) / designs)
    if request.too_large == "note":     # only the tour is wanted: storage does not limit it
        try:
            check_storage(tour, frame, geodetic, settings)
        except MissionTooLarge as error:
            result.notes.append(f"as one mission this would not fit the vehicle: {error}")
        return
    try:
        mission = build_mission(tour, frame, geodetic, settings,
                                None if progress is None else design_step(0))
    except MissionTooLarge as error:
        if request.too_large == "raise":
            raise
        _split(request, result, f"as one mission it needs {error.needed} items (at least) but "
                                f"the vehicle holds {error.capacity} (`max_items`)")
        return
    if mission.guidance is not None:
        replan = lambda rho: plan_tour_in(result.local.positions_m, rho, request.algorithm,  # noqa: E731
                                          request.parameters, request.fallback)
        widened = with_turn_margin(mission, replan, geodetic, settings,
                                   None if progress is None else design_step)
        if widened is not mission:
            result.notes.append(
                f"planned with a turn radius of {widened.rho_m:g} m instead of "
                f"{mission.rho_m:g} m so that the autopilot's guidance can hold the turns: "
                f"{targets_beyond(mission)} -> {targets_beyond(widened)} targets predicted "
                f"beyond {settings.design_limit_m:g} m, the predicted flight "
                f"{mission.summary['predicted_flight_m'] / 1e3:,.2f} -> "
                f"{widened.summary['predicted_flight_m'] / 1e3:,.2f} km")
            mission = widened
    result.mission = mission
    flight_s = mission.summary.get("flight_time_s", 0.0)
    if endurance_s is not None and flight_s > endurance_s:
        _split(request, result, f"the flight takes {flight_s / 60:.1f} min, more than the "
                                f"endurance of {endurance_s / 60:g} min (`endurance_s`)")


def _split(request: PlanRequest, result: PlanResult, reason: str) -> None:
    """Sorties of the tour, each planned again with wider turns where the guidance needs
    them (as a single mission is)."""
    settings, frame = request.settings, result.frame
    home_m = (frame.to_local(*settings.home_deg)[0] if settings.home_deg is not None
              else np.zeros(2))
    replan = lambda positions, rho: plan_tour_in(positions, rho, request.algorithm,  # noqa: E731
                                                 request.parameters, request.fallback)
    result.sorties = split_into_sorties(result.tour, frame, result.geodetic, settings, home_m,
                                        request.endurance_s, replan)
    result.split_reason = reason


__all__ = ["PlanRequest", "PlanResult", "place", "plan_tour_in", "run_plan"]
