"""The one checker every tour must pass, whatever planner produced it.

A tour is valid when (all measured, none assumed):

* every segment has a finite start pose, a finite non-negative length, and a curvature of
  magnitude at most ``1 / rho`` (relative slack 1e-12);
* it is C1-continuous and closed: the end pose of every segment, integrated exactly, meets the
  start pose of the next one (the last meets the first) within ``tolerance_rho * rho`` in
  position and ``tolerance_rho`` radians in heading;
* every target has a visit whose arc length lies on the tour and whose pose there is within
  ``tolerance_rho * rho`` of the target;
* the invariants no rounding can fake: a closed tour is at least one full circle long
  (``2 pi rho``: no closed curve of curvature at most ``1 / rho`` is shorter) and turns a whole
  number of times in total, and no part of the path between two consecutive visits is shorter
  than the exact Dubins distance between their visit poses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dubins import shortest_length
from ..errors import TourInvalidError
from ..segments import SegmentChain, wrap_angle
from .model import Tour

#: The project-wide tolerance, in turn radii (positions) and radians (headings).
TOLERANCE_RHO = 1e-6
_CURVATURE_SLACK = 1e-12


@dataclass(frozen=True)
class CheckReport:
    """What the checker measured, and the problems it found (empty when the tour is valid)."""

    problems: tuple[str, ...]
    segment_count: int
    target_count: int
    length_m: float
    max_joint_gap_m: float
    max_joint_heading_error_rad: float
    max_curvature_ratio: float      # max |curvature| * rho; <= 1 for a feasible tour
    max_target_miss_m: float

    @property
    def ok(self) -> bool:
        return not self.problems

    def raise_if_invalid(self) -> None:
        """Raise :class:`TourInvalidError` listing the problems, if there are any."""
        if self.problems:
            raise TourInvalidError("tour failed the checker: " + "; ".join(self.problems))

    def summary(self) -> str:
        status = "valid" if self.ok else "INVALID"
        return (f"{status}: {self.segment_count} segments, {self.target_count} targets, "
                f"length {self.length_m:.3f} m, max joint gap {self.max_joint_gap_m:.2e} m, "
                f"max heading jump {self.max_joint_heading_error_rad:.2e} rad, "
                f"max curvature x rho {self.max_curvature_ratio:.12f}, "
                f"max target miss {self.max_target_miss_m:.2e} m")


def _finite_max(values: np.ndarray) -> float:
    return float(np.max(values)) if values.size else 0.0


def check_tour(tour: Tour, tolerance_rho: float = TOLERANCE_RHO) -> CheckReport:
    """Measure ``tour`` against the rules in the module docstring; never raises for a bad tour."""
    return check_path(tour.chain, tour.rho_m, tour.targets_m, tour.visit_s_m, closed=True,
                      tolerance_rho=tolerance_rho)


def check_path(chain: SegmentChain, rho_m: float, targets_m: np.ndarray, visit_s_m: np.ndarray,
               closed: bool, tolerance_rho: float = TOLERANCE_RHO) -> CheckReport:
    """The same rules for any chain of segments; an open path (``closed=False``) need not
    end where it starts."""
    problems: list[str] = []
    rho = float(rho_m)
    if not np.isfinite(rho) or rho <= 0:
        problems.append(f"turn radius {rho!r} is not a positive number")
        rho = float("nan")
    tolerance_m = tolerance_rho * rho

    finite = (np.isfinite(chain.starts).all() and np.isfinite(chain.lengths_m).all()
              and np.isfinite(chain.curvatures_1_m).all())
    if not finite:
        problems.append("a segment has a non-finite pose, length or curvature")
    if (chain.lengths_m < 0).any():
        problems.append(f"{int((chain.lengths_m < 0).sum())} segments have negative length")

    curvature_ratio = np.abs(chain.curvatures_1_m) * rho
    max_curvature_ratio = _finite_max(curvature_ratio)
    too_tight = curvature_ratio > 1.0 + _CURVATURE_SLACK
    if too_tight.any():
        first = int(np.argmax(too_tight))
        problems.append(f"{int(too_tight.sum())} segments turn tighter than rho "
                        f"(first: segment {first}, radius {1 / abs(chain.curvatures_1_m[first]):.6g} m)")

    max_gap = max_heading = 0.0
    if len(chain) == 0:
        if len(targets_m) > 0:
            problems.append("the tour has no segments")
    elif finite:
        ends = chain.ends()
        following = np.roll(chain.starts, -1, axis=0)
        gaps = np.hypot(*(ends[:, :2] - following[:, :2]).T)
        heading_errors = np.abs(wrap_angle(ends[:, 2] - following[:, 2]))
        joints = slice(None) if closed else slice(None, -1)      # an open path's end is free
        max_gap, max_heading = _finite_max(gaps[joints]), _finite_max(heading_errors[joints])
        broken = (gaps > tolerance_m) | (heading_errors > tolerance_rho)
        if broken[:-1].any():
            first = int(np.argmax(broken[:-1]))
            problems.append(f"not C1-continuous at {int(broken[:-1].sum())} joints (first after "
                            f"segment {first}: gap {gaps[first]:.3g} m, heading jump "
                            f"{heading_errors[first]:.3g} rad)")
        if closed and broken[-1]:
            problems.append(f"not closed: the end misses the start by {gaps[-1]:.3g} m and "
                            f"{heading_errors[-1]:.3g} rad")

    max_miss = 0.0
    targets_m = np.asarray(targets_m, dtype=float).reshape(-1, 2)
    visits = np.asarray(visit_s_m, dtype=float).reshape(-1)
    if len(targets_m) and len(chain) and finite:
        on_tour = np.isfinite(visits) & (visits >= -tolerance_m) & (visits <= chain.length_m + tolerance_m)
        if not on_tour.all():
            problems.append(f"{int((~on_tour).sum())} visits lie outside the tour's arc length")
        poses = chain.pose_at(np.clip(np.where(on_tour, visits, 0.0), 0.0, chain.length_m))
        misses = np.hypot(*(poses[:, :2] - targets_m).T)
        misses = np.where(on_tour, misses, np.inf)
        max_miss = _finite_max(misses)
        missed = misses > tolerance_m
        if missed.any():
            first = int(np.argmax(missed))
            problems.append(f"{int(missed.sum())} targets are not on the path (first: target "
                            f"{first}, missed by {misses[first]:.3g} m)")
    if len(chain) and finite and np.isfinite(rho):
        problems.extend(_invariant_problems(chain, rho, tolerance_m, tolerance_rho,
                                            visits if len(targets_m) else np.zeros(0), closed,
                                            max_heading * len(chain)))
    return CheckReport(tuple(problems), len(chain), len(targets_m), chain.length_m,
                       max_gap, max_heading, max_curvature_ratio, max_miss)


def _invariant_problems(chain: SegmentChain, rho: float, tolerance_m: float, tolerance_rad: float,
                        visits: np.ndarray, closed: bool, heading_slack_rad: float) -> list[str]:
    """Violations of the invariants that hold for every feasible path (module docstring)."""
    problems = []
    length = chain.length_m
    if closed and length < 2.0 * np.pi * rho - tolerance_m:
        problems.append(f"a closed path of curvature <= 1/rho is at least 2 pi rho = "
                        f"{2 * np.pi * rho:.6g} m long; this one is {length:.6g} m")
    if closed:
        turning = float(np.sum(chain.curvatures_1_m * chain.lengths_m))
        turns = turning / (2.0 * np.pi)
        off = abs(turns - round(turns)) * 2.0 * np.pi
        if off > max(tolerance_rad, heading_slack_rad) + 1e-12 * len(chain):
            problems.append(f"the total turning is {turns:.9f} turns, not a whole number")
    usable = np.isfinite(visits) & (visits >= 0) & (visits <= length + tolerance_m)
    s = np.sort(np.clip(visits[usable], 0.0, length))
    if len(s) >= 2 or (closed and len(s) == 1):
        poses = chain.pose_at(s)
        following = np.roll(poses, -1, axis=0)
        along = np.diff(s, append=s[0] + length)
        if not closed:
            poses, following, along = poses[:-1], following[:-1], along[:-1]
        shortest = shortest_length(poses, following, rho)
        short = along < shortest - 2.0 * tolerance_m - 1e-9 * shortest
        if short.any():
            first = int(np.argmax(short))
            problems.append(f"{int(short.sum())} legs between consecutive visits are shorter than "
                            f"the exact Dubins distance between their poses (first: visit {first}, "
                            f"{along[first]:.6g} m against {shortest[first]:.6g} m)")
    return problems
