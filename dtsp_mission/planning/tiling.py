"""The periodic bead tiling of a rectangle, and the meta-beads of each RBTA phase.

Frame: the rectangle's own, lower-left corner at the origin, x along its width ``W``.
Row ``k`` has its axis at ``y = k h`` (``h = w / 2``, half the bead thickness); its beads are
centred at ``x = (2 m + (k mod 2)) l``.  The lower boundary of a bead coincides with the upper
boundary of the two beads below it, so every point belongs to exactly one bead (up to its
boundary, a set of measure zero).

Phase ``i`` groups beads into meta-beads of ``a_i`` consecutive beads along a row by ``b_i``
consecutive rows, ``(a, b) = (2^(j-1), 2^(j-1))`` for ``i = 2j - 1`` and ``(2^j, 2^(j-1))`` for
``i = 2j``, so each phase's meta-beads are unions of the previous phase's (the nesting the proof
of Lemma 2.2 uses) and hold ``2^(i-1)`` beads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..errors import InputError
from . import bead


class TilingUnavailable(InputError):
    """Too few targets for the region: the bead would need l > 2 rho (paper: 'n must be large
    enough that l < 2 rho').  Callers fall back to another planner."""


def bead_half_length(area_m2: float, n: int, rho_m: float) -> float:
    """The l with Area[B_rho(l)] = A / (2 n), solved exactly (the paper's bead size)."""
    wanted = area_m2 / (2.0 * n)
    top = 2.0 * rho_m
    largest = bead.area(top, rho_m)             # 8 rho^2 up to rounding: the area is computed
    if wanted > largest * (1.0 + 1e-12):        # the same way here as in the root finder
        minimum_n = int(np.ceil(area_m2 / (2.0 * largest * (1.0 + 1e-12))))
        raise TilingUnavailable(
            f"the bead tiling needs at least {minimum_n} targets for this region and radius "
            f"(area {area_m2:.4g} m^2, rho {rho_m:g} m; {n} given): with fewer, a bead would be "
            f"longer than 4 rho")
    if wanted >= largest:                       # on the boundary: the largest bead
        return top
    return float(brentq(lambda l: bead.area(l, rho_m) - wanted, 1e-300, top,
                        xtol=1e-15 * rho_m, rtol=1e-15, maxiter=500))


def phase_shape(phase: int) -> tuple[int, int]:
    """(beads along a row, rows) of a meta-bead in phase ``phase`` (1-based)."""
    j = (phase + 1) // 2
    if phase % 2:
        return 2 ** (j - 1), 2 ** (j - 1)
    return 2 ** j, 2 ** (j - 1)


@dataclass(frozen=True)
class BeadTiling:
    """Beads of half-length ``l_m`` for radius ``rho_m`` covering ``[0, W] x [0, H]``."""

    l_m: float
    rho_m: float
    width_m: float
    height_m: float

    @classmethod
    def for_region(cls, region, n: int, rho_m: float) -> "BeadTiling":
        """The paper's tiling of ``region`` (a :class:`~.region.Region`) for ``n`` targets:
        beads with Area = A / (2 n); raises :class:`TilingUnavailable` if they would be too long."""
        return cls(bead_half_length(region.area_m2, n, rho_m), rho_m, region.width_m, region.height_m)

    @property
    def row_spacing_m(self) -> float:
        """h: distance between row axes (half the bead thickness)."""
        return 0.5 * bead.thickness(self.l_m, self.rho_m)

    @property
    def row_count(self) -> int:
        """Rows 0..K whose beads meet the rectangle: every row :meth:`bead_of` gives a point of
        the rectangle (both use the same boundary slack)."""
        slack = bead.BOUNDARY_SLACK_RHO * self.rho_m
        return int(np.ceil(max(self.height_m - slack, 0.0) / self.row_spacing_m)) + 1

    def bead_of(self, points_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Row ``k`` and index ``m`` along the row of the bead holding each point."""
        points = np.asarray(points_m, dtype=float).reshape(-1, 2)
        h, l = self.row_spacing_m, self.l_m
        k = np.floor(points[:, 1] / h).astype(np.int64)
        m = np.round((points[:, 0] / l - (k % 2)) / 2.0).astype(np.int64)
        dx = points[:, 0] - (2 * m + (k % 2)) * l
        in_lower = ((points[:, 1] - k * h) <= bead.curve_height(np.clip(dx, -l, l), l, self.rho_m)
                    + bead.BOUNDARY_SLACK_RHO * self.rho_m)
        k_up = k + 1
        m_up = np.round((points[:, 0] / l - (k_up % 2)) / 2.0).astype(np.int64)
        return np.where(in_lower, k, k_up), np.where(in_lower, m, m_up)

    def meta_bead_of(self, rows: np.ndarray, columns: np.ndarray,
                     phase: int) -> tuple[np.ndarray, np.ndarray]:
        """Meta-row and meta-column of beads (row, column) in phase ``phase``."""
        a, b = phase_shape(phase)
        return np.floor_divide(rows, b), np.floor_divide(columns, a)

    def meta_axis_y(self, meta_rows: np.ndarray, phase: int) -> np.ndarray:
        """y of the axis of meta-rows: the middle of their rows' axes."""
        _, b = phase_shape(phase)
        return (np.asarray(meta_rows) * b + 0.5 * (b - 1)) * self.row_spacing_m

    def meta_centre_x(self, meta_rows: np.ndarray, meta_columns: np.ndarray,
                      phase: int) -> np.ndarray:
        """x of the centre of the scaled bead B_rho(a l) of each meta-bead: the middle of its
        beads' extent along the row (odd rows are shifted by l)."""
        a, b = phase_shape(phase)
        shift = (np.asarray(meta_rows) * b) % 2 if b == 1 else 0.5
        return (2.0 * a * np.asarray(meta_columns) + a - 1 + shift) * self.l_m

    def meta_half_length(self, phase: int) -> float:
        """Half-length a l of the scaled bead of a meta-bead (tips at centre -+ a l)."""
        return phase_shape(phase)[0] * self.l_m

    def meta_row_count(self, phase: int) -> int:
        return -(-self.row_count // phase_shape(phase)[1])
