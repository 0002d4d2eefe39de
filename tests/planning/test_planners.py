"""RBTA and the Alternating Algorithm: every tour valid, deterministic, lemma-shaped."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import assert_valid_tour
from dtsp_mission.errors import InputError
from dtsp_mission.planning import TilingUnavailable, get_planner, planners
from dtsp_mission.planning.alternating import alternating_headings
from dtsp_mission.planning.euclidean_tour import (euclidean_tour, improvement_moves_left,
                                                 tour_length)
from dtsp_mission.planning.lower_bounds import (lower_bound, one_tree_lower_bound,
                                                stochastic_lower_bound)
from dtsp_mission.planning.region import bounding_region, minimum_area_region


def uniform(n, seed, side=5000.0):
    return np.random.default_rng(seed).uniform(0, side, (n, 2))


def test_builtin_planners_are_registered_through_entry_points():
    found = planners()
    assert {"rbta", "alternating"} <= set(found)
    with pytest.raises(InputError, match="unknown planner"):
        get_planner("nope")


@pytest.mark.parametrize("n, seed", [(200, 1), (1000, 2), (3000, 3), (20000, 4)])
def test_rbta_tour_is_valid_visits_everything_and_reports_phases(n, seed):
    targets = uniform(n, seed)
    tour = get_planner("rbta").plan(targets, 100.0)
    assert_valid_tour(tour)
    phases = tour.report["phases"]
    assert sum(p["serviced"] for p in phases) + tour.report["leftovers"] == n
    assert len(phases) <= math.floor(math.log2(n)) + 1
    # Phase i serves at most one target per meta-bead of 2^(i-1) beads (2n beads in all).
    for p in phases:
        assert p["serviced"] <= math.ceil(2 * n / 2 ** (p["phase"] - 1)) + 2 * p["passes"] + 4
    assert sum(p["length_m"] for p in phases) + tour.report["leftover_length_m"] == pytest.approx(tour.length_m)


def test_rbta_is_deterministic():
    targets = uniform(2000, 7)
    first = get_planner("rbta").plan(targets, 80.0)
    second = get_planner("rbta").plan(targets.copy(), 80.0)
    assert np.array_equal(first.chain.starts, second.chain.starts)
    assert np.array_equal(first.visit_s_m, second.visit_s_m)


@pytest.mark.parametrize("region", ["bounding", "min-area", "30"])
def test_rbta_on_a_rotated_site_with_each_region_choice(region):
    rng = np.random.default_rng(5)
    local = rng.uniform([0, 0], [4000, 1500], (1500, 2))
    angle = math.radians(35)
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    targets = local @ rotation.T + [1000.0, -300.0]
    tour = get_planner("rbta", region=region).plan(targets, 60.0)
    assert_valid_tour(tour)


def test_rbta_says_when_it_cannot_tile():
    with pytest.raises(TilingUnavailable, match="needs at least"):
        get_planner("rbta").plan(uniform(20, 1), 100.0)


def test_lemma_2_2_leftovers_are_few():
    """Lemma 2.2: O(log n) leftovers w.h.p.; the proof's bound is 24 log2 n."""
    n = 5000
    i_star = math.floor(math.log2(n) - math.log2(math.log2(n)) - math.log2(6))
    for seed in range(5):
        tour = get_planner("rbta").plan(uniform(n, 100 + seed), 100.0)
        after_i_star = n - sum(p["serviced"] for p in tour.report["phases"][:i_star])
        assert after_i_star < 24 * math.log2(n)
        assert tour.report["leftovers"] <= after_i_star


@settings(max_examples=25)
@given(st.lists(st.tuples(st.floats(0, 3000), st.floats(0, 3000)), min_size=150, max_size=400),
       st.floats(20.0, 120.0))
def test_rbta_on_arbitrary_targets_including_clusters_and_duplicates(points, rho):
    targets = np.array(points)
    targets[: len(targets) // 3] = targets[0]           # a heavy duplicate cluster
    try:
        tour = get_planner("rbta").plan(targets, rho)
    except TilingUnavailable:
        return
    assert_valid_tour(tour)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 100, 5000])
def test_alternating_tour_is_valid(n):
    tour = get_planner("alternating").plan(uniform(n, n), 90.0)
    assert_valid_tour(tour)


@settings(max_examples=40)
@given(st.lists(st.tuples(st.floats(-1000, 1000), st.floats(-1000, 1000)), min_size=1, max_size=60),
       st.floats(1.0, 200.0))
def test_alternating_on_degenerate_inputs(points, rho):
    """Duplicates, collinear points, points closer than rho."""
    targets = np.array(points)
    assert_valid_tour(get_planner("alternating").plan(targets, rho))


def test_alternating_rule_flies_odd_edges_straight():
    points = uniform(11, 3)
    headings = alternating_headings(points)
    for i in range(0, 10, 2):
        edge = points[i + 1] - points[i]
        assert headings[i] == headings[i + 1] == pytest.approx(math.atan2(edge[1], edge[0]))


def test_euclidean_tour_is_a_good_permutation():
    points = uniform(3000, 9, side=1.0)
    order = euclidean_tour(points)
    assert np.array_equal(np.sort(order), np.arange(3000))
    length = tour_length(points, order)
    assert length < 1.08 * 0.7124 * math.sqrt(3000)       # measured 1.05-1.07 at this n
    assert length >= one_tree_lower_bound(points)


def test_lower_bounds():
    points = uniform(2000, 11)
    one_tree = one_tree_lower_bound(points)
    assert 0 < one_tree <= tour_length(points, euclidean_tour(points))
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
    assert one_tree_lower_bound(square) == pytest.approx(4.0)
    assert one_tree_lower_bound(np.array([[0, 0], [3, 4.0]])) == pytest.approx(10.0)
    assert one_tree_lower_bound(np.array([[0, 0], [1, 0], [5, 0.0]])) == pytest.approx(10.0)
    assert stochastic_lower_bound(1000, 100.0, 25e6) == pytest.approx(
        0.75 * (3 * 100 * 25e6) ** (1 / 3) * 100.0)
    bound = lower_bound(points, 100.0, 25e6)
    assert bound.value_m == max(bound.stochastic_m, bound.one_tree_m)


def test_regions_contain_the_targets():
    targets = uniform(500, 13) @ np.array([[0.8, -0.6], [0.6, 0.8]])
    for region in (bounding_region(targets), minimum_area_region(targets), bounding_region(targets, 1.0)):
        local = region.to_local(targets)
        assert (local >= -1e-6).all() and (local <= [region.width_m + 1e-6, region.height_m + 1e-6]).all()
    assert minimum_area_region(targets).area_m2 <= bounding_region(targets).area_m2 + 1e-6


@pytest.mark.parametrize("n, duplicates, seed", [(60, 20, 0), (50, 49, 3), (400, 133, 5), (2000, 0, 1)])
def test_euclidean_improvement_ends_by_itself_even_with_duplicates(n, duplicates, seed):
    """Regression: a point listed as its own neighbour made 2-opt cycle forever."""
    points = uniform(n, seed)
    points[:duplicates] = points[0]
    assert improvement_moves_left(points) > 0
    order = euclidean_tour(points)
    assert np.array_equal(np.sort(order), np.arange(n))
