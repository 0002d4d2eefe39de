"""Wider turns where the guidance cannot hold the tour: the mission of the radius asked for,
or of a tour planned with a wider radius when that holds more targets or flies shorter."""

from __future__ import annotations

from typing import Callable

from ..errors import DtspError
from ..targets import GeoTargets
from ..tour import Tour
from .build import build_mission
from .model import Mission
from .settings import MissionSettings


def targets_beyond(mission: Mission, limit_m: float | None = None) -> int:
    """How many targets a guidance-designed mission does not hold: by default those judged
    beyond its design limit (``max_miss_m`` less the model's margin in the forecast wind, or
    beyond ``max_miss_m`` in the other design winds); with ``limit_m``, those predicted beyond it
    in the forecast wind.  0 for a geometric design (it predicts nothing)."""
    return 0 if mission.guidance is None else mission.guidance.targets_beyond(limit_m)


def with_turn_margin(mission: Mission, replan: Callable[[float], Tour], targets: GeoTargets,
                     settings: MissionSettings,
                     progress: Callable[[int], Callable[[int, int], None]] | None = None) -> Mission:
    """``mission`` if it is no guidance design, else the best of it and the missions of tours
    planned with wider turn radii (``replan(rho)``, ``settings.tuning.guidance_margins`` in
    turn): the fewest targets beyond the design limit, then the shortest predicted flight --
    flight time is what the operator pays for; how closely a flight follows its plan is only
    reported.  A wider tour is planned only while the best design leaves targets beyond (or,
    with ``tuning.widen_after_revisits``, holds them only by passing some twice), and, once a
    design holds every target, designed only if it is shorter than ``tuning.widen_below`` of
    that design's predicted flight.
    ``progress(k)`` gives the progress callback of the k-th design tried (``mission``'s was the
    0th)."""
    def key(candidate: Mission) -> tuple[int, float]:
        return targets_beyond(candidate), candidate.guidance.predicted_flight_m
    if mission.guidance is None:
        return mission
    best = mission
    for index, factor in enumerate(settings.tuning.guidance_margins):
        if key(best)[0] == 0 and (best.guidance.revisit_waypoints == 0
                                  or not settings.tuning.widen_after_revisits):
            break               # every target held
        try:
            tour = replan(mission.rho_m * factor)
            if key(best)[0] == 0 and (tour.length_m >= settings.tuning.widen_below
                                      * best.guidance.predicted_flight_m):
                break           # too little to gain, and wider still is longer still
            candidate = build_mission(tour, mission.frame, targets, settings,
                                      None if progress is None else progress(index + 1))
        except DtspError:
            continue
        if key(candidate) < key(best):
            best = candidate
    return best
