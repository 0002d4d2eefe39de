"""The tour: a closed chain of exact segments, the targets, and where each target is visited.

A tour is what every planner returns and what the discretiser consumes.  It is plain data: a
:class:`~dtsp_mission.segments.SegmentChain` plus arrays.  Nothing here guarantees that the
geometry is right; :func:`dtsp_mission.tour.check.check_tour` measures that.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..dubins import chain_of_paths, shortest_words
from ..errors import InputError
from ..segments import SegmentChain, advance

#: Segments shorter than this fraction of the turn radius are dropped when chaining paths.
EMPTY_SEGMENT_RHO = 1e-12


@dataclass(frozen=True)
class Tour:
    """A closed Dubins tour through targets.

    ``chain`` starts and ends at the same pose.  ``visit_s_m[i]`` is the arc length, from the
    start of the chain, at which target ``i`` (row ``i`` of ``targets_m``) is visited.
    """

    chain: SegmentChain
    rho_m: float
    targets_m: np.ndarray             # (n, 2)
    visit_s_m: np.ndarray             # (n,)
    planner: str = ""
    parameters: dict[str, Any] = field(default_factory=dict)
    report: dict[str, Any] = field(default_factory=dict)   # what the planner measured
    #: Per target, the straight the tour guarantees just before its visit (metres; None: no
    #: such guarantee), as :func:`dtsp_mission.planning.lead_ins.with_lead_ins` plans them.
    lead_in_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "targets_m", np.asarray(self.targets_m, dtype=float).reshape(-1, 2))
        object.__setattr__(self, "visit_s_m", np.asarray(self.visit_s_m, dtype=float).reshape(-1))
        if len(self.targets_m) != len(self.visit_s_m):
            raise ValueError("one visit arc length per target is required")
        if self.lead_in_m is not None:
            object.__setattr__(self, "lead_in_m", np.asarray(self.lead_in_m, dtype=float).reshape(-1))
            if len(self.lead_in_m) != len(self.targets_m):
                raise ValueError("one lead-in length per target is required")

    @property
    def length_m(self) -> float:
        return self.chain.length_m

    @property
    def visit_order(self) -> np.ndarray:
        """Target indices in the order the tour visits them."""
        return np.argsort(self.visit_s_m, kind="stable")

    def visit_poses(self) -> np.ndarray:
        """Pose of the vehicle at each target's visit, row ``i`` for target ``i``, shape (n, 3)."""
        return self.chain.pose_at(self.visit_s_m)


def snap_visits(chain: SegmentChain, targets_m: np.ndarray, approximate_s_m: np.ndarray) -> np.ndarray:
    """Arc lengths of the targets on ``chain``, consistent with the chain's own cumulative sum.

    Planners know roughly where each target lies (their own running sums, which drift from the
    chain's by rounding over millions of segments); this finds the exact point: the target is
    projected onto the segment its approximate arc length falls in and onto both neighbours,
    and the nearest wins.  Result: ``offsets_m[k] + offset within segment k``.
    """
    targets = np.asarray(targets_m, dtype=float).reshape(-1, 2)
    offsets = chain.offsets_m
    last = len(chain) - 1
    guess = np.clip(np.searchsorted(offsets, approximate_s_m, side="right") - 1, 0, last)
    best_s = np.asarray(approximate_s_m, dtype=float).copy()
    best_miss = np.full(len(targets), np.inf)
    for shift in (0, -1, 1, -2, 2):
        index = np.clip(guess + shift, 0, last)
        within = chain.project(index, targets)
        pose = advance(chain.starts[index], within, chain.curvatures_1_m[index])
        miss = np.hypot(*(pose[:, :2] - targets).T)
        better = miss < best_miss
        best_s = np.where(better, offsets[index] + within, best_s)
        best_miss = np.where(better, miss, best_miss)
    return best_s


def tour_through_poses(targets_m: np.ndarray, order: np.ndarray, headings_rad: np.ndarray,
                       rho_m: float, planner: str = "",
                       parameters: dict[str, Any] | None = None) -> Tour:
    """The closed tour made of shortest Dubins paths between consecutive visit poses.

    Target ``order[k]`` is visited k-th with heading ``headings_rad[k]``; after the last visit
    the tour returns to the first.  Every leg starts exactly at its target's pose, so no
    rounding accumulates along the tour.  The tour always has positive length: when all visit
    poses coincide it is one full circle of radius ``rho_m``.
    """
    targets_m = np.asarray(targets_m, dtype=float).reshape(-1, 2)
    order = np.asarray(order, dtype=np.int64).reshape(-1)
    headings = np.asarray(headings_rad, dtype=float).reshape(-1)
    if len(order) != len(targets_m) or len(headings) != len(order):
        raise InputError("order and headings must have one entry per target")
    if len(order) and not np.array_equal(np.sort(order), np.arange(len(order))):
        raise InputError("order must be a permutation of the target indices")
    poses = np.column_stack([targets_m[order], headings])
    words, lengths = shortest_words(poses, np.roll(poses, -1, axis=0), rho_m)
    chain = chain_of_paths(poses, words, lengths, rho_m)
    leg_start_s = np.concatenate(([0.0], np.cumsum(lengths.sum(axis=1))[:-1]))
    # Dropping empty segments changes no arc length, so the leg offsets stay valid.
    chain = chain.without_empty(EMPTY_SEGMENT_RHO * rho_m)
    if len(chain) == 0 and len(poses):
        # Every visit pose is the same: an aircraft cannot stand still, so the tour is one
        # full left circle of radius rho through that pose.
        chain = SegmentChain(poses[:1], np.array([2.0 * np.pi * rho_m]), np.array([1.0 / rho_m]))
    visit_s = np.empty(len(order))
    visit_s[order] = leg_start_s
    visit_s = snap_visits(chain, targets_m, visit_s)
    return Tour(chain, float(rho_m), targets_m, visit_s, planner, dict(parameters or {}))
