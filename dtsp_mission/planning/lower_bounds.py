"""Lower bounds on the length of the shortest Dubins tour, for reporting ratios.

* The **stochastic** bound ``(3/4) (3 rho A)^(1/3) n^(2/3)`` (Enright & Frazzoli; Theorem 2.1 of
  the RBTA paper) holds asymptotically, in expectation, for targets uniform in a region of area
  ``A``.  It is not a bound for a particular instance.
* The **1-tree** bound is certified for the instance: every Dubins tour is at least as long as
  the shortest Euclidean tour through the same points, which is at least as long as any minimum
  1-tree.  The Euclidean minimum spanning tree is computed on the Delaunay triangulation (which
  contains it), the special node is the MST leaf that adds the most.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import minimum_spanning_tree
from scipy.spatial import Delaunay, QhullError, cKDTree


@dataclass(frozen=True)
class LowerBound:
    value_m: float
    kind: str          # "stochastic (asymptotic, uniform targets)" or "1-tree (certified)"
    stochastic_m: float
    one_tree_m: float


def stochastic_lower_bound(n: int, rho_m: float, area_m2: float) -> float:
    """(3/4) (3 rho A)^(1/3) n^(2/3): asymptotic expected lower bound for uniform targets."""
    return 0.75 * (3.0 * rho_m * area_m2) ** (1.0 / 3.0) * n ** (2.0 / 3.0)


def one_tree_lower_bound(points_m: np.ndarray) -> float:
    """A minimum 1-tree of the points: a certified lower bound on any closed tour through them."""
    points = np.unique(np.asarray(points_m, dtype=float), axis=0)
    n = len(points)
    if n < 2:
        return 0.0
    if n == 2:
        return 2.0 * float(np.hypot(*(points[1] - points[0])))
    try:
        simplices = Delaunay(points).simplices
        edges = np.vstack([simplices[:, [0, 1]], simplices[:, [1, 2]], simplices[:, [0, 2]]])
    except QhullError:
        # Collinear points: the tour goes out and back along the line.
        direction = points[-1] - points[0]
        along = points @ direction
        return 2.0 * float(np.ptp(along) / np.hypot(*direction))
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    weights = np.hypot(*(points[edges[:, 0]] - points[edges[:, 1]]).T)
    tree = minimum_spanning_tree(coo_matrix((weights, (edges[:, 0], edges[:, 1])), shape=(n, n))).tocoo()
    mst = float(tree.data.sum())
    degree = np.bincount(np.concatenate([tree.row, tree.col]), minlength=n)
    leaf_edge = np.zeros(n)
    np.add.at(leaf_edge, tree.row, tree.data)
    np.add.at(leaf_edge, tree.col, tree.data)
    distances, _ = cKDTree(points).query(points, k=3)
    leaves = degree == 1
    # Removing leaf v: MST(V - v) = MST - its edge; the 1-tree adds v's two shortest edges.
    extra = distances[leaves, 1] + distances[leaves, 2] - leaf_edge[leaves]
    return mst + float(max(extra.max(), 0.0))


def lower_bound(targets_m: np.ndarray, rho_m: float, area_m2: float) -> LowerBound:
    """The larger of the two bounds, and which one it was."""
    stochastic = stochastic_lower_bound(len(targets_m), rho_m, area_m2)
    one_tree = one_tree_lower_bound(targets_m)
    if stochastic >= one_tree:
        return LowerBound(stochastic, "stochastic (asymptotic, uniform targets)", stochastic, one_tree)
    return LowerBound(one_tree, "1-tree (certified)", stochastic, one_tree)
