"""The pipeline in two calls, for scripts: targets in degrees -> checked tour -> mission.

Both are the same composition the CLI's ``plan`` runs (:func:`dtsp_mission.pipeline.run_plan`);
use :mod:`dtsp_mission.pipeline` for the whole result (notes, lower bound, sorties) and the
stage modules (``frame``, ``planning``, ``mission``) for finer control.
"""

from __future__ import annotations

from typing import Any

from .frame import LocalFrame
from .mission import Mission, MissionSettings
from .pipeline import PlanRequest, place, run_plan
from .targets import GeoTargets, Targets
from .tour import Tour


def local_frame_for(targets: GeoTargets) -> tuple[LocalFrame, Targets]:
    """The local metric frame centred on the targets, and the targets in it (raises
    :class:`~dtsp_mission.errors.InputError` if the area is too big for one local frame)."""
    local, _, frame = place(targets)
    return frame, local


def plan_tour(targets: GeoTargets, rho_m: float, algorithm: str = "auto",
              **parameters: Any) -> tuple[Tour, LocalFrame]:
    """A checked closed Dubins tour through the targets (planner ``algorithm``; no fallback),
    in the local frame it returns with it."""
    result = run_plan(PlanRequest(targets, rho_m, algorithm, parameters, fallback=False))
    return result.tour, result.frame


def plan_mission(targets: GeoTargets, rho_m: float, settings: MissionSettings | None = None,
                 algorithm: str = "auto", **parameters: Any) -> Mission:
    """The mission (take-off, the tour as waypoints within the tolerance, return) for the
    targets; ``settings`` default to :class:`~dtsp_mission.mission.MissionSettings()`.  As in
    ``plan``, the guidance design may widen the turn radius (the mission's ``rho_m`` says).
    Raises :class:`~dtsp_mission.errors.MissionTooLarge` if it does not fit the vehicle (use
    :func:`~dtsp_mission.pipeline.run_plan` for the sorties)."""
    return run_plan(PlanRequest(targets, rho_m, algorithm, parameters, fallback=False,
                                settings=settings or MissionSettings(), too_large="raise")).mission


__all__ = ["local_frame_for", "plan_mission", "plan_tour"]
