"""Exact planar path segments: straight lines and circular arcs, and where they lead.

Conventions used throughout the metric core: positions in metres in a local frame whose x axis
points east and y axis north; a heading is the direction of travel in radians, counter-clockwise
from +x.  A segment is its start pose, its length and its signed curvature (``+1/R`` for a left
turn of radius ``R``, ``-1/R`` for a right turn, ``0`` for a line).  A chain of segments is
stored as arrays (structure of arrays), so tours with 10^5 targets stay cheap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * np.pi


def wrap_angle(angle_rad: np.ndarray | float) -> np.ndarray | float:
    """Return the angle(s) folded into ``(-pi, pi]``."""
    wrapped = np.mod(np.asarray(angle_rad) + np.pi, TWO_PI) - np.pi
    wrapped = np.where(wrapped <= -np.pi, wrapped + TWO_PI, wrapped)
    return wrapped if np.ndim(wrapped) else float(wrapped)


def advance(poses: np.ndarray, length_m: np.ndarray | float,
            curvature_1_m: np.ndarray | float) -> np.ndarray:
    """Pose reached after ``length_m`` along a segment of constant curvature from ``poses``.

    ``poses`` has shape ``(..., 3)`` (x_m, y_m, heading_rad); the other arguments broadcast
    against ``poses[..., 0]``.  Exact for lines and arcs alike (chord form, no small-angle
    branch), so it is continuous as the curvature goes to zero.
    """
    poses = np.asarray(poses, dtype=float)
    length_m = np.asarray(length_m, dtype=float)
    curvature_1_m = np.asarray(curvature_1_m, dtype=float)
    x, y, heading = poses[..., 0], poses[..., 1], poses[..., 2]
    half_turn = 0.5 * curvature_1_m * length_m
    chord = length_m * np.sinc(half_turn / np.pi)  # np.sinc(u) = sin(pi u) / (pi u)
    direction = heading + half_turn
    out = np.empty(np.broadcast(x, length_m, curvature_1_m).shape + (3,))
    out[..., 0] = x + chord * np.cos(direction)
    out[..., 1] = y + chord * np.sin(direction)
    out[..., 2] = heading + 2.0 * half_turn
    return out


@dataclass(frozen=True)
class SegmentChain:
    """A sequence of exact segments, each given by its start pose, length and curvature.

    Consecutive segments are meant to join (end pose of one = start pose of the next), but the
    chain itself does not enforce it: the tour checker measures it.
    """

    starts: np.ndarray          # (m, 3) x_m, y_m, heading_rad at each segment start
    lengths_m: np.ndarray       # (m,) >= 0
    curvatures_1_m: np.ndarray  # (m,) signed curvature

    def __post_init__(self) -> None:
        starts = np.ascontiguousarray(self.starts, dtype=float).reshape(-1, 3)
        lengths = np.ascontiguousarray(self.lengths_m, dtype=float).reshape(-1)
        curvatures = np.ascontiguousarray(self.curvatures_1_m, dtype=float).reshape(-1)
        if not (len(starts) == len(lengths) == len(curvatures)):
            raise ValueError("starts, lengths_m and curvatures_1_m must have the same length")
        object.__setattr__(self, "starts", starts)
        object.__setattr__(self, "lengths_m", lengths)
        object.__setattr__(self, "curvatures_1_m", curvatures)

    @classmethod
    def empty(cls) -> "SegmentChain":
        return cls(np.zeros((0, 3)), np.zeros(0), np.zeros(0))

    @classmethod
    def concatenate(cls, chains: list["SegmentChain"]) -> "SegmentChain":
        """The chains one after another, in order."""
        if not chains:
            return cls.empty()
        return cls(np.concatenate([c.starts for c in chains]),
                   np.concatenate([c.lengths_m for c in chains]),
                   np.concatenate([c.curvatures_1_m for c in chains]))

    def __len__(self) -> int:
        return len(self.lengths_m)

    @property
    def length_m(self) -> float:
        """Total length of the chain."""
        return float(np.sum(self.lengths_m))

    @property
    def offsets_m(self) -> np.ndarray:
        """Arc length at the start of each segment, plus the total at the end: shape (m+1,)."""
        return np.concatenate(([0.0], np.cumsum(self.lengths_m)))

    def ends(self) -> np.ndarray:
        """End pose of every segment, shape (m, 3); headings are not wrapped."""
        return advance(self.starts, self.lengths_m, self.curvatures_1_m)

    def without_empty(self, min_length_m: float) -> "SegmentChain":
        """The chain with segments shorter than ``min_length_m`` removed."""
        keep = self.lengths_m >= min_length_m
        return SegmentChain(self.starts[keep], self.lengths_m[keep], self.curvatures_1_m[keep])

    def between(self, start_s_m: float, end_s_m: float) -> "SegmentChain":
        """The part of the chain from arc length ``start_s_m`` to ``end_s_m`` (clipped to
        ``[0, length]``), as exact segments: the first starts at ``pose_at(start_s_m)``, the
        lengths add up to ``end_s_m - start_s_m``.  Empty if ``end_s_m <= start_s_m``."""
        offsets = self.offsets_m
        start = float(np.clip(start_s_m, 0.0, offsets[-1]))
        end = float(np.clip(end_s_m, 0.0, offsets[-1]))
        if len(self) == 0 or end <= start:
            return SegmentChain.empty()
        first = int(np.clip(np.searchsorted(offsets, start, side="right") - 1, 0, len(self) - 1))
        last = int(np.clip(np.searchsorted(offsets, end, side="left") - 1, first, len(self) - 1))
        starts = self.starts[first:last + 1].copy()
        lengths = self.lengths_m[first:last + 1].copy()
        curvatures = self.curvatures_1_m[first:last + 1].copy()
        cut = start - offsets[first]
        starts[0] = advance(starts[0], cut, curvatures[0])
        lengths[0] -= cut
        lengths[-1] = end - max(offsets[last], start)
        return SegmentChain(starts, np.maximum(lengths, 0.0), curvatures)

    def locate(self, s_m: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Segment index and offset within it for arc length(s) ``s_m`` in ``[0, length]``."""
        s_m = np.asarray(s_m, dtype=float)
        offsets = self.offsets_m
        index = np.searchsorted(offsets, s_m, side="right") - 1
        index = np.clip(index, 0, len(self) - 1)
        return index, s_m - offsets[index]

    def pose_at(self, s_m: np.ndarray | float) -> np.ndarray:
        """Pose(s) at arc length(s) ``s_m`` from the start of the chain, shape ``s.shape + (3,)``."""
        index, within = self.locate(s_m)
        return advance(self.starts[index], within, self.curvatures_1_m[index])

    def sample_s(self, max_step_m: float) -> np.ndarray:
        """Arc lengths at most ``max_step_m`` apart along the whole chain, including every
        segment start and the total length, increasing."""
        if len(self) == 0:
            return np.zeros(0)
        pieces = np.maximum(1, np.ceil(self.lengths_m / max_step_m).astype(np.int64))
        segment = np.repeat(np.arange(len(self)), pieces)
        first = np.cumsum(pieces) - pieces
        fraction = (np.arange(len(segment)) - first[segment]) / pieces[segment]
        return np.append(self.offsets_m[segment] + fraction * self.lengths_m[segment],
                         self.length_m)

    def sample(self, max_step_m: float) -> np.ndarray:
        """Poses at :meth:`sample_s` arc lengths, shape (k, 3)."""
        if len(self) == 0:
            return np.zeros((0, 3))
        return self.pose_at(self.sample_s(max_step_m))

    def project(self, index: np.ndarray, points_m: np.ndarray) -> np.ndarray:
        """Arc length within segment ``index[i]`` of the point of that segment nearest to
        ``points_m[i]`` (exact for lines; for arcs, by the angle about the centre)."""
        index = np.asarray(index)
        points = np.asarray(points_m, dtype=float).reshape(-1, 2)
        starts = self.starts[index]
        lengths = self.lengths_m[index]
        curvature = self.curvatures_1_m[index]
        heading = starts[:, 2]
        direction = np.column_stack([np.cos(heading), np.sin(heading)])
        offset = points - starts[:, :2]
        along_line = np.einsum("ij,ij->i", offset, direction)
        turning = curvature != 0
        radius = np.where(turning, 1.0 / np.where(turning, curvature, 1.0), 0.0)   # signed
        centre = starts[:, :2] + radius[:, None] * np.column_stack([-direction[:, 1], direction[:, 0]])
        from_centre = starts[:, :2] - centre
        to_point = points - centre
        angle = np.arctan2(from_centre[:, 0] * to_point[:, 1] - from_centre[:, 1] * to_point[:, 0],
                           np.einsum("ij,ij->i", from_centre, to_point))
        swept = np.mod(np.sign(curvature) * angle, 2.0 * np.pi)
        # Past the end of the arc: the nearer end (start if the gap to a full turn is smaller).
        beyond = swept * np.abs(radius) > lengths
        swept = np.where(beyond & (2.0 * np.pi - swept < swept - lengths / np.maximum(np.abs(radius), 1e-300)),
                         0.0, swept)
        along_arc = swept * np.abs(radius)
        return np.clip(np.where(turning, along_arc, along_line), 0.0, lengths)
