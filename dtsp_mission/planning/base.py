"""The interface every planner shares, built-in or plugin.

A planner is a small class: a ``name``, its parameters (constructor keywords), and ``plan``.
The public :meth:`Planner.plan` validates the input, calls the one hook a planner overrides
(:meth:`Planner._plan`), and runs the tour checker on the result, so every tour a planner
returns has been verified.
"""

from __future__ import annotations

import logging
from typing import Any, ClassVar

import numpy as np

from ..dubins import check_radius
from ..errors import InputError
from ..segments import SegmentChain
from ..targets.model import cluster_positions
from ..tour import Tour, check_tour
from ..tour.check import TOLERANCE_RHO
from .region import Region

log = logging.getLogger(__name__)


def validate_targets(targets_m: np.ndarray) -> np.ndarray:
    """Targets as a finite (n, 2) float array with n >= 1, or :class:`InputError`."""
    targets = np.asarray(targets_m, dtype=float)
    if targets.ndim != 2 or targets.shape[1] != 2:
        raise InputError(f"targets must be an (n, 2) array of x_m, y_m; got shape {targets.shape}")
    if len(targets) == 0:
        raise InputError("there are no targets to visit")
    if not np.isfinite(targets).all():
        bad = int(np.argmax(~np.isfinite(targets).all(axis=1)))
        raise InputError(f"target {bad} has a coordinate that is not a finite number")
    return targets


#: Targets closer than this many turn radii are one point to the aircraft: they are merged
#: before planning (a tenth of the checker's tolerance, so a merged target stays on the path).
MERGE_RESOLUTION_RHO = 0.1 * TOLERANCE_RHO
#: Double precision must resolve the coordinates this many times finer than the tolerance.
_RESOLUTION_MARGIN = 2.0


def check_resolvable(targets_m: np.ndarray, rho_m: float) -> None:
    """:class:`InputError` unless a tour through ``targets_m`` can be written in double precision
    to the checker's tolerance (``TOLERANCE_RHO * rho``) at these coordinates."""
    magnitude = float(np.max(np.abs(targets_m)))
    spacing = float(np.spacing(magnitude)) * _RESOLUTION_MARGIN
    if spacing > TOLERANCE_RHO * rho_m:
        raise InputError(
            f"coordinates up to {magnitude:.4g} m are too large for a turn radius of {rho_m:g} m: "
            f"double precision resolves them only to {spacing / _RESOLUTION_MARGIN:.2g} m, coarser "
            f"than the {TOLERANCE_RHO:g} rho ({TOLERANCE_RHO * rho_m:.2g} m) a tour is checked to; "
            "give the targets relative to an origin near them")


class Planner:
    """Base class: subclasses set ``name`` and implement :meth:`_plan`."""

    name: ClassVar[str] = ""
    description: ClassVar[str] = ""

    def __init__(self, **parameters: Any) -> None:
        self.parameters = parameters

    def plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None = None) -> Tour:
        """A closed Dubins tour through every target (rows of ``targets_m``, metres) for turn
        radius ``rho_m``, checked: raises :class:`~dtsp_mission.errors.TourInvalidError` rather
        than return a tour that fails the checker."""
        targets = validate_targets(targets_m)
        rho = check_radius(rho_m)
        check_resolvable(targets, rho)
        # Plan around the targets' own centre, on one target per point the aircraft can tell
        # apart; the tour is moved back and given every target once, at the end.
        centre = 0.5 * (targets.min(axis=0) + targets.max(axis=0))
        local = targets - centre
        keep, leader = cluster_positions(local, MERGE_RESOLUTION_RHO * rho)
        planned = self._plan(local[keep], rho, region.moved(-centre) if region else None)
        starts = planned.chain.starts.copy()
        starts[:, :2] += centre
        chain = SegmentChain(starts, planned.chain.lengths_m, planned.chain.curvatures_1_m)
        report = dict(planned.report)
        if len(keep) < len(targets):
            report["merged_targets"] = len(targets) - len(keep)
        tour = Tour(chain, planned.rho_m, targets, planned.visit_s_m[leader], planned.planner,
                    planned.parameters, report)
        check_tour(tour).raise_if_invalid()
        log.info("%s: %d targets, tour %.1f m", self.name, len(targets), tour.length_m)
        return tour

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        raise NotImplementedError
