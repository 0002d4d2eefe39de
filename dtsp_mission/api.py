"""The pipeline in two calls, for scripts: targets in degrees -> checked tour -> mission.

Everything here is a thin composition of the stage modules (``frame``, ``planning``,
``mission``); use those directly for finer control.  The CLI's ``plan`` runs the same stages.
"""

from __future__ import annotations

from typing import Any

from .frame import LocalFrame, mission_centre
from .mission import Mission, MissionSettings, build_mission
from .planning import get_planner
from .targets import GeoTargets, Targets
from .tour import Tour


def local_frame_for(targets: GeoTargets) -> tuple[LocalFrame, Targets]:
    """The local metric frame centred on the targets, and the targets in it (raises
    :class:`~dtsp_mission.errors.InputError` if the area is too big for one local frame)."""
    frame = LocalFrame(*mission_centre(targets.latitudes_deg, targets.longitudes_deg))
    return frame, targets.in_frame(frame)


def plan_tour(targets: GeoTargets, rho_m: float, algorithm: str = "auto",
              **parameters: Any) -> tuple[Tour, LocalFrame]:
    """A checked closed Dubins tour through the targets (planner ``algorithm``), in the local
    frame it returns with it."""
    frame, local = local_frame_for(targets)
    return get_planner(algorithm, **parameters).plan(local.positions_m, rho_m), frame


def plan_mission(targets: GeoTargets, rho_m: float, settings: MissionSettings | None = None,
                 algorithm: str = "auto", **parameters: Any) -> Mission:
    """The mission (take-off, the tour as waypoints within the tolerance, return) for the
    targets; ``settings`` default to :class:`~dtsp_mission.mission.MissionSettings()`."""
    tour, frame = plan_tour(targets, rho_m, algorithm, **parameters)
    return build_mission(tour, frame, targets, settings or MissionSettings())


__all__ = ["local_frame_for", "plan_mission", "plan_tour"]
