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
from ..tour import Tour, check_tour
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
        tour = self._plan(targets, rho, region)
        check_tour(tour).raise_if_invalid()
        log.info("%s: %d targets, tour %.1f m", self.name, len(targets), tour.length_m)
        return tour

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        raise NotImplementedError
