"""``nearest``: nearest neighbour in the Dubins metric, a cheap reference peer.

From the current pose the vehicle flies to the unvisited (target, heading) pair that is nearest
by shortest Dubins length, over ``candidates`` evenly spaced headings per target and the
``neighbours`` unvisited targets nearest in the plane (a k-d tree keeps this ``O(n log n)``
rather than ``O(n^2)``).  It starts at the first target heading along +x and returns to it at
the end.  Deterministic; ties go to the lower index.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..dubins import shortest_length
from ..tour import Tour, tour_through_poses
from .base import Planner
from .region import Region

CANDIDATES = 8
NEIGHBOURS = 12


def nearest_neighbour_visits(points_m: np.ndarray, rho_m: float, candidates: int = CANDIDATES,
                             neighbours: int = NEIGHBOURS) -> tuple[np.ndarray, np.ndarray]:
    """Visiting order and heading at each visit of the Dubins nearest-neighbour tour."""
    n = len(points_m)
    tree = cKDTree(points_m)
    grid = 2.0 * np.pi * np.arange(candidates) / candidates
    visited = np.zeros(n, dtype=bool)
    order = np.empty(n, dtype=np.int64)
    headings = np.empty(n)
    current, heading = 0, 0.0
    for k in range(n):
        order[k], headings[k] = current, heading
        visited[current] = True
        if k == n - 1:
            break
        near = _unvisited_near(tree, points_m[current], visited, neighbours, n)
        goals = np.column_stack([np.repeat(points_m[near], candidates, axis=0),
                                 np.tile(grid, len(near))])
        start = np.array([[points_m[current, 0], points_m[current, 1], heading]])
        best = int(np.argmin(shortest_length(start, goals, rho_m)))
        current, heading = int(near[best // candidates]), float(grid[best % candidates])
    return order, headings


def _unvisited_near(tree: cKDTree, point: np.ndarray, visited: np.ndarray, k: int,
                    n: int) -> np.ndarray:
    """Up to ``k`` unvisited targets nearest ``point`` (at least one while any is left)."""
    while True:
        count = min(k, n)
        _, index = tree.query(point, k=count)
        index = np.atleast_1d(index)
        free = index[~visited[index]]
        if len(free) or count == n:
            return np.sort(free[:k]) if len(free) else np.flatnonzero(~visited)[:1]
        k *= 4


class NearestPlanner(Planner):
    """Nearest neighbour in the Dubins metric (reference peer, not part of ``auto``).

    Parameters: ``candidates`` headings per target (default 8), ``neighbours`` examined per
    step (default 12).
    """

    name = "nearest"
    description = "nearest neighbour in the Dubins metric (cheap reference)"

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        order, headings = nearest_neighbour_visits(
            targets_m, rho_m, int(self.parameters.get("candidates", CANDIDATES)),
            int(self.parameters.get("neighbours", NEIGHBOURS)))
        return tour_through_poses(targets_m, order, headings, rho_m, self.name, self.parameters)
