"""The Dubins-aware improvement stage: never longer, exact bookkeeping, deterministic, checked."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dtsp_mission.bench.instances import instance
from dtsp_mission.dubins import shortest_length
from dtsp_mission.planning import get_planner
from dtsp_mission.planning import improve as im
from dtsp_mission.planning.euclidean_tour import neighbour_lists
from dtsp_mission.tour import check_tour, tour_through_poses

RHO = 100.0


def _start(points):
    base = get_planner("headings").plan(points, RHO)
    order = base.visit_order
    return base, order, base.visit_poses()[order, 2]


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-2e3, 2e3), min_size=6, max_size=6))
def test_a_path_flown_backwards_with_headings_turned_is_as_long(values):
    """The 2-opt move relies on it: a reversed section with every heading turned by pi keeps
    the lengths of its inner legs."""
    x0, y0, t0, x1, y1, t1 = values
    forward = np.array([[x0, y0, t0 / 300]])
    goal = np.array([[x1, y1, t1 / 300]])
    back_start = goal + [0, 0, np.pi]
    back_goal = forward + [0, 0, np.pi]
    assert shortest_length(forward, goal, RHO)[0] == pytest.approx(
        shortest_length(back_start, back_goal, RHO)[0], rel=1e-9, abs=1e-6)


@pytest.mark.parametrize("n", [4, 5, 7, 12, 40])
def test_the_moves_account_for_the_length_they_change_exactly(n):
    """Local search and every kind of perturbation: the length they claim is the length of
    the tour they leave (recomputed leg by leg), and the tour stays a permutation."""
    for seed in range(8):
        rng = np.random.default_rng(seed)
        points = rng.uniform(0, 8, (n, 2))
        tour = rng.permutation(n).astype(np.int64)
        headings = rng.uniform(-np.pi, np.pi, n)
        count = np.zeros(3, dtype=np.int64)
        start = im.tour_length_rho(points, tour, headings, count)
        position = np.empty(n, dtype=np.int64)
        position[tour] = np.arange(n)
        neighbours = neighbour_lists(points, min(im.NEIGHBOURS, n - 1))
        gain = im._descend(points, tour, position, headings, neighbours, np.empty(n, np.int64),
                           np.ones(n, dtype=bool), count, 10**8)
        after = im.tour_length_rho(points, tour, headings, count)
        assert after == pytest.approx(start - gain, abs=1e-7)
        assert np.array_equal(np.sort(tour), np.arange(n))
        assert np.array_equal(position[tour], np.arange(n))
        for kind in range(4):
            best_tour, best_headings = tour.copy(), headings.copy()
            best = np.array([after])
            current = im._search(points, tour, headings, neighbours, seed, 50, 10**6, count, 10**8,
                                 after, best_tour, best_headings, best, np.zeros(2, np.int64),
                                 im.KICK_SECTION, 0.05, kind)
            assert current == pytest.approx(im.tour_length_rho(points, tour, headings, count), abs=1e-6)
            assert best[0] == pytest.approx(
                im.tour_length_rho(points, best_tour, best_headings, count), abs=1e-6)
            assert best[0] <= after + 1e-9
            assert np.array_equal(np.sort(tour), np.arange(n))
            after = im.tour_length_rho(points, tour, headings, count)


def _dubins(points, a, ha, b, hb):
    return im._dist(points, a, ha, b, hb, np.zeros(1, np.int64))


@pytest.mark.parametrize("seed", range(6))
def test_moves_skipped_on_straight_line_bounds_are_never_the_best(seed):
    """The 2-opt and heading searches skip candidates whose new legs, as straight lines,
    already cost more than the best gain so far: what they return is still the best move
    among all their candidates, found here by evaluating every one."""
    rng = np.random.default_rng(seed)
    n = 30
    points = rng.uniform(0, 4, (n, 2))              # radii: close targets, many loops
    tour = rng.permutation(n).astype(np.int64)
    headings = rng.uniform(-np.pi, np.pi, n)
    position = np.empty(n, dtype=np.int64)
    position[tour] = np.arange(n)
    neighbours = neighbour_lists(points, 8)
    succ = lambda v: tour[(position[v] + 1) % n]                                  # noqa: E731
    pred = lambda v: tour[(position[v] - 1) % n]                                  # noqa: E731
    for a in range(n):
        best = 1e-9                                  # the improver's smallest move
        for forward in (True, False):
            b = succ(a) if forward else pred(a)
            for c in neighbours[a]:
                e = succ(c) if forward else pred(c)
                if c in (a, b) or e in (a, b):
                    continue
                if forward:
                    delta = (_dubins(points, a, headings[a], c, headings[c] + np.pi)
                             + _dubins(points, b, headings[b] + np.pi, e, headings[e])
                             - _dubins(points, a, headings[a], b, headings[b])
                             - _dubins(points, c, headings[c], e, headings[e]))
                else:
                    delta = (_dubins(points, e, headings[e], b, headings[b] + np.pi)
                             + _dubins(points, c, headings[c] + np.pi, a, headings[a])
                             - _dubins(points, b, headings[b], a, headings[a])
                             - _dubins(points, e, headings[e], c, headings[c]))
                best = max(best, -delta)
        trial_tour, trial_position, trial_headings = tour.copy(), position.copy(), headings.copy()
        gain, moved = im._try_two_opt(points, trial_tour, trial_position, trial_headings,
                                      neighbours, a, np.zeros(3, np.int64), np.empty(8, np.int64))
        assert gain == pytest.approx(best if best > 1e-9 else 0.0, abs=1e-9)
        assert (moved > 0) == (best > 1e-9)
        # A heading search that gives up on the straight-line bound could not have gained.
        p, s = pred(a), succ(a)
        current = (_dubins(points, p, headings[p], a, headings[a])
                   + _dubins(points, a, headings[a], s, headings[s]))
        gain, moved = im._try_heading(points, tour.copy(), position.copy(), headings.copy(), a,
                                      np.zeros(3, np.int64), np.empty(8, np.int64), im.HEADING_MIN_GAIN)
        if moved == 0:
            grid = np.linspace(-np.pi, np.pi, 721)
            cheapest = min(_dubins(points, p, headings[p], a, h) + _dubins(points, a, h, s, headings[s])
                           for h in grid)
            straight = np.hypot(*(points[a] - points[p])) + np.hypot(*(points[s] - points[a]))
            assert cheapest >= straight - 1e-9
            if current - straight < im.HEADING_MIN_GAIN:
                assert current - cheapest < im.HEADING_MIN_GAIN


def test_more_targets_get_longer_neighbour_lists():
    counts = [im.neighbour_count(n) for n in (4, 400, 1000, 2000, 10_000, 100_000, 10**7)]
    assert counts[:3] == [im.NEIGHBOURS] * 3
    assert counts == sorted(counts) and counts[-1] == im.MAX_NEIGHBOURS
    assert counts[3] > im.NEIGHBOURS


@pytest.mark.parametrize("family,n", [("uniform", 30), ("dense", 40), ("clustered", 40)])
def test_the_improved_tour_is_checked_and_never_longer(family, n):
    points = instance(family, n, 3)
    base, order, headings = _start(points)
    result = im.improve_tour(points, order, headings, RHO, time_limit_s=0.5)
    assert result.length_m <= result.start_m + 1e-6
    assert result.start_m <= base.length_m + 1e-6      # shortest legs between the same poses
    assert result.evaluations <= result.budget + 10**6  # a round finishes its last move
    tour = tour_through_poses(points, result.order, result.headings_rad, RHO)
    assert check_tour(tour).ok
    assert tour.length_m == pytest.approx(result.length_m, abs=1e-6 * RHO)


def test_the_same_input_limit_and_seed_give_the_same_tour():
    points = instance("dense", 30, 1)
    _, order, headings = _start(points)
    first = im.improve_tour(points, order, headings, RHO, time_limit_s=0.3, seed=7)
    second = im.improve_tour(points, order, headings, RHO, time_limit_s=0.3, seed=7)
    assert np.array_equal(first.order, second.order)
    assert np.array_equal(first.headings_rad, second.headings_rad)
    assert first.evaluations == second.evaluations


def test_no_budget_changes_nothing_but_the_legs():
    points = instance("uniform", 20, 2)
    _, order, headings = _start(points)
    result = im.improve_tour(points, order, headings, RHO, time_limit_s=0.0)
    assert result.stopped == "budget" and np.array_equal(result.order, order)
    assert result.length_m == result.start_m


def test_the_default_is_never_longer_than_any_peer_and_shortens_dense_sites():
    points = instance("dense", 60, 0)
    tour = get_planner("auto", time_limit_s=1.0).plan(points, RHO)
    peers = [v for v in tour.report["candidates"].values() if isinstance(v, float)]
    assert tour.length_m <= min(peers) + 1e-6
    # On dense sites the peers loop at almost every target; the improver removes many loops.
    assert tour.length_m < 0.9 * min(peers)
    assert tour.report["improvement"]["length_m"] == pytest.approx(tour.length_m, abs=1e-6 * RHO)
    assert check_tour(tour).ok


def test_the_rbta_stays_exactly_the_papers():
    points = instance("uniform", 400, 0)
    tour = get_planner("rbta").plan(points, RHO)
    assert tour.planner == "rbta" and "improvement" not in tour.report
