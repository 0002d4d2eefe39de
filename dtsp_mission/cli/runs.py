"""Runs shared by several commands, each printing what happened: the upload (``upload``,
``plan --upload``) and the simulated flight check (``fly``, ``plan --simulate``).  Commands
import these; no command module imports another."""

from __future__ import annotations

import click
import numpy as np

from ..autopilot.navigation import CALM
from ..sim.fly import (FlightCheck, check_flyable, estimated_flight_m, estimated_flight_s,
                       fly_mission)
from ..upload import to_wire, upload_mission
from ..upload.connection import read_signing_key
from .console import note, record, say
from .options import progress_reporter


def run_upload(mission, connection: str, via: str, verify: bool, signing_key_file: str | None,
               heartbeat_timeout_s: float | None = None, designed_for=None,
               transfer_timeout_s: float | None = None) -> None:
    """Upload with a progress bar and print what happened (shared with ``plan --upload``)."""
    key = read_signing_key(signing_key_file) if signing_key_file else None
    progress, close = progress_reporter("uploading")
    slots = len(to_wire(mission))
    if not mission.autopilot_stated:      # the vehicle's autopilot decides the home slot
        what = f"{len(mission.items)} mission items (and a home slot if the vehicle is ArduPilot)"
    elif slots > len(mission.items):
        what = f"{len(mission.items)} mission items and the home slot ({slots} mission slots)"
    else:
        what = f"{len(mission.items)} mission items ({slots} mission slots)"
    say(f"uploading {what} to {connection} via {via}")
    sent = [0]

    def counted(done: int, total: int, resent: int | None = None) -> None:
        sent[0] = done
        progress(done, total, resent)
    try:
        report = upload_mission(mission, connection, via=via, verify=verify, signing_key=key,
                                progress=counted, heartbeat_timeout_s=heartbeat_timeout_s,
                                designed_for=designed_for, timeout_s=transfer_timeout_s)
    except KeyboardInterrupt:
        close()
        raise Interrupted(_interrupted_holds(mission, sent[0], slots)) from None
    finally:
        close()
    for warning in report.warnings:
        note(f"warning: {warning}")
    fresh = f", {report.fresh_starts} fresh starts" if report.fresh_starts else ""
    line = (f"the vehicle accepted {report.items} mission slots in {report.seconds:.2f} s "
            f"({report.resent} messages resent{fresh})")
    say(line + ("; downloaded back: it holds exactly the planned mission" if report.verified
                else "; not verified (--no-verify)"))
    for part in report.parts:
        say(f"  {part}")
    if report.note:
        note(report.note)
    record(upload={"via": report.via, "mission_slots": report.items, "seconds": report.seconds,
                   "transfer_s": report.transfer_s, "resent": report.resent,
                   "fresh_starts": report.fresh_starts, "verified": report.verified,
                   "round_trip_s": report.round_trip_s, "parts": list(report.parts)})


class Interrupted(click.ClickException):
    """Ctrl-C during an upload: what the vehicle may hold, exit 130 (as for SIGINT)."""

    exit_code = 130


def _interrupted_holds(mission, sent: int, slots: int) -> str:
    """What a vehicle holds after an upload stopped with ``sent`` of ``slots`` items sent."""
    from ..autopilot.commands import Autopilot
    if sent == 0:
        return ("interrupted before any mission item was sent: the vehicle keeps the mission it "
                "held (if it had begun a transfer, it gives it up by itself)")
    if mission.autopilot == Autopilot.PX4:
        return (f"interrupted after {sent} of {slots} items were sent: PX4 stores an upload "
                "only once it is complete, so it keeps the mission it held")
    return (f"interrupted after {sent} of {slots} items were sent: ArduPilot writes items as "
            "they arrive, so the vehicle may hold the first of them over the end of its earlier "
            "mission -- do not fly it; upload again (or download it to see what it holds)")


def run_flight_check(mission, targets, airframe, via: str, speedup: float,
                     max_miss_m: float | None, max_items: int | None = None,
                     wind=None) -> FlightCheck:
    """Fly, print the report, and fail (exit 1) when ``max_miss_m`` is exceeded (shared with
    ``plan --simulate``).  A mission the simulator cannot fly as the autopilot would
    (:func:`~dtsp_mission.sim.fly.check_flyable`) is refused before anything flies."""
    check_flyable(mission, airframe)
    _say_estimate(mission, airframe, speedup)
    progress, close = progress_reporter("flying")
    try:
        check = fly_mission(mission, targets, airframe, via=via, speedup=speedup, max_items=max_items,
                            wind=wind or CALM,
                            progress=lambda stage, done, total: progress(done, total)
                            if stage == "flight" else None)
    finally:
        close()
    print_check(check)
    if check.lost_reports:
        raise click.ClickException(
            f"{check.lost_reports} of the vehicle's {check.samples + check.lost_reports} position "
            f"reports did not arrive (the link could not keep up at --speedup {speedup:g}): the "
            "misses above are measured on a track with holes; fly again with a lower --speedup")
    if max_miss_m is not None and check.max_miss_m > max_miss_m:
        raise click.ClickException(f"a target was missed by {check.max_miss_m:.1f} m, more than "
                                   f"--max-miss {max_miss_m:g} m")
    return check


def _say_estimate(mission, airframe, speedup: float) -> None:
    """Say up front how long the flight will take (flight time, and the wait at ``speedup``)."""
    length = estimated_flight_m(mission, airframe.loiter_radius_m)
    flight_s = estimated_flight_s(mission, airframe)
    wait = (f"about {_duration(flight_s / speedup)} to simulate at --speedup {speedup:g}"
            if speedup > 0 else "simulated as fast as it computes")
    say(f"flying about {length / 1000:,.1f} km, {_duration(flight_s)} of flight; {wait}")


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    minutes = int(round(seconds / 60))
    return f"{minutes // 60} h {minutes % 60:02d} min" if minutes >= 60 else f"{minutes} min"


def print_check(check: FlightCheck) -> None:
    minutes = check.flight_time_s / 60
    state = "completed" if check.completed else "NOT completed"
    record(flight={"completed": check.completed, "items_reached": check.items_reached,
                   "items": check.items, "flight_time_s": check.flight_time_s,
                   "min_turn_radius_m": check.min_turn_radius_m, "position_reports": check.samples,
                   "targets": [{"name": name, "miss_m": miss,
                                "altitude_error_m": altitude if np.isfinite(altitude) else None}
                               for name, miss, altitude in zip(check.names, check.miss_m,
                                                               check.altitude_error_m)],
                   "max_miss_m": check.max_miss_m})
    say(f"simulated flight {state}: {check.items_reached} of {check.items} items, "
               f"{minutes:.1f} min of flight ({'NPFG' if check.airframe.autopilot == 'px4' else 'L1'} "
               f"period {check.airframe.l1_period_s:g} s, "
               f"min turn radius {check.airframe.tightest_turn_m:.0f} m)")
    say(f"uploaded via {check.upload.via} in {check.upload.seconds:.2f} s; "
               f"{check.samples} position reports received")
    say(f"smallest turn radius in the telemetry: {check.min_turn_radius_m:.1f} m")
    if len(check.miss_m):
        say(f"targets passed within: median {np.median(check.miss_m):.2f} m, max "
                   f"{check.max_miss_m:.2f} m")
        say("target\tmiss_m\taltitude_error_m")
        for name, miss, altitude in zip(check.names, check.miss_m, check.altitude_error_m):
            say(f"{name}\t{miss:.2f}\t" + (f"{altitude:+.1f}" if np.isfinite(altitude)
                                            else "-"))    # no altitude given for the target
