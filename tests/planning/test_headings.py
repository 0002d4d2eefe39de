"""Heading optimisation for a fixed order: exact DP, improvement only, valid tours."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import assert_valid_tour
from dtsp_mission.planning import get_planner, planners
from dtsp_mission.planning.alternating import alternating_headings
from dtsp_mission.planning.headings import (_best_cycle, _edge_costs, closed_length_m,
                                            optimise_headings)


def uniform(n, seed, side=5000.0):
    return np.random.default_rng(seed).uniform(0, side, (n, 2))


@pytest.mark.parametrize("seed", range(6))
def test_dynamic_programme_finds_the_best_cycle_over_the_candidates(seed):
    rng = np.random.default_rng(seed)
    n, k = 5, 3
    points = rng.uniform(0, 300, (n, 2))
    candidates = rng.uniform(-np.pi, np.pi, (n, k))
    costs = _edge_costs(points, candidates, 80.0)
    brute = min(sum(costs[i, c[i], c[(i + 1) % n]] for i in range(n))
                for c in itertools.product(range(k), repeat=n))
    choice = _best_cycle(costs)
    assert sum(costs[i, choice[i], choice[(i + 1) % n]] for i in range(n)) == pytest.approx(brute, rel=1e-12)


@pytest.mark.parametrize("n", [2, 3, 11, 200, 2000])
def test_optimised_headings_are_never_longer_than_the_alternating_ones(n):
    points = uniform(n, n, side=1500.0)
    optimised = closed_length_m(points, optimise_headings(points, 90.0), 90.0)
    assert optimised <= closed_length_m(points, alternating_headings(points), 90.0) + 1e-6


@pytest.mark.parametrize("n", [1, 2, 3, 7, 100, 3000])
def test_headings_planner_is_valid_and_beats_alternating(n):
    assert "headings" in planners()
    targets = uniform(n, n)
    tour = get_planner("headings").plan(targets, 100.0)
    assert_valid_tour(tour)
    assert tour.length_m <= get_planner("alternating").plan(targets, 100.0).length_m + 1e-6
    second = get_planner("headings").plan(targets.copy(), 100.0)
    assert np.array_equal(tour.chain.starts, second.chain.starts)


@settings(max_examples=30)
@given(st.lists(st.tuples(st.floats(-1000, 1000), st.floats(-1000, 1000)), min_size=1, max_size=40),
       st.floats(1.0, 200.0))
def test_headings_planner_on_degenerate_inputs(points, rho):
    assert_valid_tour(get_planner("headings").plan(np.array(points), rho))


def test_auto_considers_the_headings_planner():
    tour = get_planner("auto", time_limit_s=0).plan(uniform(300, 1), 100.0)
    candidates = tour.report["candidates"]
    assert {"alternating", "headings", "rbta", "lanes", "nearest"} <= set(candidates)
    # With no improvement budget the best peer's tour is rebuilt from its poses with shortest
    # Dubins legs, never longer.
    assert tour.length_m <= min(v for v in candidates.values() if isinstance(v, float)) + 1e-6
