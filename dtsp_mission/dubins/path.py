"""Shortest Dubins paths: choosing a path (word + three lengths) is separate from sampling it.

Model and limits (as in OMPL's ``DubinsStateSpace``): a Dubins vehicle moves forward at constant
speed with turn radius at least ``rho``.  The shortest path between two poses is one of six
words of at most three segments (Dubins 1957).  The length is *not* a metric: it is asymmetric
and discontinuous (a goal just behind the start costs a full loop).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..segments import SegmentChain, advance
from . import kernel
from .trig import REDUCTION_LIMIT

WORDS = kernel.WORDS


def check_radius(rho_m: float) -> float:
    """The turn radius as a float, or :class:`InputError` unless it is a positive number."""
    rho = float(rho_m)
    if not np.isfinite(rho) or rho <= 0.0:
        raise InputError(f"turn radius must be a positive number of metres, got {rho_m!r}")
    return rho


def _pose_columns(starts: np.ndarray, goals: np.ndarray) -> tuple[list[np.ndarray], tuple]:
    """The six contiguous 1-D columns (x0, y0, th0, x1, y1, th1) of the broadcast pose pairs,
    and the broadcast shape; headings are reduced modulo 2 pi only when the kernel's range
    reduction could not take them as they are."""
    starts = np.asarray(starts, dtype=float)
    goals = np.asarray(goals, dtype=float)
    if starts.shape[-1:] != (3,) or goals.shape[-1:] != (3,):
        raise InputError("poses must have shape (..., 3): x_m, y_m, heading_rad")
    shape = np.broadcast_shapes(starts.shape, goals.shape)[:-1]
    columns = []
    for poses in (starts, goals):
        flat = np.broadcast_to(poses, shape + (3,)).reshape(-1, 3)
        if not np.isfinite(flat).all():
            raise InputError("poses must be finite numbers (got NaN or infinity)")
        for k in range(3):
            column = np.ascontiguousarray(flat[:, k])
            if k == 2 and column.size and np.abs(column).max() >= REDUCTION_LIMIT:
                column = np.mod(column, 2.0 * np.pi)
            columns.append(column)
    return columns, shape


def shortest_length(starts: np.ndarray, goals: np.ndarray, rho_m: float) -> np.ndarray:
    """Length in metres of the shortest Dubins path from each start pose to each goal pose.

    ``starts`` and ``goals`` have shape ``(..., 3)`` (x_m, y_m, heading_rad) and broadcast
    against each other; the result has the broadcast shape without the last axis.  Exact up to
    floating-point rounding (compared with OMPL to 1e-9 relative in the tests).
    """
    rho = check_radius(rho_m)
    columns, shape = _pose_columns(starts, goals)
    out = np.empty(columns[0].shape[0])
    kernel.batch_lengths(*columns, rho, out)
    return out.reshape(shape)


def shortest_words(starts: np.ndarray, goals: np.ndarray,
                   rho_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Word codes (indices into :data:`WORDS`) and segment lengths (metres, last axis of 3) of
    the shortest paths, for broadcast arrays of poses as in :func:`shortest_length`."""
    rho = check_radius(rho_m)
    columns, shape = _pose_columns(starts, goals)
    count = columns[0].shape[0]
    words = np.empty(count, dtype=np.int8)
    t, p, q = np.empty(count), np.empty(count), np.empty(count)
    kernel.batch_paths(*columns, rho, words, t, p, q)
    return words.reshape(shape), np.stack([t, p, q], axis=-1).reshape(shape + (3,))


def chain_of_paths(starts: np.ndarray, words: np.ndarray, segment_lengths_m: np.ndarray,
                   rho_m: float) -> SegmentChain:
    """The exact segments of Dubins paths given by start poses, word codes and segment
    lengths, path after path (three segments each, empty ones included)."""
    starts = np.asarray(starts, dtype=float).reshape(-1, 3)
    lengths = np.asarray(segment_lengths_m, dtype=float).reshape(-1, 3)
    curvatures = kernel.WORD_TURNS[np.asarray(words).reshape(-1)] / float(rho_m)
    poses = np.empty((len(starts), 3, 3))
    poses[:, 0] = starts
    poses[:, 1] = advance(poses[:, 0], lengths[:, 0], curvatures[:, 0])
    poses[:, 2] = advance(poses[:, 1], lengths[:, 1], curvatures[:, 1])
    return SegmentChain(poses.reshape(-1, 3), lengths.reshape(-1), curvatures.reshape(-1))


@dataclass(frozen=True)
class DubinsPath:
    """One shortest Dubins path: start pose, word, and the lengths of its three segments."""

    start: tuple[float, float, float]
    word: str
    segment_lengths_m: tuple[float, float, float]
    rho_m: float

    @property
    def length_m(self) -> float:
        return float(sum(self.segment_lengths_m))

    def chain(self) -> SegmentChain:
        """The path as three exact segments (some may be empty)."""
        return chain_of_paths(np.array(self.start), np.array([WORDS.index(self.word)]),
                              np.array([self.segment_lengths_m]), self.rho_m)

    def end(self) -> np.ndarray:
        """Pose at the end of the path, by integrating its segments."""
        return self.chain().ends()[-1]

    def sample(self, s_m: np.ndarray | float) -> np.ndarray:
        """Pose(s) at arc length(s) ``s_m`` in ``[0, length_m]`` from the start."""
        return self.chain().pose_at(s_m)


def shortest_path(start: np.ndarray, goal: np.ndarray, rho_m: float) -> DubinsPath:
    """The shortest Dubins path from pose ``start`` to pose ``goal`` (x_m, y_m, heading_rad)."""
    words, lengths = shortest_words(np.asarray(start, dtype=float).reshape(3),
                                    np.asarray(goal, dtype=float).reshape(3), rho_m)
    return DubinsPath(tuple(float(v) for v in np.asarray(start, dtype=float).reshape(3)),
                      WORDS[int(words)], tuple(float(v) for v in lengths), float(rho_m))
