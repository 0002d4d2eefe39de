"""Property tests of the Dubins kernel on random and degenerate inputs (hypothesis)."""

import math

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from dtsp_mission.dubins import shortest_length, shortest_path
from dtsp_mission.segments import wrap_angle

coordinate = st.floats(-50.0, 50.0, allow_nan=False)
heading = st.one_of(st.floats(-20.0, 20.0, allow_nan=False),
                    st.sampled_from([0.0, math.pi, -math.pi, 2 * math.pi, 2 * math.pi - 1e-12,
                                     math.pi / 2, 1e-12]))
pose = st.tuples(coordinate, coordinate, heading).map(np.array)
radius = st.floats(0.05, 20.0)


@given(pose, pose, radius)
def test_length_between_euclidean_and_euclidean_plus_seven_thirds_pi_rho(start, goal, rho):
    length = float(shortest_length(start, goal, rho))
    distance = math.hypot(*(goal[:2] - start[:2]))
    assert length >= distance - 1e-9 * rho
    assert length <= distance + 7 * math.pi / 3 * rho + 1e-9 * rho


@given(pose, pose, radius)
def test_integrated_path_lands_on_the_goal(start, goal, rho):
    end = shortest_path(start, goal, rho).end()
    assert math.hypot(*(end[:2] - goal[:2])) <= 1e-9 * rho + 1e-12 * np.abs(goal[:2]).max()
    assert abs(wrap_angle(end[2] - goal[2])) <= 1e-9


@given(pose, pose, radius, st.floats(0.01, 100.0))
def test_scaling_invariance(start, goal, rho, k):
    scaled = float(shortest_length(start * [k, k, 1], goal * [k, k, 1], k * rho))
    assert math.isclose(scaled, k * float(shortest_length(start, goal, rho)), rel_tol=1e-9,
                        abs_tol=1e-9 * k * rho)


@given(pose, pose, radius)
def test_reversed_path_has_the_same_length(start, goal, rho):
    """Flying a path backwards with headings turned round is a path of the same length."""
    forward = float(shortest_length(start, goal, rho))
    backward = float(shortest_length(goal + [0, 0, math.pi], start + [0, 0, math.pi], rho))
    assume(abs(forward - 2 * math.pi * rho) > 1e-6 * rho)   # full-loop ties may round either way
    assert math.isclose(forward, backward, rel_tol=1e-9, abs_tol=1e-9 * rho)


@given(pose, pose, radius)
def test_batch_equals_single(start, goal, rho):
    batch = shortest_length(np.stack([start, goal]), np.stack([goal, start]), rho)
    assert math.isclose(batch[0], shortest_path(start, goal, rho).length_m, rel_tol=1e-14,
                        abs_tol=1e-14 * rho)
    assert batch[1] == float(shortest_length(goal, start, rho))


@given(pose, radius)
def test_translation_and_rotation_invariance(start, rho):
    goal = start + [3.0 * rho, -1.0 * rho, 2.0]
    base = float(shortest_length(start, goal, rho))
    angle = 0.7
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    moved = [np.concatenate([rotation @ p[:2] + [100.0, -40.0], [p[2] + angle]]) for p in (start, goal)]
    assert math.isclose(float(shortest_length(moved[0], moved[1], rho)), base, rel_tol=1e-9,
                        abs_tol=1e-9 * rho)
