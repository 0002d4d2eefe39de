"""Missions designed for the autopilot's guidance: one aimed waypoint per target.

These tests check the design against the flight model it was made with: that what the design
reports is what the written mission flies (through the vehicle's storage and the geodetic
round trip, from the start), and that its repairs hold more targets.  They are not evidence
that a real aircraft passes the targets: the model's agreement with real ArduPlane flights is
``tests/autopilot/test_agreement.py``, and its margin comes from those flights."""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
import pytest

from dtsp_mission.autopilot import Autopilot, Command
from dtsp_mission.autopilot.navigation import Airframe, closest_approach_m
from dtsp_mission.errors import InputError, MissionTooLarge
from dtsp_mission.frame import LocalFrame
from dtsp_mission.mission import DesignTuning, MissionSettings, build_mission
from dtsp_mission.mission.build import check_storage
from dtsp_mission.planning import get_planner
from dtsp_mission.sim.predict import predict_flight
from dtsp_mission.targets.model import local_targets

CENTRE = (47.3977, 8.5456)


def sparse_site(count=30, seed=2, side=3000.0):
    frame = LocalFrame(*CENTRE)
    positions = np.random.default_rng(seed).uniform(-side / 2, side / 2, (count, 2))
    targets = local_targets(positions).to_geodetic(frame)
    tour = get_planner("auto").plan(targets.in_frame(frame).positions_m, 80.0)
    return tour, frame, targets


@pytest.fixture(scope="module")
def designed():
    tour, frame, targets = sparse_site()
    settings = MissionSettings(altitude_m=120.0, airspeed_m_s=22.0, design="guidance")
    return build_mission(tour, frame, targets, settings), targets


def test_one_waypoint_per_target_and_every_target_predicted_within_the_limit(designed):
    mission, targets = designed
    target_items = [i for i in mission.items if i.role == "target"]
    assert sorted(i.target for i in target_items) == list(range(len(targets)))
    assert len(mission.items) <= 1.4 * len(targets) + 3
    assert max(mission.summary["predicted_miss_m"]) <= 5.0
    assert not any("beyond `max_miss_m`" in note for note in mission.notes)
    # the predicted flight is about as long as the exact path over the same span
    assert mission.summary["predicted_flight_m"] == pytest.approx(mission.summary["planned_flight_m"], rel=0.08)


def _aim_offsets_m(mission, targets, frame) -> np.ndarray:
    items = [i for i in mission.items if i.role == "target"]
    aims = frame.to_local(np.array([i.latitude_deg for i in items]),
                          np.array([i.longitude_deg for i in items]))
    at = targets.in_frame(frame).positions_m[[i.target for i in items]]
    return np.hypot(*(aims - at).T)


def test_a_capped_design_aims_no_target_farther_than_the_cap(designed):
    """``DesignTuning.max_aim_offset_m``: the repair's corrections and the local repair's
    moves keep each target's own waypoint within the cap (the default design aims farther)."""
    mission, targets = designed
    frame = LocalFrame(*CENTRE)
    assert _aim_offsets_m(mission, targets, frame).max() > 4.0
    tour, frame, targets = sparse_site()
    settings = MissionSettings(altitude_m=120.0, airspeed_m_s=22.0, design="guidance",
                               tuning=DesignTuning(max_aim_offset_m=2.0))
    capped = build_mission(tour, frame, targets, settings)
    assert _aim_offsets_m(capped, targets, frame).max() <= 2.0 + 0.02     # 1e-7 deg storage
    assert max(capped.summary["predicted_miss_m"]) < 10.0


def test_the_reported_flight_is_the_predicted_one_where_the_model_flew_it(designed):
    """The flight length and time plan reports (and sorties and --endurance use) are the
    model's flight from the take-off to the last target, the exact path before and after it:
    not the exact path alone, which the autopilot does not fly."""
    mission, _ = designed
    summary = mission.summary
    exact = build_mission(mission.tour, mission.frame, designed[1], MissionSettings(
        altitude_m=120.0, airspeed_m_s=22.0, design="geometry")).summary["flight_length_m"]
    assert summary["flight_length_m"] == pytest.approx(
        exact + summary["predicted_flight_m"] - summary["planned_flight_m"], abs=1e-6)
    # at cruise airspeed, but for the climb-out (ArduPlane ends its take-off about 27 % above
    # cruise and slows over a few seconds) and the banks (it flies up to 0.9 m/s faster in
    # a 60 deg turn: docs/arduplane-agreement.md), which the model flies: a mean ground speed
    # a little above 22 m/s
    mean_speed = summary["flight_length_m"] / summary["flight_time_s"]
    slowed = [item.params[1] for item in mission.items if item.role == "speed"][1:]
    # ... or below it where the design slows down for targets (DesignTuning.slow_rounds)
    assert (min(slowed) if slowed else 22.0) < mean_speed < 22.6


