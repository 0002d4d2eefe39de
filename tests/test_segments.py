"""Exact segments: integration, location by arc length, sampling."""

import math

import numpy as np
import pytest

from dtsp_mission.segments import SegmentChain, advance, wrap_angle


def test_advance_on_a_full_circle_returns_home():
    start = np.array([1.0, 2.0, 0.3])
    end = advance(start, 2 * math.pi * 5.0, 1 / 5.0)
    assert np.allclose(end[:2], start[:2], atol=1e-12)
    assert wrap_angle(end[2] - start[2]) == pytest.approx(0.0, abs=1e-12)


def test_advance_is_continuous_as_curvature_vanishes():
    start = np.array([0.0, 0.0, 0.2])
    line = advance(start, 10.0, 0.0)
    for curvature in (1e-6, 1e-10, -1e-10):
        assert np.allclose(advance(start, 10.0, curvature), line, atol=1e-4)


def test_quarter_arc_exact():
    end = advance(np.zeros(3), math.pi / 2 * 3.0, -1 / 3.0)   # right quarter turn, radius 3
    assert np.allclose(end, [3.0, -3.0, -math.pi / 2], atol=1e-14)


def test_pose_at_and_sample_cover_the_chain():
    chain = SegmentChain(np.array([[0, 0, 0], [5, 0, 0.0]]), np.array([5.0, math.pi]),
                         np.array([0.0, 1.0]))
    assert chain.length_m == pytest.approx(5 + math.pi)
    assert np.allclose(chain.pose_at(2.5), [2.5, 0, 0])
    assert np.allclose(chain.pose_at(5 + math.pi), [5, 2, math.pi], atol=1e-12)
    samples = chain.sample(0.1)
    steps = np.hypot(*np.diff(samples[:, :2], axis=0).T)
    assert steps.max() <= 0.1 + 1e-12
    assert np.allclose(samples[-1], chain.ends()[-1])


def test_wrap_angle_range():
    values = np.array([-3 * math.pi, -math.pi, 0.0, math.pi, 3 * math.pi, 7.0])
    wrapped = wrap_angle(values)
    assert ((wrapped > -math.pi) & (wrapped <= math.pi)).all()
    assert np.allclose(np.cos(wrapped), np.cos(values)) and np.allclose(np.sin(wrapped), np.sin(values))


def test_between_cuts_exact_pieces_that_join_up():
    chain = SegmentChain(np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]]),
                         np.array([10.0, 5 * np.pi]), np.array([0.0, 0.2]))
    total = chain.length_m
    for start, end in [(0.0, total), (3.0, 8.0), (3.0, 12.0), (10.0, total), (12.5, 14.0)]:
        piece = chain.between(start, end)
        assert piece.length_m == pytest.approx(end - start, abs=1e-12)
        assert np.allclose(piece.starts[0], chain.pose_at(start))
        assert np.allclose(piece.ends()[-1], chain.pose_at(end))
        inside = np.linspace(0, end - start, 7)
        assert np.allclose(piece.pose_at(inside), chain.pose_at(start + inside))
    assert len(chain.between(5.0, 5.0)) == 0
