"""Uploads over real loopback UDP to the simulated vehicle (MAVSDK's server plugins), through
both uploaders, and every failure the issue names: NO_SPACE, a restart mid-upload, a wrong
signing key, no vehicle, a lossy link.  What the vehicle holds is read from the vehicle
itself, never from the uploader's own report."""

from __future__ import annotations

import time

import pytest

from conftest import free_udp_port, make_mission
from dtsp_mission.errors import InputError, LinkError
from dtsp_mission.sim.fault_proxy import Faults, FaultProxy
from dtsp_mission.upload import download_mission, upload_mission
from dtsp_mission.upload.wire import differences, to_wire

UPLOADERS = ["pymavlink", "mavsdk"]


@pytest.fixture(scope="module")
def mission():
    return make_mission(12, 3, 80.0, span_m=1500.0, airspeed_m_s=20.0).for_vehicle()


def holds_plan(vehicle, mission) -> bool:
    return not differences(to_wire(mission), vehicle.mission, mission.autopilot)


@pytest.mark.parametrize("via", UPLOADERS)
@pytest.mark.parametrize("autopilot", ["ardupilot", "px4"])
def test_upload_arrives_item_for_item_and_is_verified(via, autopilot, start_vehicle):
    mission = make_mission(12, 3, 80.0, span_m=1500.0, autopilot=autopilot).for_vehicle()
    vehicle = start_vehicle(mission)
    seen = []
    report = upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}", via=via,
                            progress=lambda done, total: seen.append((done, total)))
    assert report.verified and report.items == len(to_wire(mission))
    assert holds_plan(vehicle, mission), differences(to_wire(mission), vehicle.mission, mission.autopilot)
    assert seen and seen[-1] == (report.items, report.items)
    assert download_mission(f"udpout:127.0.0.1:{vehicle.port}", via=via) == vehicle.mission


@pytest.mark.parametrize("via", UPLOADERS)
def test_no_space_names_the_limit_and_nothing_is_claimed(via, mission, start_vehicle):
    vehicle = start_vehicle(mission, max_items=20)
    with pytest.raises(LinkError) as caught:
        upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}", via=via)
    message = str(caught.value)
    assert "no room" in message and "lower --max-items" in message
    if via == "pymavlink":     # it relays the vehicle's own words, with the limit
        assert "Only 20 items are supported" in message
    assert "holds no mission" in caught.value.on_vehicle
    assert vehicle.mission == []


def test_restart_mid_upload_fails_clearly_and_says_what_is_aboard(mission, start_vehicle):
    vehicle = start_vehicle(mission, restart_at_item=40, restart_s=0.5)
    started = time.monotonic()
    with pytest.raises(LinkError) as caught:
        upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}")
    assert time.monotonic() - started < 30
    assert vehicle.restarts == 1
    assert "stopped answering" in str(caught.value)
    assert caught.value.on_vehicle == "the vehicle holds no mission now"
    assert vehicle.mission == []


def test_signing_right_key_works_wrong_key_is_named(mission, start_vehicle):
    key = bytes(range(32))
    vehicle = start_vehicle(mission, signing_key=key)
    connection = f"udpout:127.0.0.1:{vehicle.port}"
    assert upload_mission(mission, connection, signing_key=key).verified
    assert holds_plan(vehicle, mission)
    with pytest.raises(LinkError, match="signature check: wrong --signing-key"):
        upload_mission(mission, connection, signing_key=bytes(32), heartbeat_timeout_s=2.0)
    with pytest.raises(LinkError, match="signs its messages .* give --signing-key"):
        upload_mission(mission, connection, heartbeat_timeout_s=2.0)   # unsigned: ignored
    assert holds_plan(vehicle, mission)        # the failed attempts changed nothing aboard
    with pytest.raises(InputError, match="cannot sign"):
        upload_mission(mission, connection, via="mavsdk", signing_key=key)


def test_a_key_for_a_vehicle_that_does_not_sign_says_so(mission, start_vehicle):
    vehicle = start_vehicle(mission)                       # no signing on the vehicle
    with pytest.raises(LinkError, match="does not sign its messages: upload without --signing-key"):
        upload_mission(mission, f"udpout:127.0.0.1:{vehicle.port}", signing_key=bytes(range(32)),
                       heartbeat_timeout_s=2.0)
    assert vehicle.mission == []