def test_the_written_mission_flown_again_passes_every_target(designed):
    mission, targets = designed
    flight = predict_flight(mission.for_vehicle(), Airframe.from_parameters(airspeed_m_s=22.0))
    after = flight.track[:, 0] >= flight.reached[1]
    xy = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    miss = closest_approach_m(flight.track[after, 1:3], xy)
    assert miss.max() <= 6.0, np.sort(miss)[-5:]


def test_a_px4_mission_is_designed_for_px4s_guidance():
    """PX4 missions get the guidance design too, flying PX4's model (NPFG, its switching 31 m
    before a waypoint): few items, every target held when the written mission is flown again by
    the PX4 model, and a landing at the end (PX4's MIS_TKO_LAND_REQ)."""
    tour, frame, targets = sparse_site(20)
    mission = build_mission(tour, frame, targets, MissionSettings(autopilot="px4", design="guidance"))
    assert mission.guidance is not None and mission.autopilot == Autopilot.PX4
    assert len(mission.items) <= 1.6 * len(targets) + 6
    assert mission.items[-1].command == Command.NAV_LAND
    flight = predict_flight(mission.for_vehicle(), Airframe.from_px4_parameters(), 0.02)
    start = dict(flight.reached)[0]
    xy = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    miss = closest_approach_m(flight.track[flight.track[:, 0] >= start, 1:3], xy)
    assert miss.max() <= mission.guidance.design_limit_m + 0.5, np.sort(miss)[-3:]
    # the flight the model predicts is no longer than the exact path it was designed from
    assert mission.guidance.predicted_flight_m <= 1.05 * mission.guidance.planned_flight_m


def test_a_budget_below_one_item_per_target_is_refused_with_the_count():
    tour, frame, targets = sparse_site(30)
    with pytest.raises(InputError, match=r"needs at least 33 items \(30 for the target\(s\), one each"):
        build_mission(tour, frame, targets, MissionSettings(design="guidance", max_items=20))


@pytest.mark.parametrize("design", ["guidance", "geometry"])
def test_the_storage_check_without_a_design_agrees_with_the_design(design):
    """check_storage (what a tour-only output asks) refuses exactly the budgets the design
    refuses: the smallest budget it accepts builds a mission that fits, one less fails both."""
    tour, frame, targets = sparse_site(12)
    settings = MissionSettings(design=design, airspeed_m_s=22.0)
    fits = []
    for max_items in range(10, 200):
        try:
            check_storage(tour, frame, targets, replace(settings, max_items=max_items))
            fits.append(max_items)
        except MissionTooLarge:
            pass
    least = fits[0]
    assert fits == list(range(least, 200))              # every larger budget passes too
    mission = build_mission(tour, frame, targets, replace(settings, max_items=least))
    assert mission.vehicle_item_count() <= least
    with pytest.raises(MissionTooLarge):
        build_mission(tour, frame, targets, replace(settings, max_items=least - 1))


def test_the_same_input_gives_the_same_mission(designed):
    mission, _ = designed
    tour, frame, targets = sparse_site()
    again = build_mission(tour, frame, targets, MissionSettings(altitude_m=120.0, airspeed_m_s=22.0,
                                                                 design="guidance"))
    assert again.items == mission.items


def _fence(rho_m: float):
    from conftest import fence_poses
    from dtsp_mission.tour import tour_through_poses
    points, headings = fence_poses()
    frame = LocalFrame(46.8, 6.95)
    tour = tour_through_poses(points, np.arange(len(points)), headings, rho_m)
    return tour, frame, local_targets(points).to_geodetic(frame)


def test_loops_of_the_exact_path_get_waypoints_and_are_flown_round():
    """ArduPlane given only a loop's ends cuts inside it, the wrong way round, and misses the
    posts after it (the bundled site's fence corners); waypoints on the loop make it fly the
    loop: as first designed (one predicted flight, before any repair), fewer targets beyond
    the limit, a smaller worst miss, a predicted flight closer to the planned one."""
    tour, frame, targets = _fence(104.0)
    first_flight = DesignTuning(rounds=1, refine_passes=0, revisits=False)
    settings = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0,
                               tuning=first_flight)
    looped = build_mission(tour, frame, targets, settings)
    bare = build_mission(tour, frame, targets, replace(settings, tuning=replace(
        first_flight, loop_min_rad=float("inf"))))

    def figures(mission):
        miss = np.array(mission.summary["predicted_miss_m"])
        ratio = mission.summary["predicted_flight_m"] / mission.summary["planned_flight_m"]
        return int((miss > 5.0).sum()), float(miss.max()), abs(ratio - 1.0)
    beyond, worst, off = figures(looped)
    beyond_bare, worst_bare, off_bare = figures(bare)
    assert beyond < beyond_bare and worst < worst_bare and off < off_bare
    assert looped.summary["items"] > bare.summary["items"]          # the loop waypoints


