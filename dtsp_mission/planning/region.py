"""The rectangle a planner works in, and how to get one from the targets.

A region is a rectangle given by its lower-left corner, its size and the direction of its width
(the sweep heading).  Planners that tile work in the rectangle's own frame
(:meth:`Region.to_local`) and map the tour back (:meth:`Region.from_local_chain`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from ..errors import InputError
from ..segments import SegmentChain

#: Sides shorter than this (metres) are widened, so collinear or single targets still span an area.
MIN_SIDE_M = 1.0


@dataclass(frozen=True)
class Region:
    """Rectangle: corner ``(x_m, y_m)``, ``width_m`` along ``heading_rad``, ``height_m`` to its left."""

    x_m: float
    y_m: float
    width_m: float
    height_m: float
    heading_rad: float = 0.0

    def __post_init__(self) -> None:
        values = [self.x_m, self.y_m, self.width_m, self.height_m, self.heading_rad]
        if not np.isfinite(values).all() or self.width_m <= 0 or self.height_m <= 0:
            raise InputError(f"a region needs finite corner and positive size, got {self}")

    @property
    def area_m2(self) -> float:
        return self.width_m * self.height_m

    def moved(self, offset_m: np.ndarray) -> "Region":
        """The same rectangle translated by ``offset_m`` (x, y)."""
        return Region(self.x_m + float(offset_m[0]), self.y_m + float(offset_m[1]), self.width_m,
                      self.height_m, self.heading_rad)

    def to_local(self, points_m: np.ndarray) -> np.ndarray:
        """Points in the rectangle's frame (corner at the origin, width along +x)."""
        c, s = np.cos(self.heading_rad), np.sin(self.heading_rad)
        d = np.asarray(points_m, dtype=float) - [self.x_m, self.y_m]
        return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])

    def from_local_chain(self, chain: SegmentChain) -> SegmentChain:
        """A chain planned in the rectangle's frame, moved back to the plane."""
        c, s = np.cos(self.heading_rad), np.sin(self.heading_rad)
        starts = chain.starts.copy()
        starts[:, 0] = self.x_m + c * chain.starts[:, 0] - s * chain.starts[:, 1]
        starts[:, 1] = self.y_m + s * chain.starts[:, 0] + c * chain.starts[:, 1]
        starts[:, 2] = chain.starts[:, 2] + self.heading_rad
        return SegmentChain(starts, chain.lengths_m, chain.curvatures_1_m)


def bounding_region(targets_m: np.ndarray, heading_rad: float = 0.0) -> Region:
    """The smallest rectangle with its width along ``heading_rad`` holding every target."""
    c, s = np.cos(heading_rad), np.sin(heading_rad)
    along = targets_m @ [c, s]
    across = targets_m @ [-s, c]
    width = max(float(np.ptp(along)), MIN_SIDE_M)
    height = max(float(np.ptp(across)), MIN_SIDE_M)
    u0 = float(along.min()) - 0.5 * (width - np.ptp(along))
    v0 = float(across.min()) - 0.5 * (height - np.ptp(across))
    return Region(c * u0 - s * v0, s * u0 + c * v0, width, height, heading_rad)


def minimum_area_region(targets_m: np.ndarray) -> Region:
    """The minimum-area enclosing rectangle (its width along its longer side): one side lies
    on an edge of the convex hull (Freeman & Shapira 1975), so every hull edge is tried."""
    try:
        hull = targets_m[ConvexHull(targets_m).vertices]
    except (QhullError, ValueError):
        return bounding_region(targets_m)   # collinear or too few points
    edges = np.diff(np.vstack([hull, hull[:1]]), axis=0)
    angles = np.mod(np.arctan2(edges[:, 1], edges[:, 0]), np.pi / 2)
    best = min((bounding_region(hull, a) for a in np.unique(angles)), key=lambda r: r.area_m2)
    if best.height_m > best.width_m:
        best = bounding_region(targets_m, best.heading_rad + np.pi / 2)
    return bounding_region(targets_m, best.heading_rad)
