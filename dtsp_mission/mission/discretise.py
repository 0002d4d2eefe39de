"""Where to put waypoints on an exact path: as few as possible, none where it is not needed.

Guarantee: every point of the exact path lies within ``tolerance_m`` of the polyline through
the chosen waypoints, and every forced arc length (the targets) is a waypoint.  On an arc of
radius ``rho`` this gives an angular step close to ``dtheta = 2 acos(1 - e / rho)`` (the chord
error ``e = rho (1 - cos(dtheta / 2))``); lines cost a waypoint only where they end in a turn.

Method: the path is sampled finely enough that the arc between two samples strays at most
``tolerance / 10`` from their chord; then, walking from the start, each waypoint is placed as
far along as the samples in between stay within ``0.9 tolerance`` of the chord to it (never
past a forced point).  The two margins add up to the tolerance, so the guarantee holds for the
continuous path, not only for the samples.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..segments import SegmentChain


@numba.njit(cache=True)
def _farthest_reach(points: np.ndarray, forced: np.ndarray, tolerance: float) -> np.ndarray:
    """Greedy waypoint selection over ordered sample points (see the module docstring)."""
    count = len(points)
    keep = np.zeros(count, dtype=np.bool_)
    keep[0] = True
    keep[count - 1] = True
    anchor = 0
    while anchor < count - 1:
        reach = anchor + 1
        candidate = anchor + 2
        while candidate < count and not forced[candidate - 1]:
            ax, ay = points[anchor, 0], points[anchor, 1]
            dx, dy = points[candidate, 0] - ax, points[candidate, 1] - ay
            squared = dx * dx + dy * dy
            fits = True
            for j in range(anchor + 1, candidate):
                px, py = points[j, 0] - ax, points[j, 1] - ay
                t = 0.0
                if squared > 0.0:
                    t = min(1.0, max(0.0, (px * dx + py * dy) / squared))
                ex, ey = px - t * dx, py - t * dy
                if ex * ex + ey * ey > tolerance * tolerance:
                    fits = False
                    break
            if not fits:
                break
            reach = candidate
            candidate += 1
        keep[reach] = True
        anchor = reach
    return keep


def candidate_s(chain: SegmentChain, arc_step_rad: float, forced_s_m: np.ndarray,
             merge_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Sorted arc lengths: every segment end, arcs every ``arc_step_rad``, and the forced
    ones; samples closer than ``merge_m`` to a forced one are dropped.  Returns the arc
    lengths and which of them are forced."""
    turn = np.abs(chain.curvatures_1_m) * chain.lengths_m
    pieces = np.maximum(1, np.ceil(turn / arc_step_rad).astype(np.int64))
    segment = np.repeat(np.arange(len(chain)), pieces)
    first = np.cumsum(pieces) - pieces
    fraction = (np.arange(len(segment)) - first[segment]) / pieces[segment]
    offsets = chain.offsets_m
    regular = np.append(offsets[segment] + fraction * chain.lengths_m[segment], offsets[-1])
    forced = np.unique(np.asarray(forced_s_m, dtype=float))
    if len(forced):
        nearest = np.searchsorted(forced, regular)
        gap = np.minimum(np.abs(regular - forced[np.clip(nearest, 0, len(forced) - 1)]),
                         np.abs(regular - forced[np.clip(nearest - 1, 0, len(forced) - 1)]))
        regular = regular[gap > merge_m]
    s = np.concatenate([regular, forced])
    is_forced = np.concatenate([np.zeros(len(regular), bool), np.ones(len(forced), bool)])
    ordering = np.argsort(s, kind="stable")
    return s[ordering], is_forced[ordering]


def waypoint_s(chain: SegmentChain, rho_m: float, forced_s_m: np.ndarray,
               tolerance_m: float) -> np.ndarray:
    """Arc lengths of the waypoints for ``tolerance_m`` (see the module docstring); the first
    and last are the path's ends, and every forced arc length is included."""
    fine_step = 2.0 * math.acos(max(-1.0, 1.0 - 0.1 * tolerance_m / rho_m))
    s, forced = candidate_s(chain, min(fine_step, math.pi / 2), forced_s_m, 1e-6 * rho_m)
    points = chain.pose_at(s)[:, :2]
    keep = _farthest_reach(np.ascontiguousarray(points), forced, 0.9 * tolerance_m)
    return s[keep]


def deviation_m(chain: SegmentChain, s_waypoints: np.ndarray, step_m: float) -> float:
    """Largest distance from the exact path (sampled every ``step_m``) to the polyline through
    the waypoints at ``s_waypoints``: a measurement, for tests and reports.

    The path and the polyline run in the same order, so each sample is compared with the
    polyline segment spanning its arc length and both neighbours."""
    dense_s = chain.sample_s(step_m)
    points = chain.pose_at(dense_s)[:, :2]
    vertices = chain.pose_at(s_waypoints)[:, :2]
    span = np.clip(np.searchsorted(s_waypoints, dense_s, side="right") - 1, 0, len(vertices) - 2)
    nearest_distance = np.full(len(points), np.inf)
    for shift in (-1, 0, 1):
        index = np.clip(span + shift, 0, len(vertices) - 2)
        a, b = vertices[index], vertices[index + 1]
        direction = b - a
        squared = np.einsum("ij,ij->i", direction, direction)
        t = np.einsum("ij,ij->i", points - a, direction) / np.where(squared > 0, squared, 1.0)
        nearest = a + np.clip(t, 0.0, 1.0)[:, None] * direction
        nearest_distance = np.minimum(nearest_distance, np.hypot(*(points - nearest).T))
    return float(np.max(nearest_distance))
