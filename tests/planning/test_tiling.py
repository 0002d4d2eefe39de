"""The staggered bead tiling: sizes, every point in exactly one bead, nested meta-beads."""

import numpy as np
import pytest

from dtsp_mission.planning import bead
from dtsp_mission.planning.tiling import (BeadTiling, TilingUnavailable, bead_half_length,
                                          phase_shape)


def test_bead_size_solves_the_papers_equation():
    l = bead_half_length(25e6, 1000, 100.0)
    assert bead.area(l, 100.0) == pytest.approx(25e6 / 2000, rel=1e-12)
    with pytest.raises(TilingUnavailable, match="at least 6250000 targets"):
        bead_half_length(25e6, 10, 0.5)


def test_every_point_belongs_to_exactly_one_bead(rng):
    tiling = BeadTiling(30.0, 100.0, 2000.0, 500.0)
    points = np.column_stack([rng.uniform(0, 2000, 50000), rng.uniform(0, 500, 50000)])
    rows, columns = tiling.bead_of(points)
    h, l = tiling.row_spacing_m, tiling.l_m
    local = np.column_stack([points[:, 0] - (2 * columns + rows % 2) * l, points[:, 1] - rows * h])
    assert bead.contains(local, l, 100.0).all()
    # No other nearby bead contains the point (beyond the shared boundary).
    for dk in (-1, 0, 1):
        for dm in (-1, 0, 1):
            if dk == dm == 0:
                continue
            k, m = rows + dk, columns + dm
            other = np.column_stack([points[:, 0] - (2 * m + k % 2) * l, points[:, 1] - k * h])
            shrunk = other * [1.0, 1.0 + 1e-6]
            assert not bead.contains(shrunk, l * (1 - 1e-9), 100.0).any()
    assert rows.min() >= 0 and rows.max() <= tiling.row_count - 1


def test_meta_beads_are_nested_and_hold_two_to_the_phase_minus_one_beads():
    tiling = BeadTiling(30.0, 100.0, 2000.0, 500.0)
    rows, columns = np.meshgrid(np.arange(0, 64), np.arange(0, 64), indexing="ij")
    rows, columns = rows.ravel(), columns.ravel()
    previous = None
    for phase in range(1, 10):
        a, b = phase_shape(phase)
        assert a * b == 2 ** (phase - 1)
        meta = np.column_stack(tiling.meta_bead_of(rows, columns, phase))
        _, counts = np.unique(meta, axis=0, return_counts=True)
        assert (counts == a * b).all()
        if previous is not None:     # each earlier meta-bead lies in one of this phase's
            pairs = np.unique(np.column_stack([previous, meta]), axis=0)
            assert len(np.unique(pairs[:, :2], axis=0)) == len(pairs)
        previous = meta
