"""``auto``: run every applicable built-in planner and keep the shortest checked tour."""

from __future__ import annotations

import numpy as np

from ..errors import DtspError
from ..tour import Tour
from .alternating import AlternatingPlanner
from .base import Planner
from .headings import HeadingsPlanner
from .lanes import LanesPlanner
from .rbta import RBTAPlanner
from .region import Region
from .tiling import TilingUnavailable


class AutoPlanner(Planner):
    """The shortest of the RBTA (when the targets are numerous enough to tile), the Alternating
    Algorithm, the heading-optimised Euclidean tour and the lanes; ``report["candidates"]`` lists every
    length measured."""

    name = "auto"
    description = "shortest checked tour of the applicable planners (default)"

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        candidates: dict[str, float | str] = {}
        best: Tour | None = None
        failures: list[DtspError] = []
        for planner in (AlternatingPlanner(), HeadingsPlanner(), LanesPlanner(),
                        RBTAPlanner(**self.parameters)):
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
        report = dict(best.report, chosen=best.planner, candidates=candidates)
        return Tour(best.chain, best.rho_m, best.targets_m, best.visit_s_m,
                    f"auto ({best.planner})", dict(self.parameters), report)