def test_the_repair_keeps_only_what_the_model_flew_better():
    """The repair rounds never return a design the model predicts worse than the first one,
    and on the fence they hold more posts than it."""
    tour, frame, targets = _fence(104.0)
    settings = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0)

    def excess(mission):
        miss = np.array(mission.summary["judged_miss_m"])
        limit = settings.design_limit_m
        return float(np.maximum(miss - limit, 0.0).sum()), int((miss > limit).sum())
    repaired = build_mission(tour, frame, targets, settings)
    first = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(rounds=1, refine_passes=0, revisits=False)))
    assert excess(repaired)[0] < excess(first)[0] and excess(repaired)[1] < excess(first)[1]
    assert 2 < repaired.summary["design_rounds"]
    # one predicted flight, the verifying one, then the design flown in each design wind, by
    # the aircraft turning slower and faster (DesignTuning.turn_spread), rolling slower
    # (DesignTuning.roll_spread) and rolling much slower (DesignTuning.flip_roll_spread)
    assert first.summary["design_rounds"] == 2 + len(settings.design_winds()) + 4


def test_a_flight_copied_midway_goes_on_exactly_as_the_original():
    """The local repair re-flies from copies of a flight in progress: a copy continued must
    give the same track as the flight itself, and leave it untouched while it flies."""
    from dtsp_mission.autopilot.commands import Command
    from dtsp_mission.autopilot.navigation import LocalItem, MissionFlight
    points = [(400.0, 0.0), (600.0, 300.0), (200.0, 500.0), (-100.0, 200.0)]
    items = [LocalItem(0, Command.NAV_WAYPOINT, np.nan, np.nan, 0.0, (0.0,) * 4),
             LocalItem(1, Command.NAV_TAKEOFF, 0.0, 0.0, 60.0, (15.0, 0, 0, 0))]
    items += [LocalItem(len(items) + k, Command.NAV_WAYPOINT, x, y, 60.0, (0.0,) * 4)
              for k, (x, y) in enumerate(points)]
    flight = MissionFlight(items, Airframe.from_parameters(airspeed_m_s=22.0), 0.0, 1)
    for _ in range(600):
        flight.step(0.05)
    copy = flight.copy()
    frozen = (flight.state.x_m, flight.state.y_m, flight.state.heading_rad, len(flight.reached))
    copied = []
    for _ in range(1500):
        copy.step(0.05)
        copied.append((copy.state.x_m, copy.state.y_m))
    assert (flight.state.x_m, flight.state.y_m, flight.state.heading_rad,
            len(flight.reached)) == frozen
    original = []
    for _ in range(1500):
        flight.step(0.05)
        original.append((flight.state.x_m, flight.state.y_m))
    assert copied == original and copy.reached == flight.reached
    assert len(flight.reached) > frozen[3]          # it went on past more waypoints


def test_the_local_repair_holds_more_and_reports_what_the_mission_flies():
    """The local repair (short flights from checkpoints) ends with fewer targets beyond than
    the global repair, and the misses it reports are those of the written mission flown again
    from the start at the model's step."""
    tour, frame, targets = _fence(80.0)
    eight = DesignTuning(rounds=8)
    settings = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0,
                               tuning=eight)
    repaired = build_mission(tour, frame, targets, settings)
    unrepaired = build_mission(tour, frame, targets, replace(
        settings, tuning=replace(eight, refine_passes=0, revisits=False)))
    limit = settings.design_limit_m
    held = np.array(repaired.summary["predicted_miss_m"])          # in the forecast (calm) air
    before = np.array(unrepaired.summary["judged_miss_m"])
    assert (before > limit).sum() > 0
    assert (np.array(repaired.summary["judged_miss_m"]) > limit).sum() < (before > limit).sum()
    flight = predict_flight(repaired.for_vehicle(), Airframe.from_parameters(airspeed_m_s=22.0),
                            eight.verify_step_s)
    after = flight.track[:, 0] >= flight.reached[1]
    xy = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
    flown = closest_approach_m(flight.track[after, 1:3], xy)
    assert np.abs(flown - held).max() < 0.01    # the same flight: the design flies the stored positions


@pytest.mark.heavy(seconds=16)
def test_the_turn_margin_keeps_a_design_that_holds_and_otherwise_ranks_by_the_flight():
    """Flight time is what the operator pays for: a design that holds every target is kept
    as it is (no other radius is even planned), however far its flight strays from the plan;
    one that does not is replaced only by a design holding more targets, or as many with a
    shorter predicted flight."""
    from dtsp_mission.mission.widening import targets_beyond, with_turn_margin
    tour, frame, targets = _fence(80.0)
    planned = []

    def replan(rho):
        planned.append(rho)
        return get_planner("auto").plan(targets.in_frame(frame).positions_m, rho)

    def key(mission):
        return targets_beyond(mission), mission.summary["predicted_flight_m"]
    loose = MissionSettings(altitude_m=120.0, airspeed_m_s=22.0, design="guidance", max_miss_m=60.0)
    mission = build_mission(tour, frame, targets, loose)
    assert targets_beyond(mission) == 0
    assert with_turn_margin(mission, replan, targets, loose) is mission and planned == []
    # (a 4 m limit: since the model flies faster in banks the design holds the fence within
    # 5 m without second passes)
    strict = MissionSettings(altitude_m=120.0, airspeed_m_s=22.0, design="guidance",
                             max_miss_m=4.0, tuning=DesignTuning(
                                 revisits=False, slow_rounds=0, guidance_margins=(1.3,)))
    mission = build_mission(tour, frame, targets, strict)
    assert targets_beyond(mission) > 0
    chosen = with_turn_margin(mission, replan, targets, strict)
    assert planned and planned[0] == pytest.approx(1.3 * mission.rho_m)
    assert key(chosen) <= key(mission)
    assert chosen is mission or chosen.rho_m in [pytest.approx(r) for r in planned]


