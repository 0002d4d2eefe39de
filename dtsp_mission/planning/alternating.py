"""The Alternating Algorithm (Savla, Frazzoli & Bullo, "On the point-to-point and traveling
salesperson problems for Dubins' vehicle", ACC 2005; the RBTA paper's reference [9]).

Take a Euclidean tour ``p1 p2 ... pn``.  Fly every odd edge ``p1p2, p3p4, ...`` straight: the
heading at both of its ends is the edge's direction.  Every even edge ``p2p3, ...`` (and the
closing edge) is the shortest Dubins path between those poses.  With ``n`` odd the last point
has no odd edge; it is headed straight at the next point.  Its length is at most the Euclidean
tour plus ``ceil(n / 2)`` times ``7 pi rho / 3`` (the worst Dubins detour).
"""

from __future__ import annotations

import numpy as np

from ..tour import Tour, tour_through_poses
from .base import Planner
from .euclidean_tour import euclidean_tour
from .region import Region


def alternating_headings(points_m: np.ndarray) -> np.ndarray:
    """Heading at each point of an ordered closed tour by the alternating rule."""
    n = len(points_m)
    following = np.roll(points_m, -1, axis=0)
    edge = following - points_m
    direction = np.arctan2(edge[:, 1], edge[:, 0])
    # A zero-length edge has no direction: keep the previous edge's (0 for the first).
    empty = np.hypot(edge[:, 0], edge[:, 1]) == 0
    if empty.any():
        index = np.where(~empty, np.arange(n), 0)
        np.maximum.accumulate(index, out=index)
        direction = np.where(empty & (index == 0) & empty[0], 0.0, direction[index])
    headings = np.empty(n)
    odd_starts = np.arange(0, n - 1, 2)              # edges p1p2, p3p4, ... (0-based starts)
    headings[odd_starts] = direction[odd_starts]
    headings[odd_starts + 1] = direction[odd_starts]
    if n % 2:
        headings[n - 1] = direction[n - 1]
    return headings


def alternating_visits(points_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Visiting order (a strong Euclidean tour) and the alternating rule's heading at each
    visit, in visiting order."""
    order = euclidean_tour(points_m)
    return order, alternating_headings(points_m[order])


class AlternatingPlanner(Planner):
    """Euclidean tour, odd edges straight, even edges Dubins."""

    name = "alternating"
    description = "Alternating Algorithm: Euclidean tour, odd edges flown straight, even edges Dubins"

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        order, headings = alternating_visits(targets_m)
        return tour_through_poses(targets_m, order, headings, rho_m, self.name, self.parameters)
