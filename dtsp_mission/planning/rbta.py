"""The Recursive Bead-Tiling Algorithm (Savla, Frazzoli & Bullo), exactly as published.

Region: a rectangle ``W x H`` (the targets' bounding rectangle unless given).  Beads have
``Area[B_rho(l)] = W H / (2 n)`` and tile the rectangle in rows parallel to its width
(:mod:`.tiling`).  Phase ``i = 1, 2, ...`` (at most ``floor(log2 n) + 1``) works on meta-beads of
``2^(i-1)`` beads and is a closed tour that

(i) sweeps every (meta-)row, top to bottom, alternating left-to-right and right-to-left, each
    pass spanning the whole width of the region;
(ii) in every meta-bead that still holds an unvisited target, services one of them.

Leftover targets are then visited by the Alternating Algorithm.  The choices the paper leaves
open, made here (docs/algorithms.md):

* each pass flies the meta-row's axis; a meta-bead is entered at the left tip of its scaled bead
  ``B_rho(a l)`` and left at the right tip (mirrored for right-to-left passes);
* the target serviced in a meta-bead is the one nearest the axis;
* inside the scaled bead the path is the exact three-arc S-curve through the target (P3);
  where the block's tips stick out of it, or ``a l > 2 rho`` so that no bead of that size exists,
  the path is the shortest pair of Dubins paths tip -> target -> tip over the target heading
  (72-heading grid, then golden-section refinement) and its true length is what counts;
* U-turns between passes and the joins are shortest Dubins paths;
* every phase starts and ends at the same pose, the region's top-left corner heading along the
  width, so the phases (and the leftover tour) concatenate into one closed tour.
"""

from __future__ import annotations

import math

import numpy as np

from ..dubins import chain_of_paths, shortest_length, shortest_words
from ..errors import InputError
from ..segments import SegmentChain
from ..tour import Tour, tour_through_poses
from ..tour.model import snap_visits
from . import bead
from .alternating import alternating_visits
from .base import Planner
from .region import Region, bounding_region, minimum_area_region
from .tiling import BeadTiling, phase_shape

HEADING_GRID = 72
GOLDEN_STEPS = 40
BLOCK = 7        # segments per block: a connector line + up to six segments of a piece


def _dubins_segments(starts: np.ndarray, goals: np.ndarray, rho: float):
    """Exact segments (as (m, 3, ...) arrays) of the shortest paths between pose pairs."""
    words, lengths = shortest_words(starts, goals, rho)
    chain = chain_of_paths(starts, words, lengths, rho)
    m = len(starts)
    return (chain.starts.reshape(m, 3, 3), chain.lengths_m.reshape(m, 3),
            chain.curvatures_1_m.reshape(m, 3))


def _best_heading(entries: np.ndarray, targets: np.ndarray, exits: np.ndarray, rho: float) -> np.ndarray:
    """Heading at each target minimising Dubins(entry -> target) + Dubins(target -> exit)."""
    def cost(headings: np.ndarray) -> np.ndarray:
        poses = np.concatenate([np.broadcast_to(targets[:, None, :], headings.shape + (2,)),
                                headings[..., None]], axis=-1)
        return (shortest_length(entries[:, None, :], poses, rho)
                + shortest_length(poses, exits[:, None, :], rho))
    grid = np.linspace(0.0, 2.0 * np.pi, HEADING_GRID, endpoint=False)
    values = cost(np.broadcast_to(grid, (len(targets), HEADING_GRID)))
    best = grid[np.argmin(values, axis=1)]
    best_value = values.min(axis=1)
    low, high = best - 2 * np.pi / HEADING_GRID, best + 2 * np.pi / HEADING_GRID
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(GOLDEN_STEPS):
        a = high - ratio * (high - low)
        b = low + ratio * (high - low)
        fa, fb = cost(a[:, None])[:, 0], cost(b[:, None])[:, 0]
        high = np.where(fa < fb, b, high)
        low = np.where(fa < fb, low, a)
    refined = 0.5 * (low + high)
    return np.where(cost(refined[:, None])[:, 0] < best_value, refined, best)


