"""``lanes``: parallel lanes across the targets' rectangle, flown so that every turn is a wide one.

This is the bead tiling with its waste removed (docs/algorithms.md, "Beyond the paper"):

* the rectangle (the targets' minimum-area rectangle unless given) is cut into lanes of width
  ``w`` along its longer side; a lane is a row of beads in which *every* target is visited in
  one pass, in order along the lane;
* only lanes that hold targets are flown, and each pass starts at its first target and ends at
  its last (no sweep of empty space);
* lanes are flown in ``s = max(2, ceil(2 rho / w))`` interleaved classes (lanes ``r, r + s,
  r + 2s, ...`` up, the next class down), so consecutive passes are at least ``2 rho`` apart and
  every turn between them is a plain half circle, never the ``7/3 pi rho`` turn to an adjacent
  row;
* the headings at the targets are chosen by dynamic programming over a fan of headings around
  the lane direction plus the directions of the two edges at each target, then refined;
* *repair*: where two targets of a lane are so close, and so far apart across it, that the
  shortest path between them needs a full loop, the one nearer its lane's edge moves to the
  neighbouring lane, and the headings are optimised again (``repair_rounds`` times, keeping the
  shortest tour seen).

The lane width scales as the natural width ``(A^2 / (n^2 rho))^(1/3)``: at that width the lanes'
total length is ``(rho A)^(1/3) n^(2/3)``, the order of the optimal tour.  Several multiples are
tried and the shortest tour is kept.  Deterministic.
"""

from __future__ import annotations

import math

import numpy as np

from ..tour import Tour, tour_through_poses
from .alternating import alternating_headings
from .base import Planner
from .headings import (closed_length_m, edge_directions, headings_over_candidates,
                       leg_lengths_m)
from .region import Region, minimum_area_region

#: Lane widths tried, as multiples of the natural width (A^2 / (n^2 rho))^(1/3); above
#: ``WIDE_UP_TO`` targets only the first (uniform 5 km square, rho 100 m: 0.7 wins up to 2,000
#: targets and is 3 % longer at 5,000, 14 % at 1e4, 46 % at 1e5).
WIDTH_FACTORS = (0.5, 0.7)
WIDE_UP_TO = 20_000
#: Headings per target in the exact stage (a fan around the lane direction plus two edges).
CANDIDATES = 15
#: Widest fan, either side of the lane direction.
MAX_FAN_RAD = math.radians(70.0)
REPAIR_ROUNDS = 2


def natural_lane_width_m(area_m2: float, n: int, rho_m: float) -> float:
    """(A^2 / (n^2 rho))^(1/3): the width at which the lanes' length is (rho A)^(1/3) n^(2/3)."""
    return (area_m2 * area_m2 / (n * n * rho_m)) ** (1.0 / 3.0)


def lane_sequence(lane_count: int, step: int) -> np.ndarray:
    """Lanes in flying order: ``step`` interleaved classes, alternately upwards and downwards,
    so consecutive lanes of one class are ``step`` lanes apart."""
    classes = [np.arange(r, lane_count, step) for r in range(min(step, lane_count))]
    return np.concatenate([c if r % 2 == 0 else c[::-1] for r, c in enumerate(classes)])


def visiting_order(along_m: np.ndarray, lanes: np.ndarray, step: int) -> tuple[np.ndarray, np.ndarray]:
    """Order of the targets (lane after lane as :func:`lane_sequence`, along each lane in the
    direction it is flown) and the direction of each visit: +1 along the lane axis, -1 against."""
    by_along = np.argsort(along_m, kind="stable")
    by_lane = by_along[np.argsort(lanes[by_along], kind="stable")]      # lane-major, along-sorted
    counts = np.bincount(lanes, minlength=int(lanes.max()) + 1)
    starts = np.concatenate([[0], np.cumsum(counts)])
    order, direction = [], []
    flown = 0
    for lane in lane_sequence(len(counts), step):
        members = by_lane[starts[lane]:starts[lane + 1]]
        if len(members) == 0:
            continue
        sign = 1 if flown % 2 == 0 else -1
        order.append(members if sign > 0 else members[::-1])
        direction.append(np.full(len(members), sign))
        flown += 1
    return np.concatenate(order), np.concatenate(direction)


def lane_headings(points_m: np.ndarray, direction: np.ndarray, rho_m: float, fan_rad: float,
                  candidate_count: int = CANDIDATES) -> np.ndarray:
    """Headings (in the lanes' frame) for a closed order: DP over a fan of ``candidate_count - 2``
    headings within +-``fan_rad`` of each visit's lane direction plus its two edge directions."""
    along = np.where(direction > 0, 0.0, np.pi)
    fan = np.linspace(-fan_rad, fan_rad, candidate_count - 2)
    incoming, outgoing = edge_directions(points_m)
    candidates = np.column_stack([along[:, None] + fan[None, :], incoming, outgoing])
    return headings_over_candidates(points_m, candidates, rho_m, fan_rad / (candidate_count - 2), 2)


def looped_edges(points_m: np.ndarray, legs_m: np.ndarray, lanes: np.ndarray,
                 rho_m: float) -> np.ndarray:
    """Indices ``i`` of the edges (visit i -> i + 1) inside one lane whose shortest path
    (``legs_m[i]``, :func:`~.headings.leg_lengths_m`) is at least ``pi rho`` longer than the
    straight line: the ones that need a loop."""
    straight = np.hypot(*(np.roll(points_m, -1, axis=0) - points_m).T)
    same_lane = lanes == np.roll(lanes, -1)
    return np.flatnonzero(same_lane & (legs_m - straight > np.pi * rho_m))