@pytest.mark.heavy(seconds=29)
def test_the_local_repair_s_other_starts_are_deterministic():
    """After one repair round on the fence (forecast wind only), the local repair's pattern
    search leaves posts beyond the design limit; 100 seeded random starts (off by default) give
    the same mission for the same input.  (A heuristic that no longer pays: with the take-off
    flown where the vehicle stores it, over 1-4 rounds the search alone left 1 post beyond and
    with the starts 1, 3, 3, 3; since the model flies to a waypoint whose leg starts already
    past it, as ArduPlane does, one round leaves 2 alone and 5 with the starts.)"""
    tour, frame, targets = _fence(80.0)
    # (judged as measured: the turn spread of then, no slower roll, no slow zones)
    then = dict(rounds=1, revisits=False, slow_rounds=0, turn_spread=0.04, roll_spread=0.0,
                roll_damping_spread=0.0, perturbed_holdback_m=0.0)
    settings = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0,
                               wind_spread_m_s=0.0, tuning=DesignTuning(local_starts=100, **then))
    started = build_mission(tour, frame, targets, settings)
    assert build_mission(tour, frame, targets, settings).items == started.items
    assert started.guidance.design_rounds > 1


def _flown_again_off_the_report_m(mission) -> float:
    """How far the written mission, flown again from the start by the stock aircraft at
    22 m/s, passes its targets from the misses its design reports (the worst target)."""
    from dtsp_mission.sim.fly import planned_targets
    flown = predict_flight(mission.for_vehicle(), Airframe.from_parameters(airspeed_m_s=22.0))
    passed = planned_targets(mission)
    miss = closest_approach_m(flown.track[:, 1:3],
                              flown.frame.to_local(passed.latitudes_deg, passed.longitudes_deg))
    order = [item.target for item in mission.items if item.role == "target"]
    return float(np.abs(miss - mission.guidance.predicted_miss_m[order]).max())