def _pieces(local: np.ndarray, phase: int, tiling: BeadTiling, meta_rows: np.ndarray,
            centre_x: np.ndarray, direction: np.ndarray, rho: float):
    """For each serviced target: the path piece from its meta-bead's entry tip to its exit tip
    (padded to six segments) and the arc length of the target on it."""
    m = len(local)
    half = tiling.meta_half_length(phase)
    axis_y = tiling.meta_axis_y(meta_rows, phase)
    # Target in the frame of its scaled bead, x along the direction of flight.
    u = direction * (local[:, 0] - centre_x)
    v = direction * (local[:, 1] - axis_y)
    in_bead = (np.zeros(m, dtype=bool) if half > 2.0 * rho
               else bead.contains(np.column_stack([u, v]), half, rho))
    starts = np.zeros((m, 6, 3))
    lengths = np.zeros((m, 6))
    curvatures = np.zeros((m, 6))
    s = np.zeros(m)
    pass_heading = np.where(direction > 0, 0.0, np.pi)
    exits = np.column_stack([centre_x + direction * half, axis_y, pass_heading])
    if in_bead.any():
        points = np.column_stack([u[in_bead], v[in_bead]])
        radii = bead.radius_through(points, half, rho)
        st, le, cu, s_in = bead.s_curve_arrays(points, half, radii)
        sign = direction[in_bead][:, None]
        starts[in_bead, :3, 0] = centre_x[in_bead][:, None] + sign * st[:, :, 0]
        starts[in_bead, :3, 1] = axis_y[in_bead][:, None] + sign * st[:, :, 1]
        starts[in_bead, :3, 2] = st[:, :, 2] + pass_heading[in_bead][:, None]
        lengths[in_bead, :3] = le
        curvatures[in_bead, :3] = cu
        starts[in_bead, 3:] = exits[in_bead][:, None, :]
        s[in_bead] = s_in
    general = ~in_bead
    if general.any():
        entries = np.column_stack([centre_x - direction * half, axis_y, pass_heading])[general]
        headings = _best_heading(entries, local[general], exits[general], rho)
        poses = np.column_stack([local[general], headings])
        st1, le1, cu1 = _dubins_segments(entries, poses, rho)
        st2, le2, cu2 = _dubins_segments(poses, exits[general], rho)
        starts[general] = np.concatenate([st1, st2], axis=1)
        lengths[general] = np.concatenate([le1, le2], axis=1)
        curvatures[general] = np.concatenate([cu1, cu2], axis=1)
        s[general] = le1.sum(axis=1)
    return starts, lengths, curvatures, s, in_bead