def repaired_lanes(lanes: np.ndarray, across_m: np.ndarray, width_m: float, order: np.ndarray,
                   loops: np.ndarray, lane_count: int) -> np.ndarray:
    """Lanes after moving, for every looped edge, one endpoint across the edge of its lane
    nearest to it: the endpoint nearer its edge, unless that edge is the region's (each
    target moves at most once per round)."""
    new = lanes.copy()
    moved = np.zeros(len(lanes), dtype=bool)
    offset = across_m / width_m - lanes                 # position across its lane, 0..1
    edge_distance = np.minimum(offset, 1.0 - offset)
    destination = lanes + np.where(offset < 0.5, -1, 1)
    movable = (destination >= 0) & (destination < lane_count)
    for i in loops:
        a, b = order[i], order[(i + 1) % len(order)]
        if moved[a] or moved[b]:
            continue
        choices = [t for t in sorted((a, b), key=lambda t: (edge_distance[t], t)) if movable[t]]
        if choices:
            new[choices[0]] = destination[choices[0]]
            moved[choices[0]] = True
    return new


class LanesPlanner(Planner):
    """Interleaved lanes, every target of a lane in one pass, headings by DP, loops repaired.

    Parameters: ``width_m`` (one lane width instead of the multiples of the natural width),
    ``width_factors`` (the multiples tried, default 0.5 and 0.7, 0.5 alone above
    :data:`WIDE_UP_TO` targets), ``candidates`` (K, default
    15), ``repair_rounds`` (default 2).  For measuring what each step gains
    (``benchmarks/bead_steps.py``): ``interleave=False`` flies the lanes in plain order (turns
    to the adjacent lane), ``dp_headings=False`` keeps the Alternating Algorithm's headings.
    """

    name = "lanes"
    description = "interleaved lanes ~(A^2/(n^2 rho))^(1/3) wide, headings by DP, loops repaired"

    def widths_m(self, area_m2: float, n: int, rho_m: float) -> list[float]:
        """The lane widths this planner tries."""
        if "width_m" in self.parameters:
            return [float(self.parameters["width_m"])]
        natural = natural_lane_width_m(area_m2, n, rho_m)
        factors = self.parameters.get("width_factors", WIDTH_FACTORS if n <= WIDE_UP_TO
                                      else WIDTH_FACTORS[:1])
        return [f * natural for f in factors]

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        region = region or minimum_area_region(targets_m)
        local = region.to_local(targets_m)
        options = dict(candidate_count=int(self.parameters.get("candidates", CANDIDATES)),
                       rounds=int(self.parameters.get("repair_rounds", REPAIR_ROUNDS)),
                       interleave=bool(self.parameters.get("interleave", True)),
                       dp_headings=bool(self.parameters.get("dp_headings", True)))
        best: tuple[float, np.ndarray, np.ndarray] | None = None
        tried: dict[str, float] = {}
        for width in self.widths_m(region.area_m2, len(targets_m), rho_m):
            length, order, headings = self._lanes(local, rho_m, width, **options)
            tried[f"{width:.1f}"] = length
            if best is None or length < best[0]:
                best = (length, order, headings)
        assert best is not None
        length, order, headings = best
        alternating = alternating_headings(local[order])
        if closed_length_m(local[order], alternating, rho_m) < length:
            headings = alternating
        tour = tour_through_poses(targets_m, order, headings + region.heading_rad, rho_m,
                                  self.name, self.parameters)
        return Tour(tour.chain, tour.rho_m, tour.targets_m, tour.visit_s_m, tour.planner,
                    tour.parameters, {"lane_width_m": tried})

    @staticmethod
    def _lanes(local: np.ndarray, rho_m: float, width_m: float, candidate_count: int,
               rounds: int, interleave: bool, dp_headings: bool
               ) -> tuple[float, np.ndarray, np.ndarray]:
        """The shortest (length, order, headings) over the repair rounds at one lane width."""
        lane_count = max(1, int(math.ceil(local[:, 1].max() / width_m)))
        lanes = np.clip(np.floor(local[:, 1] / width_m).astype(np.int64), 0, lane_count - 1)
        step = max(2, math.ceil(2.0 * rho_m / width_m)) if interleave else 1
        fan = min(MAX_FAN_RAD, 1.5 * math.sqrt(width_m / rho_m))
        best: tuple[float, np.ndarray, np.ndarray] | None = None
        for round_ in range(rounds + 1):
            order, direction = visiting_order(local[:, 0], lanes, step)
            points = local[order]
            headings = (lane_headings(points, direction, rho_m, fan, candidate_count)
                        if dp_headings else alternating_headings(points))
            legs = leg_lengths_m(points, headings, rho_m)
            length = float(legs.sum())
            if best is None or length < best[0]:
                best = (length, order, headings)
            if round_ == rounds:
                break
            loops = looped_edges(points, legs, lanes[order], rho_m)
            if len(loops) == 0:
                break
            lanes = repaired_lanes(lanes, local[:, 1], width_m, order, loops, lane_count)
        assert best is not None
        return best