def _clustered(count: int, seed: int):
    """Targets in Gaussian clusters among sparse ones (benchmarks/mission_items.py's clustered
    sites: tours crossing themselves among targets tens of metres apart)."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-2500.0, 2500.0, (max(2, count // 40), 2))
    inside = count * 3 // 4
    clustered = centres[rng.integers(0, len(centres), inside)] + rng.normal(0, 120.0, (inside, 2))
    points = np.vstack([clustered, rng.uniform(-3000.0, 3000.0, (count - inside, 2))])
    return local_targets(points).to_geodetic(LocalFrame(*CENTRE))


#: The clustered sites' settings: the stock aircraft at 22 m/s, forecast wind only.
_CLUSTERED_SETTINGS = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0,
                                      home_deg=CENTRE, wind_spread_m_s=0.0)


@pytest.fixture(scope="module")
def clustered_stuck():
    """A clustered site (80 targets, seed 2, rho 80 m; forecast wind only), its settings, and
    its design without the local repair's second search, slow zones and second passes (which
    leaves a target beyond)."""
    from dtsp_mission.api import plan_tour
    targets = _clustered(80, 2)
    tour, frame = plan_tour(targets, 80.0)
    settings = _CLUSTERED_SETTINGS
    stuck = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(local_reset=False, revisits=False, slow_rounds=0)))
    return tour, frame, targets, settings, stuck


@pytest.mark.heavy(seconds=90)
def test_the_local_repair_starts_again_from_the_targets_where_corrections_piled_up(clustered_stuck):
    """On a clustered site (80 targets, seed 2, rho 80 m; forecast wind only) the pattern
    search from the repaired aims leaves targets beyond the design limit: the corrections of
    neighbouring waypoints, each moved to pass its own target, hold each other where no small
    step helps.  Searched again from those waypoints put back on their targets, fewer are
    left beyond with the same waypoints (here: no more), and the default design (with second
    passes) leaves no more than that (it held every target before the model flew faster in
    banks; it leaves one now, which ``plan`` names).  (A heuristic: without second passes, over seeds 0-6 at rho
    80 it left 16 targets beyond with the second search and 21 without -- measured before the
    model flew faster in banks; on no seed does it hold all.)"""
    from dtsp_mission.mission.widening import targets_beyond
    tour, frame, targets, settings, stuck = clustered_stuck
    reset = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(local_reset=True, revisits=False, slow_rounds=0)))
    assert 0 < targets_beyond(reset) <= targets_beyond(stuck)
    assert len(reset.items) == len(stuck.items)          # the same waypoints, placed otherwise
    held = build_mission(tour, frame, targets, settings)      # local_reset and revisits by default
    assert targets_beyond(held) <= targets_beyond(reset)


def test_a_mission_designed_for_the_wind_holds_in_it_what_a_calm_design_misses():
    """In 8 m/s from 40 deg the calm design (flown by the model, which counts the targets a
    real ArduPlane missed in wind within a few: test_agreement) misses targets by tens of
    metres; the same tour designed for that wind holds them in it."""
    from dtsp_mission.autopilot.navigation import Wind
    tour, frame, targets = sparse_site(20, seed=3, side=2000.0)
    wind = Wind(8.0, 40.0)
    airframe = Airframe.from_parameters(airspeed_m_s=22.0)
    xy = targets.in_frame(frame).positions_m

    def misses_in_wind(mission):
        flight = predict_flight(mission.for_vehicle(), airframe, wind=wind)
        after = flight.track[:, 0] >= flight.reached[1]
        local = flight.frame.to_local(targets.latitudes_deg, targets.longitudes_deg)
        return closest_approach_m(flight.track[after, 1:3], local)
    calm = build_mission(tour, frame, targets, MissionSettings(
        design="guidance", airspeed_m_s=22.0, altitude_m=120.0, wind_spread_m_s=0.0))
    windy = build_mission(tour, frame, targets, MissionSettings(
        design="guidance", airspeed_m_s=22.0, altitude_m=120.0, wind=wind, wind_spread_m_s=0.0))
    assert len(xy) == 20
    in_wind_calm, in_wind_designed = misses_in_wind(calm), misses_in_wind(windy)
    assert (in_wind_calm > 5.0).sum() >= 3
    assert (in_wind_designed > 5.0).sum() < (in_wind_calm > 5.0).sum()
    print("beyond 5 m in the wind: calm design", (in_wind_calm > 5.0).sum(), "designed for it",
          (in_wind_designed > 5.0).sum(), "worst", in_wind_calm.max(), in_wind_designed.max())
    # what the design reports is what the model flies in that wind
    assert np.abs(np.array(windy.summary["predicted_miss_m"]) - in_wind_designed).max() < 0.01
    assert windy.summary["design_wind"]["speed_m_s"] == 8.0


@pytest.mark.heavy(seconds=40)
def test_a_target_left_beyond_is_passed_again_later_and_held():
    """On another clustered site (seed 5), without the second search the design leaves targets
    beyond its limit (5 today); with revisits each such target is passed a second time later in
    the mission -- one waypoint over it, at its altitude and acceptance radius -- which brings
    them closer (1 left beyond: revisits are a heuristic, kept only when the robust cost falls;
    on the site of the test above they no longer lower it, since the model flies to a waypoint
    whose leg starts already past it as ArduPlane does), and the written mission, flown again
    from the start, passes the targets as the design reports."""
    from dtsp_mission.api import plan_tour
    from dtsp_mission.mission.widening import targets_beyond as beyond
    settings = _CLUSTERED_SETTINGS
    targets = _clustered(80, 5)
    tour, frame = plan_tour(targets, 80.0)
    # judged by the forecast and the design winds only (as measured; with the turn spread the
    # revisit does not lower the robust cost here and is not kept;
    # and with no slow zones, which hold it on the first pass)
    only = dict(local_reset=False, turn_spread=0.0, roll_spread=0.0, roll_damping_spread=0.0,
                slow_rounds=0)
    alone = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(revisits=False, **only)))
    again = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(detour_rounds=0, **only)))
    assert beyond(alone) > 0 and beyond(again) <= beyond(alone)
    limit = settings.checked(80.0).design_limit_m
    excess = [np.maximum(m.guidance.judged_miss_m - limit, 0.0).sum() for m in (alone, again)]
    assert excess[1] < excess[0]
    revisits = [item for item in again.items if item.role == "revisit"]
    assert revisits and again.guidance.revisit_waypoints == len(revisits)
    own = {item.target: item for item in again.items if item.role == "target"}
    latitudes, longitudes = again.target_positions_deg
    for item in revisits:
        assert item.params[1] == own[item.target].params[1] > 0          # its acceptance radius
        assert item.altitude_m == pytest.approx(own[item.target].altitude_m)
    assert _flown_again_off_the_report_m(again) < 0.3


@pytest.mark.heavy(seconds=40)
def test_a_target_the_revisits_leave_beyond_gets_a_detour_with_a_straight_lead_in(clustered_stuck):
    """A detour passes a stuck target again from a lead-in waypoint about two L1 distances
    before it (a straight the guidance settles on) and rejoins the leg it left before that
    leg's next waypoint; the design keeps it only where the robust cost falls, and the written
    mission flown from the start passes the targets as the design reports.  (Without slow
    zones, which hold this site without any second pass.)"""
    from dtsp_mission.mission.widening import targets_beyond as beyond
    tour, frame, targets, settings, alone = clustered_stuck
    detoured = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(local_reset=False, revisit_rounds=0, slow_rounds=0)))
    limit = settings.checked(80.0).design_limit_m
    excess = [np.maximum(m.guidance.judged_miss_m - limit, 0.0).sum() for m in (alone, detoured)]
    assert excess[1] < excess[0] and beyond(detoured) <= beyond(alone)
    items = detoured.items
    passes = [k for k, item in enumerate(items) if item.role == "revisit"]
    assert passes
    airframe = Airframe.from_parameters(airspeed_m_s=22.0)
    l1_m = airframe.l1_distance_m(22.0)
    local = frame.to_local(np.array([i.latitude_deg for i in items]),
                           np.array([i.longitude_deg for i in items]))
    for k in passes:
        assert items[k - 1].role == "shaping" and items[k + 1].role == "shaping"
        lead_in = float(np.hypot(*(local[k - 1] - local[k])))
        assert 1.5 * l1_m < lead_in < 2.5 * l1_m, (lead_in, l1_m)
    assert _flown_again_off_the_report_m(detoured) < 0.3


def test_slow_zones_start_far_enough_before_each_target_and_end_at_it():
    from dtsp_mission.mission.guidance import _slow_zones
    s_wp = [0.0, 100.0, 250.0, 300.0, 420.0, 500.0, 900.0, 1000.0, 1100.0]
    target_of = [0, -1, 1, 2, -1, 3, 4, 5, 6]
    # slowed for targets 3 (waypoint 5) and 4 (waypoint 6), 200 m ahead of each: the speed
    # changes on reaching the last waypoint at least 200 m before (3 for target 3, 5 for
    # target 4: the change is the item before waypoints 4 and 6; the zones are one), and back
    # on reaching the last target's waypoint (the item before waypoint 7)
    speeds = _slow_zones(s_wp, target_of, [3, 4], 16.0, 22.0, 200.0)
    nan = float("nan")
    expected = [nan, nan, nan, nan, 16.0, nan, nan, 22.0, nan]
    assert [v if v == v else None for v in speeds] == [v if v == v else None for v in expected]
    # a zone reaching back past the first waypoint starts before it; none ends after the last
    speeds = _slow_zones(s_wp, target_of, [1, 6], 16.0, 22.0, 500.0)
    assert speeds[0] == 16.0 and speeds[3] == 22.0
    assert speeds[6] == 16.0 and all(v != v for v in speeds[7:])


def test_a_slow_zone_starts_at_a_waypoint_of_its_own_where_the_leg_before_is_long():
    """The speed changes where a waypoint is reached: a zone whose last waypoint far enough
    before its target is a long leg back gets a slowing waypoint where it should start, so
    the zone is as long as asked, not a whole leg longer."""
    from dtsp_mission.mission.guidance import _slow_zones, _with_zone_starts
    s_wp = [0.0, 100.0, 900.0, 1000.0, 1500.0, 1560.0, 2600.0]
    target_of = [0, 1, 2, 3, 4, 5, 6]
    # targets 2 (at 900 m: its zone should start at 650 m, the waypoint before is at 100 m),
    # 3 (its zone starts inside target 2's: no waypoint), 5 (starts at 1310 m, 190 m after
    # the waypoint at 1000 m) and 6 (starts at 2350 m, 790 m after 1560 m): waypoints
    s_new, of_new, inserted = _with_zone_starts(s_wp, target_of, {2, 3, 5, 6}, 250.0, 45.0, {})
    assert [round(s_new[k]) for k in inserted] == [650, 1310, 2350]
    assert all(of_new[k] == -1 for k in inserted)
    assert s_new == sorted(s_new) and len(s_new) == len(s_wp) + 3
    speeds = _slow_zones(s_new, of_new, [2, 3, 5, 6], 16.0, 22.0, 250.0)
    # slow from the item after each slowing waypoint, back after target 3's and 5's waypoints
    slow_from = [k for k, v in enumerate(speeds) if v == 16.0]
    assert slow_from == [k + 1 for k in inserted]
    # one within the slack before the start (1000 m for a zone from 1010 m): no waypoint
    _, _, none = _with_zone_starts(s_wp, target_of, {4}, 490.0, 45.0, {})
    assert none == []
    # not inside a loiter, nor before the path
    _, _, none = _with_zone_starts(s_wp, target_of, {2, 1}, 250.0, 45.0, {600.0: 700.0})
    assert none == []


@pytest.mark.heavy(seconds=60)
def test_targets_the_design_cannot_hold_at_the_airspeed_are_flown_slower(clustered_stuck):
    """On the clustered site, without second passes: slow zones (DO_CHANGE_SPEED to 75 % of the
    airspeed from a little before each target left beyond, back after it) hold targets the
    design at the airspeed leaves beyond, with no longer a flight; the written mission,
    flown again from the start, passes the targets as the design reports."""
    from dtsp_mission.mission.widening import targets_beyond as beyond
    tour, frame, targets, settings, _ = clustered_stuck
    fast = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(revisits=False, slow_rounds=0, refine_passes=0)))
    slow = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(revisits=False)))
    assert beyond(fast) > 0 and beyond(slow) < beyond(fast)
    assert slow.guidance.predicted_flight_m <= 1.02 * fast.guidance.predicted_flight_m
    speeds = [item.params[1] for item in slow.items if item.command == Command.DO_CHANGE_SPEED]
    assert speeds[0] == 22.0 and len(speeds) >= 2
    assert set(speeds[1:]) == {16.5, 22.0}
    assert all(a != b for a, b in zip(speeds, speeds[1:]))     # slow, back, slow, back ...
    assert _flown_again_off_the_report_m(slow) < 0.3


@pytest.mark.heavy(seconds=40)
def test_a_tour_with_lead_ins_is_designed_with_a_waypoint_where_each_straight_begins(clustered_stuck):
    """A tour with straight lead-ins planned before some targets
    (:func:`dtsp_mission.planning.lead_ins.with_lead_ins`, here before the targets the design
    leaves beyond) is a valid tour, and the guidance design flies each straight from a
    waypoint placed at its start (here without the local repair, which may move it).  (Measured on this site: the lead-ins lengthen the tour by
    115 m and hold 4 of the 6 targets, but the design then leaves 5 others beyond: not used
    by default, docs/design-time.md.)"""
    from dtsp_mission.mission.waypoints import lead_in_starts_m
    from dtsp_mission.planning.lead_ins import with_lead_ins
    from dtsp_mission.tour.check import check_tour
    tour, frame, targets, settings, stuck = clustered_stuck
    beyond = np.flatnonzero(stuck.guidance.judged_miss_m > stuck.guidance.design_limit_m)
    assert beyond.size > 0
    led_tour = with_lead_ins(tour, {int(t): 60.0 for t in beyond})
    assert check_tour(led_tour).ok
    led = build_mission(led_tour, frame, targets, replace(
        settings, tuning=DesignTuning(revisits=False, slow_rounds=0, refine_passes=0)))
    starts_s = lead_in_starts_m(led.path, led.tour)
    assert len(starts_s) >= beyond.size - 1           # (the first target is reached otherwise)
    starts = led.path.chain.pose_at(starts_s)[:, :2]
    shaping = [item for item in led.items if item.role == "shaping"]
    placed = frame.to_local(np.array([i.latitude_deg for i in shaping]),
                            np.array([i.longitude_deg for i in shaping]))
    for point in starts:          # there, as the vehicle stores it
        assert np.hypot(*(placed - point).T).min() < 0.05


@pytest.mark.heavy(seconds=15)
def test_in_wind_targets_passed_twice_are_entered_along_a_straight_planned_into_the_tour():
    """In 8 m/s (20 targets over 2 km) the design holds two targets only by passing them
    again; with straight lead-ins planned into the tour before those two the design holds
    every target on the first pass, in a shorter predicted flight (measured: 634 -> 474 s),
    and that mission is the one returned: its tour has the lead-ins, passes the checker, and
    the summary gives both tours."""
    from dtsp_mission.autopilot.navigation import Wind
    from dtsp_mission.tour.check import check_tour
    tour, frame, targets = sparse_site(20, seed=1, side=2000.0)
    settings = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0,
                               wind=Wind(8.0, 40.0))
    plain = build_mission(tour, frame, targets, replace(
        settings, tuning=DesignTuning(stuck_lead_in_l1=None)))
    passed_again = {item.target for item in plain.items if item.role == "revisit"}
    assert plain.tour is tour and len(passed_again) == 2
    led = build_mission(tour, frame, targets, settings)
    assert led.tour is not tour and check_tour(led.tour).ok
    assert set(np.flatnonzero(led.tour.lead_in_m > 0).tolist()) == passed_again
    airframe = settings.checked(80.0).design_airframe()
    lead_m = DesignTuning().stuck_lead_in_l1 * airframe.l1_distance_m(22.0 + 8.0)
    assert np.all(led.tour.lead_in_m[list(passed_again)] >= lead_m - 1e-6)
    assert led.guidance.targets_beyond() == 0 and led.guidance.revisit_waypoints == 0
    assert led.guidance.predicted_flight_s < 0.9 * plain.guidance.predicted_flight_s
    assert led.summary["tour_length_m"] == tour.length_m
    assert led.summary["lead_in_tour_length_m"] == led.tour.length_m > tour.length_m
    assert any("straight lead-ins planned into the tour before 2 targets" in note
               for note in led.notes)
    # calm air: a second pass costs less there than the straight (measured), no lead-ins
    calm = build_mission(tour, frame, targets, replace(settings, wind=Wind(0.0, 0.0)))
    assert calm.tour is tour


_ONE_DESIGN = """
import hashlib, os, pickle, sys
sys.path.insert(0, {tests!r})
from mission.test_guidance import _clustered, CENTRE
from dtsp_mission.frame import LocalFrame
from dtsp_mission.mission import DesignTuning, MissionSettings, build_mission
if {one_core}:
    os.sched_setaffinity(0, {{min(os.sched_getaffinity(0))}})
