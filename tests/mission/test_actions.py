"""Actions at the targets: a picture, the camera pointed at the target, the gimbal pitch, a
loiter -- as options for every target and as columns of the targets file, written in the
items each autopilot accepts, in the places where the autopilot runs them, and flown."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from dtsp_mission.autopilot import Autopilot, Command, Frame, stored_item
from dtsp_mission.autopilot.navigation import Airframe
from dtsp_mission.errors import FileFormatError, InputError
from dtsp_mission.frame import LocalFrame
from dtsp_mission.mission import MissionSettings, build_mission
from dtsp_mission.planning import get_planner
from dtsp_mission.targets import read_targets
from dtsp_mission.targets.actions import TargetActions
from dtsp_mission.targets.model import local_targets
from dtsp_mission.tour.check import check_path
from dtsp_mission.autopilot.wire import to_wire

RHO_M = 60.0


def _site(count: int = 8, seed: int = 5, actions: TargetActions | None = None):
    frame = LocalFrame(46.8, 6.95)
    positions = np.random.default_rng(seed).uniform(-700.0, 700.0, (count, 2))
    targets = local_targets(positions).to_geodetic(frame)
    targets = replace(targets, names=tuple(f"p{i}" for i in range(count)), actions=actions)
    tour = get_planner("alternating").plan(targets.in_frame(frame).positions_m, RHO_M)
    return tour, frame, targets


def _every_action(count: int, loiter_at: dict[int, int]) -> TargetActions:
    return TargetActions.none(count).with_options(gimbal_pitch_deg=-45.0, loiter_turns=loiter_at)


@pytest.mark.parametrize("autopilot", ["ardupilot", "px4"])
@pytest.mark.parametrize("design", ["geometry", "guidance"])
def test_actions_are_the_autopilots_items_in_the_places_it_runs_them(autopilot, design):
    tour, frame, targets = _site(actions=_every_action(8, {2: 1, 5: 2}))
    mission = build_mission(tour, frame, targets, MissionSettings(
        autopilot=autopilot, design=design, airspeed_m_s=20.0, photo=True, roi=True))
    items = mission.items
    ardupilot = autopilot == "ardupilot"
    forms = {"photo": Command.DO_DIGICAM_CONTROL if ardupilot else Command.IMAGE_START_CAPTURE,
             "roi": Command.DO_SET_ROI if ardupilot else Command.DO_SET_ROI_LOCATION,
             "gimbal": Command.DO_MOUNT_CONTROL if ardupilot else Command.DO_GIMBAL_MANAGER_PITCHYAW,
             "loiter": Command.NAV_LOITER_TURNS if ardupilot else Command.NAV_LOITER_TIME}
    for item in items:
        if item.role in forms:
            assert item.command == forms[item.role], item
    roles = [item.role for item in items]
    assert roles.count("photo") == 8 and roles.count("roi") == 8 and roles.count("loiter") == 2
    assert roles.count("gimbal") == 1                  # the same pitch is set once
    assert roles.count("roi_off") == 1
    visits = [k for k, item in enumerate(items) if item.role == "target"]
    for number, k in enumerate(visits):
        target = items[k].target
        # The picture is taken when the target's waypoint completes, then the loiter.
        assert items[k + 1].role == "photo" and items[k + 1].target == target
        if target in (2, 5):
            loiter = items[k + 2]
            assert loiter.role == "loiter" and loiter.target == target
        # The camera turns to the target for the whole leg to it: its ROI follows the
        # previous target's items (or the take-off) and no waypoint of another target.
        roi = max(j for j in range(k) if items[j].role == "roi")
        assert items[roi].target == target
        assert (items[roi].latitude_deg, items[roi].longitude_deg) == (
            targets.latitudes_deg[target], targets.longitudes_deg[target])
        earlier = visits[number - 1] if number else 0
        assert earlier < roi
    assert max(k for k, r in enumerate(roles) if r == "roi_off") > visits[-1]
    photo = next(item for item in items if item.role == "photo")
    wire = to_wire(mission.for_vehicle())
    sent = wire[items.index(photo) + (1 if ardupilot else 0)]
    if ardupilot:   # the shutter flag is MISSION_ITEM_INT's x as a plain number, not degrees
        assert (sent.command, sent.x, sent.y) == (Command.DO_DIGICAM_CONTROL, 1, 0)
        assert stored_item(sent, Autopilot.ARDUPILOTMEGA).x == 1
    else:
        assert (sent.param1, sent.param2, sent.param3) == (0.0, 0.0, 1.0)   # one image, now
    assert mission.summary["actions"] == {"photo": 8, "roi": 8, "gimbal": 1, "loiter": 2}
    assert mission.summary["items"] == len(items)


def test_a_loiter_is_whole_circles_through_the_target_in_the_exact_path():
    tour, frame, targets = _site(actions=_every_action(8, {3: 2}))
    plain = build_mission(tour, frame, replace(targets, actions=None), MissionSettings())
    mission = build_mission(tour, frame, targets, MissionSettings(loiter_radius_m=75.0))
    path = mission.path
    (span,) = path.loiters
    assert span.target == 3 and span.turns == 2 and span.radius_m == 75.0
    assert math.isclose(path.chain.length_m - plain.path.chain.length_m, 2 * 2 * math.pi * 75.0,
                        rel_tol=1e-9)
    target_m = tour.targets_m[3]
    assert math.isclose(np.hypot(*(span.centre_m - target_m)), 75.0, rel_tol=1e-9)
    assert math.isclose(path.target_s_m[3], span.start_s_m, abs_tol=1e-9)
    report = check_path(path.chain, RHO_M, tour.targets_m, path.target_s_m, closed=False)
    assert report.ok, report.problems
    (loiter,) = [item for item in mission.items if item.role == "loiter"]
    centre = frame.to_geodetic(span.centre_m.reshape(1, 2))
    assert loiter.params == (2.0, 0.0, 75.0 if span.clockwise else -75.0, 1.0)
    assert math.isclose(loiter.latitude_deg, centre[0][0]) and math.isclose(loiter.longitude_deg, centre[1][0])
    # No waypoint stands on the circles (the loiter item flies them); without the loiter the
    # same tour needs the same waypoints off them.
    waypoints = [i for i in mission.items if i.command == Command.NAV_WAYPOINT and i.role != "target"]
    points = frame.to_local(np.array([i.latitude_deg for i in waypoints]),
                            np.array([i.longitude_deg for i in waypoints]))
    on_circle = np.abs(np.hypot(*(points - span.centre_m).T) - 75.0) < 0.01
    assert not on_circle.any()
    assert len(waypoints) == sum(i.command == Command.NAV_WAYPOINT and i.role != "target"
                                 for i in plain.items)


def test_the_loiter_is_flown_the_aircraft_passes_the_target_once_per_circle():
    """In the flight model of the simulated ArduPlane (the model the vehicle flies): the
    track comes back over the loitered target after each circle and the mission goes on."""
    from dtsp_mission.sim.predict import predict_flight
    tour, frame, targets = _site(actions=_every_action(8, {3: 2}))
    mission = build_mission(tour, frame, targets, MissionSettings(
        design="guidance", airspeed_m_s=20.0, loiter_radius_m=90.0))
    flight = predict_flight(mission.for_vehicle(), Airframe.turning_at(RHO_M, 20.0), dt_s=0.05)
    loiter_seq = 1 + next(k for k, item in enumerate(mission.items) if item.role == "loiter")
    assert loiter_seq in flight.reached            # ArduPlane's seq: home is 0
    assert all(1 + k in flight.reached for k in mission.target_items)
    home = LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg)
    target = home.to_local(targets.latitudes_deg[3:4], targets.longitudes_deg[3:4])[0]
    near = np.hypot(*(flight.track[:, 1:3] - target).T) < 15.0
    passes = int(np.count_nonzero(near[1:] & ~near[:-1]))
    assert passes == 3, passes          # over it, then once after each of the two circles


def test_action_columns_of_a_targets_file(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("name,lat,lon,photo,roi,gimbal_pitch,loiter_turns\n"
                   "a,46.80,6.94,yes,,-90,\nb,46.81,6.95,no,1,,2\nc,46.805,6.955,,,,\n")
    actions = read_targets(csv).actions
    assert actions.photo.tolist() == [True, False, False]
    assert actions.roi.tolist() == [False, True, False]
    assert actions.gimbal_pitch_deg[0] == -90.0 and np.isnan(actions.gimbal_pitch_deg[1:]).all()
    assert actions.loiter_turns.tolist() == [0, 2, 0]
    geojson = tmp_path / "t.geojson"
    geojson.write_text('{"type": "FeatureCollection", "features": ['
                       '{"type": "Feature", "geometry": {"type": "Point", "coordinates": [6.94, 46.8]},'
                       ' "properties": {"name": "a"}},'
                       '{"type": "Feature", "geometry": {"type": "Point", "coordinates": [6.95, 46.81]},'
                       ' "properties": {"name": "b", "photo": true, "loiter_turns": 1}}]}')
    actions = read_targets(geojson).actions
    assert actions.photo.tolist() == [False, True] and actions.loiter_turns.tolist() == [0, 1]
    for cell, message in (("maybe", "photo must be yes/no"), ("1.5", "whole number")):
        column = "photo" if cell == "maybe" else "loiter_turns"
        bad = tmp_path / "bad.csv"
        bad.write_text(f"lat,lon,{column}\n46.80,6.94,{cell}\n46.81,6.95,\n")
        with pytest.raises(FileFormatError, match=message) as caught:
            read_targets(bad)
        assert "line 2" in str(caught.value)


def test_impossible_actions_are_refused_with_a_reason():
    tour, frame, targets = _site(actions=_every_action(8, {1: 1}))
    with pytest.raises(InputError, match="loiter_radius_m"):
        build_mission(tour, frame, targets, MissionSettings(loiter_radius_m=RHO_M / 2))
    with pytest.raises(InputError, match="airspeed"):
        build_mission(tour, frame, targets, MissionSettings(autopilot="px4"))
    with pytest.raises(InputError, match="gimbal pitch"):
        build_mission(tour, frame, targets, MissionSettings(gimbal_pitch_deg=400.0))


def test_action_items_count_against_the_vehicle_storage():
    tour, frame, targets = _site(count=8)
    plain = build_mission(tour, frame, targets, MissionSettings(design="guidance"))
    budget = plain.vehicle_item_count()
    from dtsp_mission.errors import MissionTooLarge
    with pytest.raises(MissionTooLarge):
        build_mission(tour, frame, targets, MissionSettings(design="guidance", photo=True,
                                                            max_items=budget))
    fitted = build_mission(tour, frame, targets, MissionSettings(
        design="guidance", photo=True, max_items=budget + 8))
    assert fitted.vehicle_item_count() <= budget + 8 and fitted.summary["actions"] == {"photo": 8}


def test_actions_reach_a_simulated_vehicle_intact(start_vehicle):
    """Uploaded over loopback and downloaded back: the ArduPilot vehicle keeps the DO items in
    the form AP_Mission stores them (frame 0, the shutter flag in x), and the comparison
    knows that form -- no false alarm."""
    from dtsp_mission.upload import upload_mission
    for autopilot in ("ardupilot", "px4"):
        tour, frame, targets = _site(actions=_every_action(8, {4: 1}))
        mission = build_mission(tour, frame, targets, MissionSettings(
            autopilot=autopilot, airspeed_m_s=20.0, photo=True, roi=True)).for_vehicle()
        vehicle = start_vehicle(mission)
        report = upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
        assert report.verified
        held = {item.command: item for item in vehicle.mission}
        if autopilot == "ardupilot":
            assert held[Command.DO_DIGICAM_CONTROL].frame == Frame.GLOBAL
            assert held[Command.DO_DIGICAM_CONTROL].x == 1
