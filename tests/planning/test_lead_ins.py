"""Straight lead-ins planned into a tour: valid tours, the straight really there, the order
kept, the least growth over the headings tried, deterministic."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import assert_valid_tour
from dtsp_mission.planning import get_planner
from dtsp_mission.planning.lead_ins import _leg_m, with_lead_ins
from dtsp_mission.tour import tour_through_poses


def _tour(n: int, seed: int, side_m: float = 1500.0, rho_m: float = 80.0):
    points = np.random.default_rng(seed).uniform(0.0, side_m, (n, 2))
    return get_planner("alternating").plan(points, rho_m)


def straight_before_m(tour, target: int, lead_m: float) -> bool:
    """Whether the chain runs straight over the ``lead_m`` just before the target's visit
    (sampled every centimetre-ish, the closed chain wrapping)."""
    chain, s = tour.chain, float(tour.visit_s_m[target])
    q = np.mod(s - lead_m * np.linspace(1e-6, 1.0 - 1e-6, 2001), chain.length_m)
    k = np.clip(np.searchsorted(chain.offsets_m, q, side="right") - 1, 0, len(chain) - 1)
    return bool(np.all(chain.curvatures_1_m[k] == 0.0))


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("lead_m", [40.0, 160.0])
def test_each_chosen_target_is_entered_along_a_straight_of_the_lead_in(seed, lead_m):
    tour = _tour(25, seed)
    chosen = [3, 4, 11, 20]
    led = with_lead_ins(tour, {t: lead_m for t in chosen})
    assert_valid_tour(led)
    for t in chosen:
        assert straight_before_m(led, t, lead_m)
        assert led.lead_in_m[t] == lead_m
    assert np.array_equal(led.visit_order, tour.visit_order)
    assert led.rho_m == tour.rho_m
    # the straights are paid for, but by no more than the worst heading kept as it was
    kept = with_lead_ins(tour, {t: lead_m for t in chosen}, reach=-1)
    assert led.length_m <= kept.length_m + 1e-6
    assert led.length_m >= tour.length_m - 1e-6 or led.length_m > 0


def test_a_lead_in_grows_the_tour_by_the_least_over_the_headings_tried():
    """One target freed alone (reach 0): its heading is the best of the 72 around the circle
    and its old one."""
    tour = _tour(12, 7)
    order = tour.visit_order
    k = 5
    t = int(order[k])
    led = with_lead_ins(tour, {t: 100.0}, reach=0)
    poses = tour.visit_poses()[order]
    before, after = poses[k - 1], poses[k + 1]

    def stretch(heading: float) -> float:
        pose = np.array([*poses[k, :2], heading])
        return float(_leg_m(before, pose, 100.0, tour.rho_m) + _leg_m(pose, after, 0.0, tour.rho_m))
    best = min(stretch(h) for h in np.linspace(0.0, 2.0 * math.pi, 73)[:-1])
    chosen = float(led.visit_poses()[t, 2])
    assert stretch(chosen) <= best + 1e-6
    others = [i for i in range(len(order)) if i not in (k - 1, k, k + 1)]
    assert led.length_m - tour.length_m == pytest.approx(
        stretch(chosen) - float(_leg_m(before, poses[k], 0.0, tour.rho_m)
                                + _leg_m(poses[k], after, 0.0, tour.rho_m)), abs=1e-6)
    assert others


def test_lead_ins_accumulate_and_the_result_is_deterministic():
    tour = _tour(30, 2)
    once = with_lead_ins(tour, {1: 80.0})
    twice = with_lead_ins(once, {2: 120.0, 1: 40.0})
    assert twice.lead_in_m[1] == 80.0 and twice.lead_in_m[2] == 120.0
    assert straight_before_m(twice, 1, 80.0)
    again = with_lead_ins(with_lead_ins(tour, {1: 80.0}), {2: 120.0, 1: 40.0})
    assert np.array_equal(again.chain.starts, twice.chain.starts)
    assert np.array_equal(again.visit_s_m, twice.visit_s_m)


def test_no_lead_in_asked_keeps_the_tour():
    tour = _tour(15, 4)
    same = with_lead_ins(tour, {})
    assert same.length_m == pytest.approx(tour.length_m, abs=1e-6)
    assert not same.lead_in_m.any()


@settings(max_examples=40, deadline=None)
@given(n=st.integers(2, 9), seed=st.integers(0, 10_000), lead=st.floats(1.0, 400.0),
       span=st.sampled_from([0.0, 5.0, 60.0, 800.0]))
def test_random_and_degenerate_sites_give_valid_tours(n, seed, lead, span):
    rng = np.random.default_rng(seed)
    points = rng.uniform(0.0, span, (n, 2)) if span else np.zeros((n, 2)) + rng.uniform(0, 1, (n, 2)) * 1e-3
    headings = rng.uniform(-math.pi, math.pi, n)
    tour = tour_through_poses(points, np.arange(n), headings, 60.0)
    chosen = {int(t): lead for t in rng.choice(n, min(n, 3), replace=False)}
    led = with_lead_ins(tour, chosen)
    assert_valid_tour(led)
    for t in chosen:
        assert straight_before_m(led, t, lead)