targets = _clustered(80, 2)
with open({tour!r}, "rb") as file:
    tour, origin = pickle.load(file)
frame = LocalFrame(*origin)
settings = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0,
                           home_deg=CENTRE, wind_spread_m_s=0.0,
                           tuning=DesignTuning(revisits=False, slow_rounds=0))
mission = build_mission(tour, frame, targets, settings)
print(hashlib.sha256(repr([(i.command, i.latitude_deg, i.longitude_deg, i.params)
                            for i in mission.items]).encode()).hexdigest(),
      mission.guidance.design_rounds)
"""


@pytest.mark.heavy(seconds=8)
@pytest.mark.skipif(not hasattr(os, "sched_getaffinity") or len(os.sched_getaffinity(0)) < 2,
                    reason="needs two cores to compare with one")
def test_the_design_is_the_same_on_one_core_and_on_several(clustered_stuck, tmp_path):
    """The design flies its trials on every core (the local repair's moves of a step, the
    conditions of a trial): what it chooses does not depend on the machine -- the mission
    designed pinned to one core is item for item the one designed on all of them (the clustered
    site whose local repair has targets to work on; its tour planned once, by the fixture)."""
    import pickle
    import subprocess
    import sys
    from pathlib import Path
    tests = str(Path(__file__).resolve().parents[1])
    tour, frame = clustered_stuck[:2]
    saved = tmp_path / "tour.pickle"
    saved.write_bytes(pickle.dumps((tour, (frame.origin_lat_deg, frame.origin_lon_deg))))
    # both at once: the one pinned to one core, the other on all of them
    running = [subprocess.Popen([sys.executable, "-c", _ONE_DESIGN.format(
                                     tests=tests, one_core=one, tour=str(saved))],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
               for one in (True, False)]
    results = []
    try:
        for process in running:
            out, err = process.communicate(timeout=300)
            assert process.returncode == 0, err
            results.append(out.split())
    finally:
        for process in running:
            process.kill()
    assert results[0] == results[1]
    assert int(results[0][1]) > 0


def _slow_roll_misses_m(mission) -> tuple[np.ndarray, list[int]]:
    """The written mission flown again from the start by the stock aircraft at 22 m/s rolling
    much slower (DesignTuning's flip guard: roll response 40 % slower, damping +0.3): its miss
    at each target waypoint, and the target each is for."""
    from dtsp_mission.mission.guidance import rolling_slower
    from dtsp_mission.sim.fly import planned_targets
    tuning = DesignTuning()
    slow = rolling_slower(Airframe.from_parameters(airspeed_m_s=22.0), tuning.flip_roll_spread,
                          tuning.flip_roll_damping_spread)
    flown = predict_flight(mission.for_vehicle(), slow)
    passed = planned_targets(mission)
    miss = closest_approach_m(flown.track[:, 1:3],
                              flown.frame.to_local(passed.latitudes_deg, passed.longitudes_deg))
    return miss, [item.target for item in mission.items if item.role == "target"]


@pytest.mark.heavy(seconds=20)
def test_the_flip_guard_holds_every_target_with_the_aircraft_rolling_much_slower(clustered_stuck):
    """With the flip guard (the default), the written mission flown again by the aircraft
    rolling much slower passes every target the design holds within --max-miss plus the
    guard's allowance (5 + 1.5 m); the same site designed without the guard does not (one
    target at 6.8 m here): the guard is what holds them."""
    tour, frame, targets = clustered_stuck[:3]        # the clustered site's tour, planned once
    allowed = 5.0 + DesignTuning().flip_allowance_m
    worst = []
    for tuning in (DesignTuning(), DesignTuning(flip_roll_spread=0.0, flip_roll_damping_spread=0.0)):
        settings = MissionSettings(design="guidance", airspeed_m_s=22.0, altitude_m=120.0,
                                   home_deg=CENTRE, tuning=tuning)
        mission = build_mission(tour, frame, targets, settings)
        held = mission.guidance.judged_miss_m <= settings.checked(80.0).design_limit_m
        assert held.all()
        miss, target_of = _slow_roll_misses_m(mission)
        worst.append(max(m for m, t in zip(miss, target_of) if held[t]))
    assert worst[0] <= allowed < worst[1]