@pytest.mark.parametrize("via", UPLOADERS)
def test_no_vehicle_is_a_clear_error_in_bounded_time(via, mission):
    started = time.monotonic()
    with pytest.raises(LinkError, match="no heartbeat from a vehicle"):
        upload_mission(mission, f"udpout:127.0.0.1:{free_udp_port()}", via=via,
                       heartbeat_timeout_s=1.0)
    assert time.monotonic() - started < 10


def test_lossy_link_completes_and_verifies_or_fails_clearly(start_vehicle):
    """20 % loss, duplicates and reordering in both directions: every run ends in bounded
    time with success or a clear message, and success is only ever reported when the
    vehicle itself holds exactly the plan."""
    mission = make_mission(5, 3, 80.0, span_m=800.0).for_vehicle()
    outcomes = []
    for seed in range(2):
        vehicle = start_vehicle(mission)
        faults = Faults(drop=0.2, duplicate=0.1, reorder=0.1, delay_s=0.02, seed=seed)
        with FaultProxy(("127.0.0.1", vehicle.port), faults) as proxy:
            started = time.monotonic()
            try:
                report = upload_mission(mission, f"udpout:127.0.0.1:{proxy.port}")
                assert report.verified and holds_plan(vehicle, mission)
                outcomes.append("verified")
            except LinkError as error:
                assert "stopped answering" in error.reason, str(error)
                assert error.on_vehicle, "a failure must say what the vehicle holds"
                outcomes.append(str(error))
            assert time.monotonic() - started < 150
            assert proxy.counts["dropped"] > 0 and proxy.counts["duplicated"] > 0
    print("lossy uploads:", outcomes)


def test_bad_connection_string_is_an_input_error(mission):
    with pytest.raises(LinkError, match="cannot open the connection"):
        upload_mission(mission, "udpout:no-such-host.invalid:14550", heartbeat_timeout_s=1.0)
    with pytest.raises(InputError, match="cannot read the connection"):
        upload_mission(mission, "carrier-pigeon", via="mavsdk")


def test_the_simulated_ardupilot_returns_what_ardupilot_stores(start_vehicle):
    """Downloads come from the vehicle's storage: RTL in frame 0, its own home at seq 0."""
    from dtsp_mission.autopilot import stored_item
    ardupilot = make_mission(6, 9, 80.0, span_m=1000.0, airspeed_m_s=20.0).for_vehicle()
    vehicle = start_vehicle(ardupilot)
    connection = f"udpout:127.0.0.1:{vehicle.port}"
    upload_mission(ardupilot, connection)
    downloaded = download_mission(connection)
    sent = to_wire(ardupilot)
    assert downloaded[-1].command == 20 and sent[-1].frame == 2 and downloaded[-1].frame == 0
    assert downloaded[1:] == [type(s)(**{**stored_item(s, ardupilot.autopilot).__dict__, "current": 0})
                              for s in sent[1:]]
    assert (downloaded[0].x, downloaded[0].y) == (round(ardupilot.home.latitude_deg * 1e7),
                                                  round(ardupilot.home.longitude_deg * 1e7))


def test_more_items_than_mavlink_addresses_are_refused_before_anything_is_sent(mission):
    from dataclasses import replace
    huge = replace(mission, items=mission.items[1:2] * 65_536)
    with pytest.raises(InputError, match="MAVLink addresses at most 65535: nothing was sent"):
        upload_mission(huge, f"udpout:127.0.0.1:{free_udp_port()}", heartbeat_timeout_s=0.5)


def test_a_serial_device_that_does_not_exist_is_one_clear_error():
    with pytest.raises(LinkError, match="cannot open the connection '/dev/ttyNOSUCH0,57600'"):
        upload_mission(make_mission(3, 1, 80.0, span_m=500.0).for_vehicle(),
                       "/dev/ttyNOSUCH0,57600", heartbeat_timeout_s=0.5)
