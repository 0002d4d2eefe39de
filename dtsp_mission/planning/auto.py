"""``auto``: every applicable built-in planner, the shortest checked tour, then improved.

The peers are the RBTA (when the targets are numerous enough to tile), the Alternating
Algorithm, the lanes, and up to :data:`SLOW_PEERS_MAX_TARGETS` targets the heading-optimised
Euclidean tour and the Dubins nearest neighbour; the shortest of their tours goes through the Dubins-aware improvement stage
(:mod:`~dtsp_mission.planning.improve`), so the result is never longer than any peer it ran.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..errors import DtspError
from ..tour import Tour, tour_through_poses
from .alternating import AlternatingPlanner
from .base import Planner
from .headings import HeadingsPlanner
from .improve import improve_tour
from .lanes import LanesPlanner
from .nearest import NearestPlanner
from .rbta import RBTAPlanner
from .region import Region
from .tiling import TilingUnavailable

#: Work budget of the improvement stage when none is given, in reference seconds: 7 s up to
#: 2,000 targets, 2.8 ms more per target above, at most 30 s (29 s at 1e4 targets).
DEFAULT_TIME_LIMIT_S = 7.0
_DEFAULT_PER_TARGET_S = 0.0028
_DEFAULT_FROM_TARGETS = 2000
_DEFAULT_MAX_S = 30.0


def default_time_limit_s(targets: int) -> float:
    """The improvement budget ``auto`` uses for ``targets`` targets when none is given."""
    extra = max(0, targets - _DEFAULT_FROM_TARGETS) * _DEFAULT_PER_TARGET_S
    return min(DEFAULT_TIME_LIMIT_S + extra, _DEFAULT_MAX_S)

#: Above this many targets the Dubins nearest neighbour and the headings planner are not run:
#: there they are the slowest peers (30 s and 8 s at 1e5) and measured 3 to 6 times longer
#: than the best (docs/benchmarks-scaling.md).
SLOW_PEERS_MAX_TARGETS = 20_000


class AutoPlanner(Planner):
    """The shortest of the peers' tours, improved on exact Dubins lengths.

    Parameters: ``time_limit_s`` (the improver's work budget in reference seconds, default
    :func:`default_time_limit_s`; 0 keeps the best peer's tour as it is), ``seed`` (the
    improver's random choices, default 0), ``region`` (passed to the RBTA); ``progress``, a
    callable given the fraction of the improvement budget spent, is not a planning parameter
    and is not recorded with the tour.  ``report["candidates"]`` lists every peer's length.
    """

    name = "auto"
    description = "shortest checked tour of the built-in planners, improved on Dubins lengths (default)"

    def __init__(self, **parameters: Any) -> None:
        self.progress: Callable[[float], None] | None = parameters.pop("progress", None)
        super().__init__(**parameters)

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        peer_parameters = {k: v for k, v in self.parameters.items() if k == "region"}
        candidates: dict[str, float | str] = {}
        best: Tour | None = None
        failures: list[DtspError] = []
        for planner in (AlternatingPlanner(), HeadingsPlanner(), LanesPlanner(), NearestPlanner(),
                        RBTAPlanner(**peer_parameters)):
            if (isinstance(planner, (NearestPlanner, HeadingsPlanner))
                    and len(targets_m) > SLOW_PEERS_MAX_TARGETS):
                candidates[planner.name] = f"not run above {SLOW_PEERS_MAX_TARGETS} targets"
                continue
            try:
                tour = planner.plan(targets_m, rho_m, region)
            except TilingUnavailable as error:
                candidates[planner.name] = f"not applicable: {error}"
                continue
            except DtspError as error:     # a peer's failure is reported, never fatal
                candidates[planner.name] = f"failed: {error}"
                failures.append(error)
                continue
            candidates[planner.name] = tour.length_m
            if best is None or tour.length_m < best.length_m:
                best = tour
        if best is None:
            raise failures[0]
        limit = self.parameters.get("time_limit_s")
        limit = default_time_limit_s(len(targets_m)) if limit is None else float(limit)
        order = best.visit_order
        result = improve_tour(targets_m, order, best.visit_poses()[order, 2], rho_m, limit,
                              int(self.parameters.get("seed", 0)), self.progress)
        report = dict(best.report, chosen=best.planner, candidates=candidates,
                      improvement={"start_m": result.start_m, "length_m": result.length_m,
                                   "evaluations": result.evaluations, "budget": result.budget,
                                   "kicks": result.kicks, "stopped": result.stopped})
        if result.length_m < best.length_m:
            improved = tour_through_poses(targets_m, result.order, result.headings_rad, rho_m)
            if improved.length_m < best.length_m:
                return Tour(improved.chain, rho_m, targets_m, improved.visit_s_m,
                            f"auto ({best.planner} + improvement)", dict(self.parameters), report)
        return Tour(best.chain, best.rho_m, best.targets_m, best.visit_s_m,
                    f"auto ({best.planner})", dict(self.parameters), report)
