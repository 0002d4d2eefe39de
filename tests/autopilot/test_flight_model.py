"""The compiled flight model's bookkeeping and its wind, against independent computations and
analytic cases (its agreement with real ArduPlane flights is ``test_agreement.py``)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from dtsp_mission.autopilot import Command
from dtsp_mission.autopilot.parameters import ARDUPLANE_DEFAULTS
from dtsp_mission.autopilot.navigation import (CALM, Airframe, LocalItem, MissionFlight, Wind,
                                               check_wind, closest_approach_m)
from dtsp_mission.errors import InputError

SHIPPED = Airframe.from_parameters(airspeed_m_s=22.0)      # the aircraft missions are designed for


def _mission(points, altitude=100.0, loiter=None):
    items = [LocalItem(0, Command.NAV_WAYPOINT, math.nan, math.nan, 0.0, (0.0,) * 4),
             LocalItem(1, Command.NAV_TAKEOFF, 0.0, 0.0, altitude, (15.0, 0, 0, 0))]
    for x, y in points:
        items.append(LocalItem(len(items), Command.NAV_WAYPOINT, x, y, altitude, (0.0,) * 4))
    if loiter is not None:
        x, y, turns, radius = loiter
        items.append(LocalItem(len(items), Command.NAV_LOITER_TURNS, x, y, altitude,
                               (turns, 0.0, radius, 0.0)))
    items.append(LocalItem(len(items), Command.NAV_RETURN_TO_LAUNCH, math.nan, math.nan, altitude,
                           (0.0,) * 4))
    return items


ZIGZAG = [(600.0, 100.0), (900.0, 700.0), (300.0, 1100.0), (-400.0, 700.0), (-200.0, 100.0)]


@pytest.mark.parametrize("wind", [CALM, Wind(7.0, 250.0)])
def test_closest_approach_is_exact_for_near_and_far_points(wind):
    """The per-point closest approach kept while flying equals the least distance of the
    recorded track (every step's chord, measured by an independent KD-tree search), for points
    near the track and points kilometres away (measured by the second flight)."""
    items = _mission(ZIGZAG)
    rng = np.random.default_rng(3)
    points = np.vstack([np.array(ZIGZAG) + rng.normal(0, 4, (len(ZIGZAG), 2)),
                        rng.uniform(-3000, 3000, (40, 2))])
    flight = MissionFlight(items, SHIPPED, 0.0, 1, wind)
    run = flight.run(0.02, len(items) - 2, points_m=points, measure_from_seq=2)
    after = run.track[run.track[:, 0] >= dict(flight.reached)[1]]
    assert run.closest_m.max() > 100 and run.closest_m.min() < 10
    np.testing.assert_allclose(run.closest_m, closest_approach_m(after[:, 1:3], points),
                               rtol=0, atol=1e-9)
    # and the length flown is the track's, from the take-off's end to the last waypoint
    assert run.measured_length_m == pytest.approx(np.hypot(*np.diff(after[:, 1:3], axis=0).T).sum())


def test_a_checkpoint_goes_on_exactly_as_the_flight_it_was_taken_from():
    items = _mission(ZIGZAG)
    points = np.array(ZIGZAG)
    flight = MissionFlight(items, SHIPPED, 0.0, 1, Wind(5.0, 90.0))
    whole = flight.run(0.02, len(items) - 2, points_m=points, marks={4}, measure_from_seq=2)
    checkpoint = whole.checkpoints[4]
    again = checkpoint.flight
    assert again.reached == [event for event in flight.reached if event[0] < 4]
    resumed = again.run(0.02, len(items) - 2, points_m=points,
                        closest_m=checkpoint.closest_m, measure_from_seq=2)
    np.testing.assert_array_equal(np.vstack([whole.track[:checkpoint.rows], resumed.track]),
                                  whole.track)
    np.testing.assert_array_equal(resumed.closest_m, whole.closest_m)
    assert again.reached == flight.reached
    assert resumed.measured_length_m == whole.measured_length_m
    # a checkpoint is not used up: taken again it starts where it was taken
    assert checkpoint.flight.reached == [event for event in flight.reached if event[0] < 4]


@pytest.mark.parametrize("from_deg,factor", [(90.0, -1), (270.0, 1)])
def test_a_long_leg_is_flown_at_airspeed_plus_or_minus_the_wind(from_deg, factor):
    """Flying east, a wind from the east (90 deg) slows the aircraft over the ground by its
    speed, one from the west speeds it up; the guidance holds the leg (crab), so the track
    stays on the line."""
    wind = Wind(6.0, from_deg)
    items = _mission([(500.0, 0.0), (4500.0, 0.0)])
    flight = MissionFlight(items, SHIPPED, 0.0, 1, wind)
    run = flight.run(0.02, 3)
    times = dict(flight.reached)
    leg = run.track[(run.track[:, 0] > times[2] + 40) & (run.track[:, 0] < times[3] - 20)]
    speed = np.hypot(*np.diff(leg[:, 1:3], axis=0).T).sum() / (leg[-1, 0] - leg[0, 0])
    assert speed == pytest.approx(22.0 + factor * 6.0, abs=0.05)
    assert np.abs(leg[:, 2]).max() < 1.0                 # on the line despite the crab


def test_a_crosswind_is_crabbed_into_and_the_line_held():
    """A 8 m/s wind across the leg: the nose points into it (heading off the course by
    asin(W/V)) while the ground track stays on the line."""
    items = _mission([(500.0, 0.0), (4500.0, 0.0)])
    flight = MissionFlight(items, SHIPPED, 0.0, 1, Wind(8.0, 180.0))     # from the south
    flight.run(0.02, until_s=120.0)                 # on the second leg, x about 2,400 m
    state = flight.state
    assert abs(state.y_m) < 1.0
    assert math.degrees(state.heading_rad) == pytest.approx(-math.degrees(math.asin(8 / 22)), abs=0.5)
    east, north = flight.ground_velocity_m_s
    assert north == pytest.approx(0.0, abs=0.05) and east == pytest.approx(math.sqrt(22**2 - 64), abs=0.05)


def test_a_loiter_in_wind_holds_its_circle_over_the_ground():
    """ArduPlane's loiter law acts on the ground velocity: in 6 m/s of wind the ground track of
    the last circle stays within 5 m of the calm one's (a circle flown in the air mass alone
    would drift some 270 m a turn), three turns still take their time."""
    items = _mission([(300.0, 0.0)], loiter=(900.0, 0.0, 3.0, 150.0))
    radii = []
    for wind in (CALM, Wind(6.0, 0.0)):
        flight = MissionFlight(items, SHIPPED, 0.0, 1, wind)
        run = flight.run(0.02, 3)
        times = dict(flight.reached)
        loop = run.track[run.track[:, 0] > times[3] - 40]          # most of the last circle
        radii.append(np.hypot(loop[:, 1] - 900.0, loop[:, 2]))
        assert times[3] - times[2] > 3 * 2 * math.pi * 150 / 28    # three turns, at most 28 m/s
    calm, windy = radii
    assert np.ptp(calm) < 0.1                                       # a steady circle
    assert np.abs(windy - calm.mean()).max() < 5.0


def test_the_wind_is_checked():
    assert check_wind(Wind(8.0, 225.0), 22.0).speed_m_s == 8.0
    for wind in (Wind(-1.0, 0.0), Wind(math.nan, 0.0), Wind(5.0, math.inf), Wind(40.0, 0.0)):
        with pytest.raises(InputError):
            check_wind(wind)
    with pytest.raises(InputError, match="headway"):
        check_wind(Wind(18.0, 0.0), 22.0)


def test_the_wind_blows_from_where_it_is_said_to():
    east, north = Wind(10.0, 270.0).velocity_m_s       # from the west: towards the east
    assert east == pytest.approx(10.0) and north == pytest.approx(0.0, abs=1e-12)
    east, north = Wind(10.0, 0.0).velocity_m_s         # from the north: towards the south
    assert east == pytest.approx(0.0, abs=1e-12) and north == pytest.approx(-10.0)


@pytest.mark.parametrize("airspeed,rho", [(22.0, 80.0), (18.0, 60.0), (25.0, 150.0)])
def test_the_aircraft_turns_at_the_radius_its_airframe_says(airspeed, rho):
    """One answer to "what radius does this aircraft turn": asked to loiter on a circle
    tighter than it can fly, the aircraft made to turn no tighter than ``rho`` turns at its
    roll limit (and the airspeed it flies at that bank), on arcs of exactly
    ``Airframe.turn_radius_m`` at that bank -- which is ``rho``
    -- measured on the track (distance flown over the course turned, 1 s windows)."""
    assert Airframe() == Airframe.from_parameters()           # the default is the shipped aircraft
    airframe = Airframe.turning_at(rho, airspeed)
    bank = math.radians(airframe.roll_limit_deg)
    faster = airspeed + 1.0 * (1.0 / math.cos(bank) - 1.0)              # 1 m/s per load excess
    assert airframe.turn_radius_m(airframe.roll_limit_deg) == pytest.approx(
        faster ** 2 / (0.70 * 9.80665 * math.tan(bank)), rel=1e-12)    # 0.70 of the coordinated rate
    assert airframe.tightest_turn_m == pytest.approx(rho, rel=1e-12)
    assert airframe.turn_radius_m(airframe.roll_limit_deg) == pytest.approx(rho, rel=1e-12)
    items = _mission([(400.0, 0.0)], loiter=(1200.0, 0.0, 6.0, 0.3 * rho))
    flight = MissionFlight(items, airframe, 0.0, 1)
    run = flight.run(0.02, 3)
    circling = run.track[run.track[:, 0] > dict(flight.reached)[2] + 30.0]   # in the loiter
    step = np.diff(circling[:, 1:3], axis=0)
    course = np.unwrap(np.arctan2(step[:, 1], step[:, 0]))
    flown = np.concatenate([[0.0], np.cumsum(np.hypot(step[:, 0], step[:, 1]))])
    window = 50                                                         # 1 s of 0.02 s steps
    turned = np.maximum(np.abs(course[window:] - course[:-window]), 1e-12)
    radius = (flown[window:-1] - flown[:-window - 1]) / turned
    assert radius.min() >= rho * (1 - 1e-3)                             # never tighter
    assert np.percentile(radius, 25) <= rho * 1.001                     # mostly at the limit


@pytest.mark.parametrize("wind", [CALM, Wind(5.0, 300.0)])
def test_a_px4_loiter_holds_its_circle_for_its_time(wind):
    """PX4 flies NAV_LOITER_TIME on the circle of param3's radius (NPFG with the circle's
    curvature fed forward) for param1 seconds from reaching it: the last circle stays within
    a few metres of the radius over the ground, in calm air and in wind."""
    from dtsp_mission.autopilot.navigation import Airframe
    items = _mission([(300.0, 0.0)])
    items.insert(3, LocalItem(3, Command.NAV_LOITER_TIME, 900.0, 0.0, 100.0, (120.0, 0.0, 90.0, 0.0)))
    items = [LocalItem(k, i.command, i.x_m, i.y_m, i.alt_m, i.params) for k, i in enumerate(items)]
    flight = MissionFlight(items, Airframe.from_px4_parameters(), 0.0, 1, wind)
    run = flight.run(0.02, 3)
    times = dict(flight.reached)
    loop = run.track[run.track[:, 0] > times[3] - 40]               # most of the last circle
    radius = np.hypot(loop[:, 1] - 900.0, loop[:, 2])
    assert np.abs(radius - 90.0).max() < (1.0 if wind == CALM else 2.0), (radius.min(), radius.max())
    assert 120.0 < times[3] - times[2] < 120.0 + 2 * math.pi * 90.0 / 10.0   # its time, from the circle


def _roll_history(airframe: Airframe, from_deg: float, to_deg: float, seconds: float = 2.0):
    """The bank (deg) of the model's roll response, step by step (0.01 s), from a steady bank
    of ``from_deg`` asked to roll to ``to_deg``."""
    from dtsp_mission.autopilot import flight_kernel as K
    from dtsp_mission.autopilot.navigation import airframe_vector
    af = airframe_vector(airframe)
    st = np.zeros(K.STATE_SIZE)
    st[K.S_AIRSPEED] = airframe.airspeed_m_s
    st[K.S_BANK] = math.radians(from_deg)
    st[K.S_COS_HEADING] = 1.0
    demand = K.G * math.tan(math.radians(to_deg))
    banks = []
    for _ in range(int(seconds / 0.01)):
        K._fly(st, af, 0.01, demand, 0.0, 1.0)
        banks.append(math.degrees(st[K.S_BANK]))
    return np.array(banks)


def test_a_large_roll_reversal_is_no_faster_than_the_roll_rate_limit():
    """ArduPlane's roll controller asks for at most RLL2SRV_RMAX: the model's reversal from
    40 deg one way to 40 deg the other is limited to 1.5 x RLL2SRV_RMAX (its fitted share),
    where the second-order lag alone would roll far faster; a small step is the same with the
    limit as without (the limit is not reached)."""
    limited = SHIPPED
    free = Airframe.from_parameters(replace(ARDUPLANE_DEFAULTS, RLL2SRV_RMAX=0.0), 22.0)
    assert limited.roll_rate_max_deg_s == pytest.approx(135.0) and free.roll_rate_max_deg_s == 0.0
    reversal = _roll_history(limited, -40.0, 40.0, seconds=4.0)
    rate = np.diff(reversal) / 0.01
    assert rate.max() <= 135.0 + 1e-6 and rate.max() > 120.0
    free_rate = np.diff(_roll_history(free, -40.0, 40.0)) / 0.01
    assert free_rate.max() > 180.0
    # both end on the new bank
    assert reversal[-1] == pytest.approx(40.0, abs=0.5)
    # a small step does not reach the limit: the same response, step for step
    np.testing.assert_array_equal(_roll_history(limited, 0.0, 5.0), _roll_history(free, 0.0, 5.0))
    # a vehicle's own limit is read from its parameters
    slow = Airframe.from_parameters(replace(ARDUPLANE_DEFAULTS, RLL2SRV_RMAX=60.0), 22.0)
    assert np.diff(_roll_history(slow, -40.0, 40.0)).max() / 0.01 <= 90.0 + 1e-6
