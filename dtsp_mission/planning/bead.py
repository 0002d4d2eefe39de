"""The bead B_rho(l) of Savla, Frazzoli & Bullo, and the exact path through a target in it.

Reconstruction (shared/notes/rbta-geometry.md; the paper's Figure 1 is missing): with tips
``p- = (-l, 0)`` and ``p+ = (l, 0)`` and ``alpha = asin(l / 2 rho)``, the upper boundary is the
feasible path left arc / right arc / left arc of radius ``rho`` turning by alpha, 2 alpha, alpha,
with apex height ``h = 2 rho (1 - cos alpha)``; the lower boundary is its mirror image.  Then

* (P1) thickness ``w(l) = 2 h = 4 rho (1 - sqrt(1 - l^2 / 4 rho^2))``;
* (P2) area ``l w(l)`` (the beads tile the plane in staggered rows, one per ``2 l h``);
* (P3) every point of the bead lies on the same three-arc "S-curve" for some radius
  ``R >= rho``; that curve joins p- to p+ (heading 0 at both), stays in the bead, and has length
  ``4 R asin(l / 2R) <= 4 rho asin(l / 2 rho)``.

All functions are vectorised over points and work in the bead's own frame (tips on the x axis).
"""

from __future__ import annotations

import numpy as np

from ..segments import SegmentChain

#: Points this close (in rho) to a bead's boundary belong to the bead (rounding).
BOUNDARY_SLACK_RHO = 1e-12
#: Radii beyond this many rho are treated as a straight line (height below 1e-12 l^2 / rho).
STRAIGHT_RADIUS_RHO = 1e12
_BISECTION_STEPS = 200


def _check(l_m: float, rho_m: float) -> None:
    if not 0.0 < l_m <= 2.0 * rho_m:
        raise ValueError(f"a bead needs 0 < l <= 2 rho (got l = {l_m}, rho = {rho_m})")


def half_angle(l_m: float, radius_m: np.ndarray | float) -> np.ndarray | float:
    """alpha = asin(l / 2R): the turn of the first arc of the S-curve of radius R."""
    return np.arcsin(np.minimum(l_m / (2.0 * np.asarray(radius_m, dtype=float)), 1.0))


def apex_height(l_m: float, radius_m: np.ndarray | float) -> np.ndarray | float:
    """h = 2 R (1 - cos alpha) = 4 R sin^2(alpha / 2): height of the S-curve's apex."""
    return 4.0 * radius_m * np.sin(0.5 * half_angle(l_m, radius_m)) ** 2


def thickness(l_m: float, rho_m: float) -> float:
    """(P1): w(l) = 4 rho (1 - sqrt(1 - l^2 / (4 rho^2)))."""
    _check(l_m, rho_m)
    return float(2.0 * apex_height(l_m, rho_m))


def area(l_m: float, rho_m: float) -> float:
    """(P2): Area[B_rho(l)] = l w(l)."""
    return l_m * thickness(l_m, rho_m)


def path_length_bound(l_m: float, rho_m: float) -> float:
    """(P3): 4 rho asin(l / 2 rho), the length of the boundary path."""
    _check(l_m, rho_m)
    return float(4.0 * rho_m * half_angle(l_m, rho_m))


def curve_height(x_m: np.ndarray, l_m: float, radius_m: np.ndarray | float) -> np.ndarray:
    """Height above the axis of the upper S-curve of radius R at abscissa x (``|x| <= l``),
    in a cancellation-free form."""
    x = np.abs(np.asarray(x_m, dtype=float))
    radius = np.asarray(radius_m, dtype=float)
    h = apex_height(l_m, radius)
    middle = h - x * x / (radius + np.sqrt(np.maximum(radius * radius - x * x, 0.0)))
    u = np.maximum(l_m - x, 0.0)
    outer = u * u / (radius + np.sqrt(np.maximum(radius * radius - u * u, 0.0)))
    return np.where(x <= 0.5 * l_m, middle, outer)


def contains(points_m: np.ndarray, l_m: float, rho_m: float) -> np.ndarray:
    """Whether each point (bead frame, shape (..., 2)) lies in the closed bead B_rho(l), with a
    slack of :data:`BOUNDARY_SLACK_RHO` rho for points on the boundary (rounding of integrated
    paths)."""
    _check(l_m, rho_m)
    points = np.asarray(points_m, dtype=float)
    x, y = points[..., 0], points[..., 1]
    slack = BOUNDARY_SLACK_RHO * rho_m
    inside_x = np.abs(x) <= l_m + slack
    height = curve_height(np.clip(x, -l_m, l_m), l_m, rho_m)
    return inside_x & (np.abs(y) <= height + slack)