def _phase(local: np.ndarray, remaining: np.ndarray, tiling: BeadTiling, bead_rows: np.ndarray,
           bead_columns: np.ndarray, phase: int, home: np.ndarray, rho: float):
    """One phase: a closed chain from ``home`` back to it, the targets it services and their
    arc lengths along it, and a report."""
    index = np.flatnonzero(remaining)
    meta_rows, meta_columns = tiling.meta_bead_of(bead_rows[index], bead_columns[index], phase)
    offset = np.abs(local[index, 1] - tiling.meta_axis_y(meta_rows, phase))
    order = np.lexsort((offset, meta_columns, meta_rows))
    first = np.ones(len(order), dtype=bool)
    first[1:] = (np.diff(meta_rows[order]) != 0) | (np.diff(meta_columns[order]) != 0)
    chosen = order[first]
    serviced, meta_rows, meta_columns = index[chosen], meta_rows[chosen], meta_columns[chosen]

    row_count = tiling.meta_row_count(phase)
    pass_of_row = row_count - 1 - np.arange(row_count)         # top meta-row is pass 0
    pass_direction = np.where(np.arange(row_count) % 2 == 0, 1.0, -1.0)   # by pass number
    visit_pass = pass_of_row[meta_rows]
    direction = pass_direction[visit_pass]
    # Sweep order: pass by pass, along the direction of flight within a pass.
    sweep = np.lexsort((direction * meta_columns, visit_pass))
    serviced, meta_rows, meta_columns = serviced[sweep], meta_rows[sweep], meta_columns[sweep]
    visit_pass, direction = visit_pass[sweep], direction[sweep]

    half = tiling.meta_half_length(phase)
    centre_x = tiling.meta_centre_x(meta_rows, meta_columns, phase)
    starts, lengths, curvatures, s_piece, in_bead = _pieces(
        local[serviced], phase, tiling, meta_rows, centre_x, direction, rho)
    entry_x = centre_x - direction * half
    exit_x = centre_x + direction * half

    # Pass extents: the region's width, widened to the tips of the meta-beads serviced on it.
    low_x = np.zeros(row_count)
    high_x = np.full(row_count, tiling.width_m)
    np.minimum.at(low_x, visit_pass, np.minimum(entry_x, exit_x))
    np.maximum.at(high_x, visit_pass, np.maximum(entry_x, exit_x))
    heading = np.where(pass_direction > 0, 0.0, np.pi)
    axis_y = tiling.meta_axis_y(pass_of_row, phase)
    pass_start = np.column_stack([np.where(pass_direction > 0, low_x, high_x), axis_y, heading])
    pass_end = np.column_stack([np.where(pass_direction > 0, high_x, low_x), axis_y, heading])

    # Connector before each piece: along the axis from the previous exit (or the pass start).
    same_pass = np.zeros(len(serviced), dtype=bool)
    same_pass[1:] = visit_pass[1:] == visit_pass[:-1]
    previous_x = np.where(same_pass, np.roll(exit_x, 1), pass_start[visit_pass, 0])
    connector_start = np.column_stack([previous_x, pass_start[visit_pass, 1:]])
    connector_length = np.abs(entry_x - previous_x)

    # After the last piece of each pass: to the pass end, then a U-turn to the next pass start
    # (the last pass returns home instead).
    last_exit = pass_start[:, 0].copy()
    is_last = np.ones(len(serviced), dtype=bool)
    is_last[:-1] = visit_pass[1:] != visit_pass[:-1]
    last_exit[visit_pass[is_last]] = exit_x[is_last]
    following = np.vstack([pass_start[1:], home[None, :]])
    turn_starts, turn_lengths, turn_curvatures = _dubins_segments(pass_end, following, rho)

    blocks = len(serviced) + row_count
    block_starts = np.zeros((blocks, BLOCK, 3))
    block_lengths = np.zeros((blocks, BLOCK))
    block_curvatures = np.zeros((blocks, BLOCK))
    block_starts[:len(serviced), 0] = connector_start
    block_lengths[:len(serviced), 0] = connector_length
    block_starts[:len(serviced), 1:] = starts
    block_lengths[:len(serviced), 1:] = lengths
    block_curvatures[:len(serviced), 1:] = curvatures
    tail = slice(len(serviced), blocks)
    block_starts[tail, 0] = np.column_stack([last_exit, pass_end[:, 1:]])
    block_lengths[tail, 0] = np.abs(pass_end[:, 0] - last_exit)
    block_starts[tail, 1:4] = turn_starts
    block_lengths[tail, 1:4] = turn_lengths
    block_curvatures[tail, 1:4] = turn_curvatures
    block_starts[tail, 4:] = following[:, None, :]
    key = np.concatenate([visit_pass * 2.0, np.arange(row_count) * 2.0 + 1.0])
    block_order = np.argsort(key, kind="stable")

    lead_starts, lead_lengths, lead_curvatures = _dubins_segments(home[None, :], pass_start[:1], rho)
    chain = SegmentChain(
        np.concatenate([lead_starts.reshape(-1, 3), block_starts[block_order].reshape(-1, 3)]),
        np.concatenate([lead_lengths.reshape(-1), block_lengths[block_order].reshape(-1)]),
        np.concatenate([lead_curvatures.reshape(-1), block_curvatures[block_order].reshape(-1)]))
    block_offset = np.concatenate([[0.0], np.cumsum(block_lengths[block_order].sum(axis=1))])
    position = np.empty(blocks, dtype=np.int64)
    position[block_order] = np.arange(blocks)
    visit_s = (lead_lengths.sum() + block_offset[position[:len(serviced)]]
               + connector_length + s_piece)
    report = {"phase": phase, "meta_bead_beads": list(phase_shape(phase)),
              "meta_half_length_m": half, "passes": int(row_count), "serviced": int(len(serviced)),
              "s_curves": int(in_bead.sum()), "tip_or_long_paths": int((~in_bead).sum()),
              "length_m": chain.length_m}
    return chain, serviced, visit_s, report


