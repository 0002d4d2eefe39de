"""Bead B_rho(l): properties (P1)-(P3) on thousands of random points, l / rho in [0.01, 2]."""

import math

import numpy as np
import pytest

from dtsp_mission.planning import bead
from dtsp_mission.segments import SegmentChain

RATIOS = [0.01, 0.05, 0.2, 0.5, 1.0, 1.5, 1.9, 1.99, 2.0]


@pytest.mark.parametrize("ratio", RATIOS)
def test_thickness_and_area_formulas(ratio):
    rho, l = 3.0, ratio * 3.0
    assert bead.thickness(l, rho) == pytest.approx(4 * rho * (1 - math.sqrt(1 - l * l / (4 * rho * rho))),
                                                   rel=1e-12)
    boundary = bead.boundary(l, rho)
    top = boundary.sample(l / 2000)[:, 1]
    assert top.max() - top.min() == pytest.approx(bead.thickness(l, rho), rel=1e-6)
    # Area by the shoelace formula on the exact boundary, sampled densely: l w(l).
    xy = boundary.sample(l / 5000)[:, :2]
    shoelace = 0.5 * abs(np.dot(xy[:-1, 0], xy[1:, 1]) - np.dot(xy[1:, 0], xy[:-1, 1]))
    assert shoelace == pytest.approx(bead.area(l, rho), rel=1e-5)
    assert boundary.length_m == pytest.approx(2 * bead.path_length_bound(l, rho), rel=1e-12)


@pytest.mark.parametrize("ratio", RATIOS)
def test_path_through_any_point_is_short_inside_and_hits_it(rng, ratio):
    rho = 50.0
    l = ratio * rho
    w = bead.thickness(l, rho)
    candidates = np.column_stack([rng.uniform(-l, l, 6000), rng.uniform(-w / 2, w / 2, 6000)])
    points = candidates[bead.contains(candidates, l, rho)]
    points = np.vstack([points, [[0, 0], [0, w / 2], [0, -w / 2], [-l, 0], [l, 0], [0.3 * l, 0]]])
    assert len(points) > 2000
    radii = bead.radius_through(points, l, rho)
    assert np.all(radii >= rho)
    starts, lengths, curvatures, s = bead.s_curve_arrays(points, l, radii)
    assert np.all(lengths.sum(axis=1) <= bead.path_length_bound(l, rho) * (1 + 1e-12))
    assert np.all(np.abs(curvatures) <= 1 / rho * (1 + 1e-12))
    for i in range(0, len(points), 7):
        chain = SegmentChain(starts[i], lengths[i], curvatures[i])
        ends = chain.ends()
        assert np.allclose(ends[:-1], chain.starts[1:], atol=1e-9 * rho)        # C1
        assert np.allclose(ends[-1], [l, 0, 0], atol=1e-9 * rho)                # reaches p+
        assert np.hypot(*(chain.pose_at(s[i])[:2] - points[i])) <= 1e-9 * rho   # through p
        inside = bead.contains(chain.sample(l / 50)[:, :2], l, rho)             # stays inside
        assert inside.all()


def test_points_outside_are_outside():
    rho, l = 10.0, 8.0
    w = bead.thickness(l, rho)
    assert not bead.contains(np.array([[l * 1.001, 0.0], [0.0, w / 2 * 1.001], [0.9 * l, w / 2]]),
                             l, rho).any()
    with pytest.raises(ValueError):
        bead.thickness(2.1 * rho, rho)
