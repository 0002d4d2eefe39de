"""Tours for a steady wind: Dubins paths in the air mass that pass every target over the ground."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from dtsp_mission.dubins import shortest_length
from dtsp_mission.errors import InputError
from dtsp_mission.planning.euclidean_tour import euclidean_tour
from dtsp_mission.planning.wind_tour import (_MAX_STEP_RHO, _air_length, crab_headings,
                                             leg_times_s, plan_wind_tour)

V, RHO = 22.0, 80.0


def _straight(ground_deg: float, wind: tuple[float, float], distance_m: float = 1000.0) -> float:
    g = math.radians(ground_deg)
    heading = crab_headings(np.array([g]), V, wind)[0]
    points = np.array([[0.0, 0.0], distance_m * np.array([math.cos(g), math.sin(g)])])
    return float(leg_times_s(points, np.array([heading, heading]), RHO, V, wind)[0])


def test_a_straight_leg_takes_its_length_over_the_ground_speed():
    """Downwind, upwind and across: the aircraft crabbed into the wind tracks the leg."""
    assert _straight(0.0, (5.0, 0.0)) == pytest.approx(1000.0 / 27.0, rel=1e-12)
    assert _straight(0.0, (-5.0, 0.0)) == pytest.approx(1000.0 / 17.0, rel=1e-12)
    assert _straight(0.0, (0.0, 5.0)) == pytest.approx(1000.0 / math.sqrt(V ** 2 - 25.0), rel=1e-12)
    # A short one (shorter than the turn radius), where a late root would be a whole loop.
    heading = crab_headings(np.array([math.radians(13.0)]), V, (0.0, -5.0))[0]
    ground_speed = np.hypot(V * math.cos(heading), V * math.sin(heading) - 5.0)
    assert _straight(13.0, (0.0, -5.0), 50.0) == pytest.approx(50.0 / ground_speed, rel=1e-12)


def test_in_calm_air_a_leg_takes_its_dubins_length_at_the_airspeed():
    rng = np.random.default_rng(3)
    points = rng.uniform(0, 1500, (12, 2))
    headings = rng.uniform(-math.pi, math.pi, 12)
    poses = np.column_stack([points, headings])
    expected = shortest_length(poses, np.roll(poses, -1, axis=0), RHO) / V
    np.testing.assert_allclose(leg_times_s(points, headings, RHO, V, (0.0, 0.0)), expected,
                               rtol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.floats(-2000, 2000), st.floats(-2000, 2000), st.floats(-math.pi, math.pi),
       st.floats(-math.pi, math.pi), st.floats(0, 0.7 * V), st.floats(0, 2 * math.pi))
def test_a_leg_flown_backwards_in_the_opposite_wind_takes_the_same_time(x, y, a, b, speed, towards):
    """Time reversal: the reversed path, headings turned round, in the reversed wind."""
    wind = (speed * math.cos(towards), speed * math.sin(towards))
    forward = leg_times_s(np.array([[0.0, 0.0], [x, y]]), np.array([a, b]), RHO, V, wind)[0]
    backward = leg_times_s(np.array([[x, y], [0.0, 0.0]]), np.array([b + math.pi, a + math.pi]),
                           RHO, V, (-wind[0], -wind[1]))[0]
    if math.isfinite(forward) or math.isfinite(backward):
        assert forward == pytest.approx(backward, rel=1e-9, abs=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.floats(-1500, 1500), st.floats(-1500, 1500), st.floats(-math.pi, math.pi),
       st.floats(-math.pi, math.pi), st.floats(0.5, 0.7 * V), st.floats(0, 2 * math.pi))
def test_a_leg_arrives_on_time_and_no_earlier_time_would_do(x, y, a, b, speed, towards):
    """The shortest path in the air mass to where the target is after the leg's time takes that
    time; at no earlier time (sampled) is it short enough, but within a window too short for the
    search's step (the wind carrying the target across the heading line).  A leg found no time
    is refused."""
    wind = np.array([speed * math.cos(towards), speed * math.sin(towards)])
    t = leg_times_s(np.array([[0.0, 0.0], [x, y]]), np.array([a, b]), RHO, V, tuple(wind))[0]
    if not math.isfinite(t):
        return
    assert _air_length(0.0, 0.0, a, x - wind[0] * t, y - wind[1] * t, b, RHO) == pytest.approx(
        V * t, abs=1e-6)

    def arrives(s: float) -> bool:
        return _air_length(0.0, 0.0, a, x - wind[0] * s, y - wind[1] * s, b, RHO) <= V * s - 1e-6

    window = _MAX_STEP_RHO * RHO / V      # arrivals possible for less than this may be passed
    straight = np.hypot(x, y) / (V + speed)
    for s in np.linspace(straight, t, 400, endpoint=False):
        if arrives(s):
            around = [u for u in s + np.linspace(-window, window, 81) if straight <= u < t]
            assert not all(arrives(u) for u in around if abs(u - s) <= window / 2), (s, t)


@settings(max_examples=25, deadline=None)
@given(st.integers(2, 14), st.integers(0, 10_000), st.floats(0, 0.7 * V),
       st.floats(0, 2 * math.pi), st.sampled_from([30.0, 300.0, 3000.0]))
def test_every_wind_tour_passes_the_checker_and_overflies_every_target(n, seed, speed, towards,
                                                                      spread_m):
    rng = np.random.default_rng(seed)
    targets = rng.uniform(0, spread_m, (n, 2))
    wind = (speed * math.cos(towards), speed * math.sin(towards))
    tour = plan_wind_tour(targets, euclidean_tour(targets), RHO, V, wind, grid=8)
    report = tour.check()
    assert report.ok, report.problems
    assert report.max_curvature_ratio <= 1.0 + 1e-12
    # Independently of the checker: over the ground, the path is over each target when the
    # aircraft has flown the legs before it.
    chain = tour.air_chain()
    lengths = np.array([leg.length_m for leg in tour._air_legs()])
    offsets = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    np.testing.assert_allclose(tour.ground_xy_m(offsets), targets[tour.order], atol=1e-6 * RHO)
    assert chain.length_m == pytest.approx(tour.air_length_m, rel=1e-9)
    assert sorted(tour.order.tolist()) == list(range(n))


def test_a_tour_in_wind_is_slower_than_in_calm_air_and_the_same_in_calm_air():
    rng = np.random.default_rng(7)
    targets = rng.uniform(0, 3000, (40, 2))
    order = euclidean_tour(targets)
    calm = plan_wind_tour(targets, order, RHO, V, (0.0, 0.0))
    headings_length = shortest_length(
        np.column_stack([targets[calm.order], calm.air_headings_rad]),
        np.roll(np.column_stack([targets[calm.order], calm.air_headings_rad]), -1, axis=0), RHO).sum()
    assert calm.time_s == pytest.approx(headings_length / V, rel=1e-12)
    windy = [plan_wind_tour(targets, order, RHO, V, (8 * math.cos(d), 8 * math.sin(d)))
             for d in np.linspace(0, 2 * math.pi, 4, endpoint=False)]
    assert all(tour.check().ok for tour in windy)
    assert min(tour.time_s for tour in windy) > calm.time_s


def test_in_calm_air_the_tour_is_never_slower_than_the_calm_tour_it_starts_from():
    """With the calm tour's headings among the candidates, calm air gives back at most its
    length at the airspeed (the order improved on time can only shorten it)."""
    from dtsp_mission.pipeline import plan_tour_in
    rng = np.random.default_rng(11)
    targets = rng.uniform(0, 1200, (30, 2))
    tour = plan_tour_in(targets, RHO, parameters={"time_limit_s": 0.5})
    calm = plan_wind_tour(targets, tour.visit_order, RHO, V, (0.0, 0.0),
                          ground_headings_rad=tour.visit_poses()[:, 2])
    assert calm.check().ok
    assert calm.time_s <= tour.length_m / V * (1 + 1e-12)


def test_the_order_improved_for_the_wind_is_faster_and_never_slower():
    """Or-opt on flight time: in a strong wind over dense targets it finds a faster order
    (measured: 0-3.5 % on the benchmark sites in 5-8 m/s), and it never returns a slower one."""
    rng = np.random.default_rng(4)
    targets = rng.uniform(0, 1500, (40, 2))
    order = euclidean_tour(targets)
    for towards in np.linspace(0, 2 * math.pi, 4, endpoint=False):
        wind = (8 * math.cos(towards), 8 * math.sin(towards))
        kept = plan_wind_tour(targets, order, RHO, V, wind, improve=False)
        improved = plan_wind_tour(targets, order, RHO, V, wind)
        assert improved.check().ok
        assert sorted(improved.order.tolist()) == list(range(len(targets)))
        assert improved.time_s <= kept.time_s
    assert improved.time_s < kept.time_s * 0.999, (improved.time_s, kept.time_s)


@pytest.mark.parametrize("arguments, message", [
    (dict(wind_m_s=(22.0, 0.0)), "not slower than the airspeed"),
    (dict(wind_m_s=(math.nan, 0.0)), "not slower than the airspeed"),
    (dict(rho_m=0.0), "turn radius"),
    (dict(airspeed_m_s=-1.0), "airspeed"),
    (dict(order=np.array([0, 1, 1])), "each of at least two targets once"),
])
def test_bad_input_is_refused_with_a_clear_error(arguments, message):
    call = dict(targets_m=np.array([[0.0, 0.0], [500.0, 0.0], [0.0, 500.0]]),
                order=np.array([0, 1, 2]), rho_m=RHO, airspeed_m_s=V, wind_m_s=(5.0, 0.0))
    call.update(arguments)
    with pytest.raises(InputError, match=message):
        plan_wind_tour(**call)


def test_a_mission_in_a_forecast_wind_is_measured_against_the_tour_for_that_wind():
    """``run_plan`` plans the tour for the forecast wind beside the mission (checked), and the
    mission's flight time is the model's in that wind: between its length at the ground
    speeds of flying all downwind and all upwind."""
    from dtsp_mission.autopilot.navigation import Wind
    from dtsp_mission.mission import MissionSettings
    from dtsp_mission.pipeline import PlanRequest, run_plan
    from dtsp_mission.targets import GeoTargets
    rng = np.random.default_rng(5)
    targets = GeoTargets(47.40 + 0.01 * rng.random(12), 8.50 + 0.015 * rng.random(12))
    calm = run_plan(PlanRequest(targets, RHO, parameters={"time_limit_s": 0.5},
                                settings=MissionSettings(altitude_m=120.0, airspeed_m_s=V,
                                                         design="geometry")))
    assert calm.wind_tour is None
    windy = run_plan(PlanRequest(targets, RHO, parameters={"time_limit_s": 0.5},
                                 settings=MissionSettings(altitude_m=120.0, airspeed_m_s=V,
                                                          wind=Wind(7.0, 250.0), design="guidance")))
    assert windy.wind_tour.check().ok
    assert windy.wind_tour.time_s > calm.tour.length_m / V * 0.9
    summary = windy.mission.summary
    assert (summary["flight_length_m"] / (V + 7.0) < summary["flight_time_s"]
            < summary["flight_length_m"] / (V - 7.0))
    assert summary["predicted_flight_s"] == pytest.approx(windy.mission.guidance.predicted_flight_s)
    assert 0 < windy.mission.guidance.predicted_flight_s < summary["flight_time_s"]