def boundary(l_m: float, rho_m: float) -> SegmentChain:
    """The bead's boundary: the upper S-curve of radius rho from p- to p+, then the lower one
    flown back from p+ to p- (closed; not C1 at the tips, where the two halves meet)."""
    _check(l_m, rho_m)
    starts, lengths, curvatures, _ = s_curve_arrays(np.array([[0.0, 1.0], [0.0, -1.0]]), l_m,
                                                    np.array([rho_m, rho_m]))
    upper = SegmentChain(starts[0], lengths[0], curvatures[0])
    lower = SegmentChain(starts[1], lengths[1], curvatures[1])
    back = SegmentChain(lower.ends()[::-1] + [0.0, 0.0, np.pi], lower.lengths_m[::-1],
                        -lower.curvatures_1_m[::-1])
    return SegmentChain.concatenate([upper, back])


def radius_through(points_m: np.ndarray, l_m: float, rho_m: float) -> np.ndarray:
    """The radius R >= rho of the S-curve through each point of the bead (bead frame), found
    by bisection on log R; ``inf`` for points on the axis (the straight line)."""
    points = np.asarray(points_m, dtype=float).reshape(-1, 2)
    x = np.clip(points[:, 0], -l_m, l_m)
    target = np.abs(points[:, 1])
    low = np.full(len(points), np.log(rho_m))
    high = np.full(len(points), np.log(rho_m * STRAIGHT_RADIUS_RHO))
    straight = target <= curve_height(x, l_m, np.exp(high))
    for _ in range(_BISECTION_STEPS):
        middle = 0.5 * (low + high)
        above = curve_height(x, l_m, np.exp(middle)) > target   # curve too high: R too small
        low = np.where(above, middle, low)
        high = np.where(above, high, middle)
        if np.all(high - low < 1e-15):
            break
    radius = np.maximum(np.exp(low), rho_m)     # exp(log rho) may round below rho
    return np.where(straight, np.inf, radius)


def s_curve_arrays(points_m: np.ndarray, l_m: float, radii_m: np.ndarray):
    """The S-curves from p- (heading 0) to p+ (heading 0) with the given radii, each bending to
    the side of its point (upper for y >= 0), and where each point lies on its curve.

    Returns ``(starts (m, 3, 3), lengths (m, 3), curvatures (m, 3), s_m (m,))``, bead frame;
    a straight curve (infinite radius) is one line of length 2l followed by two empty arcs.
    """
    points = np.asarray(points_m, dtype=float).reshape(-1, 2)
    radii = np.asarray(radii_m, dtype=float)
    count = len(points)
    straight = ~np.isfinite(radii)
    radius = np.where(straight, 1.0, radii)
    side = np.where(points[:, 1] >= 0, 1.0, -1.0)
    alpha = np.where(straight, 0.0, half_angle(l_m, radius))
    rise = radius * (1.0 - np.cos(alpha))
    starts = np.empty((count, 3, 3))
    starts[:, 0] = np.column_stack([np.full(count, -l_m), np.zeros(count), np.zeros(count)])
    starts[:, 1] = np.column_stack([np.full(count, -0.5 * l_m), side * rise, side * alpha])
    starts[:, 2] = np.column_stack([np.full(count, 0.5 * l_m), side * rise, -side * alpha])
    lengths = radius[:, None] * alpha[:, None] * np.array([1.0, 2.0, 1.0])
    curvatures = side[:, None] * np.array([1.0, -1.0, 1.0]) / radius[:, None]
    x = np.clip(points[:, 0], -l_m, l_m)
    arc = radius * alpha
    s = np.where(x <= -0.5 * l_m, radius * np.arcsin(np.clip((x + l_m) / radius, -1, 1)),
                 np.where(x < 0.5 * l_m, 2 * arc + radius * np.arcsin(np.clip(x / radius, -1, 1)),
                          4 * arc - radius * np.arcsin(np.clip((l_m - x) / radius, -1, 1))))
    # A straight "curve": one line from p- to p+, then two empty arcs at p+.
    starts[straight, 1] = [l_m, 0.0, 0.0]
    starts[straight, 2] = [l_m, 0.0, 0.0]
    lengths[straight] = [2.0 * l_m, 0.0, 0.0]
    curvatures[straight] = [0.0, 0.0, 0.0]
    s = np.where(straight, x + l_m, s)
    return starts, lengths, curvatures, s