def region_heading_deg(choice) -> float:
    """A ``region`` parameter that is a sweep heading, in degrees, or :class:`InputError`."""
    try:
        heading = float(choice)
    except (TypeError, ValueError):
        raise InputError(f"region {choice!r} is not 'bounding', 'min-area' or a sweep heading in "
                         "degrees") from None
    if not math.isfinite(heading):
        raise InputError(f"region heading must be a finite number of degrees, got {choice!r}")
    return heading


class RBTAPlanner(Planner):
    """The Recursive Bead-Tiling Algorithm, then the Alternating Algorithm for leftovers.

    Parameters: ``region`` = ``"bounding"`` (default: the targets' axis-aligned bounding
    rectangle), ``"min-area"`` (minimum-area enclosing rectangle) or a sweep heading in degrees
    (a number); an explicit :class:`Region` passed to ``plan`` wins over all of them.
    """

    name = "rbta"
    description = "Recursive Bead-Tiling Algorithm exactly as published (Savla, Frazzoli, Bullo)"

    def region_for(self, targets_m: np.ndarray) -> Region:
        choice = self.parameters.get("region", "bounding")
        if choice == "bounding":
            return bounding_region(targets_m)
        if choice == "min-area":
            return minimum_area_region(targets_m)
        return bounding_region(targets_m, math.radians(region_heading_deg(choice)))

    def _plan(self, targets_m: np.ndarray, rho_m: float, region: Region | None) -> Tour:
        n = len(targets_m)
        region = region or self.region_for(targets_m)
        local = region.to_local(targets_m)
        tiling = BeadTiling.for_region(region, n, rho_m)
        bead_rows, bead_columns = tiling.bead_of(local)
        home = np.array([0.0, region.height_m, 0.0])
        remaining = np.ones(n, dtype=bool)
        visit_s = np.full(n, np.nan)
        chains, reports, offset = [], [], 0.0
        for phase in range(1, int(math.floor(math.log2(n))) + 2):
            if not remaining.any():
                break
            chain, serviced, s, report = _phase(local, remaining, tiling, bead_rows, bead_columns,
                                                phase, home, rho_m)
            remaining[serviced] = False
            visit_s[serviced] = offset + s
            chains.append(chain)
            reports.append(report)
            offset += chain.length_m
        leftovers = np.flatnonzero(remaining)
        leftover_length = 0.0
        if len(leftovers):
            points = np.vstack([home[None, :2], local[leftovers]])
            order, leftover_headings = alternating_visits(local[leftovers])
            headings = np.concatenate([[home[2]], leftover_headings])
            excursion = tour_through_poses(points, np.concatenate([[0], order + 1]), headings, rho_m)
            visit_s[leftovers] = offset + excursion.visit_s_m[1:]
            chains.append(excursion.chain)
            leftover_length = excursion.length_m
        chain = region.from_local_chain(SegmentChain.concatenate(chains))
        parameters = dict(self.parameters)
        parameters.update(bead_half_length_m=tiling.l_m, region=[region.x_m, region.y_m,
                          region.width_m, region.height_m, region.heading_rad])
        report = {"phases": reports, "leftovers": int(len(leftovers)),
                  "leftover_length_m": leftover_length}
        chain = chain.without_empty(1e-12 * rho_m)
        return Tour(chain, rho_m, targets_m, snap_visits(chain, targets_m, visit_s), self.name,
                    parameters, report)
