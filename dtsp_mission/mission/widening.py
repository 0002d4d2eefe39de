"""Wider turns where the guidance cannot hold the tour: the mission of the radius asked for,
or of a tour planned with a wider radius when that holds more targets or flies shorter."""

from __future__ import annotations

from dataclasses import replace
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
    """``mission`` if it is no guidance design or holds every target, else the best of it and the
    missions of tours planned with wider turn radii (``replan(rho)``,
    ``settings.tuning.guidance_margins``, tried in turn until one holds every target): the fewest targets
    beyond the design limit, then the shortest predicted flight -- flight time is what the
    operator pays for; how closely a flight follows its plan is only reported.
    ``progress(k)`` gives the progress callback of the k-th design tried (``mission``'s was the
    0th)."""
    def key(candidate: Mission) -> tuple[int, float]:
        return targets_beyond(candidate), candidate.guidance.predicted_flight_m
    if mission.guidance is None:
        return mission
    best = mission
    for index, factor in enumerate(settings.tuning.guidance_margins):
        if key(best)[0] == 0:
            break
        try:
            candidate = build_mission(replan(mission.rho_m * factor), mission.frame, targets,
                                      settings, None if progress is None else progress(index + 1))
        except DtspError:
            continue
        if key(candidate) < key(best):
            best = candidate
    if key(best)[0] > 0 and settings.tuning.revisit_last and not settings.tuning.revisits:
        # Still targets beyond: the best design again, those targets passed a second time.
        again = replace(settings, tuning=replace(settings.tuning, revisits=True))
        try:
            candidate = build_mission(best.tour, best.frame, targets, again, None if progress is
                                      None else progress(len(settings.tuning.guidance_margins) + 1))
        except DtspError:
            candidate = best
        if key(candidate) < key(best):
            best = candidate
    return best
