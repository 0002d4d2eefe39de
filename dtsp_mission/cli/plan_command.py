"""``dtsp-mission plan``: the main job -- targets in, checked tour and mission files out."""

from __future__ import annotations

import math
import os
from dataclasses import replace
from pathlib import Path

import click
import numpy as np

from ..export import exporter_for
from ..errors import DtspError
from ..files import check_replaceable, write_together
from ..mission import Autopilot, DesignTuning, MissionSettings
from ..mission.widening import targets_beyond
from ..mission.sorties import sortie_path
from ..pipeline import PlanRequest, PlanResult, check_request, run_plan
from ..planning import planners
from ..planning.base import MERGE_RESOLUTION_RHO
from ..planning.rbta import region_heading_deg
from ..map import require_bokeh
from ..plot import plot_format, render_plan, require_matplotlib
from ..targets import GeoTargets, Targets, random_targets, read_targets
from ..targets.model import target_name
from ..targets.random_area import check_random_area
from ..targets.actions import TargetActions, check_loiter_turns
from ..targets.geojson_file import read_geojson
from . import console
from .console import console_options, note, record, say
from .options import (FiniteFloatRange, LAT_LON, LIMITS, UserError, airframe_from, apply,
                      designed_for as designed_for_file, link_options, mission_options,
                      mission_settings, progress_reporter, reports_errors, seed_option,
                      simulation_options, turn_radius_from, vehicle_options)
from .runs import run_flight_check, run_upload


def _check_writable(paths, inputs=()) -> None:
    """UserError, before any work, for an output whose folder does not exist or is not
    writable, two outputs to the same file, or an output that is one of the ``inputs``."""
    seen = set()
    read = {Path(path).resolve(): path for path in inputs if path and path != "-"}
    for path in paths:
        resolved = Path(path).resolve()
        if resolved in seen:
            raise UserError(f"{path} is given twice as an output")
        if resolved in read or (resolved.exists() and any(
                resolved.samefile(other) for other in read if other.exists())):
            raise UserError(f"{path} is an input of this run ({read.get(resolved, path)}); "
                            "writing it would replace what it was planned from: choose another "
                            "output name")
        seen.add(resolved)
        try:
            check_replaceable(path)
        except DtspError as error:
            raise UserError(str(error)) from None
        folder = resolved.parent
        if not folder.is_dir():
            raise UserError(f"{path}: the folder {folder} does not exist")
        if not os.access(folder, os.W_OK):
            raise UserError(f"{path}: the folder {folder} is not writable")


def _targets(targets_file: str | None, random_count: int | None, area_file: str | None,
             seed: int, rho_m: float) -> GeoTargets | Targets:
    if random_count is not None and targets_file is not None and area_file is not None:
        raise UserError(f"give either a TARGETS_FILE ({targets_file}) or --random N with --area, "
                        "not both: --random draws its own targets")
    if random_count is None:
        if targets_file is None:
            raise UserError("give a TARGETS_FILE, or --random N with --area")
        targets = read_targets(targets_file)
        if area_file is not None:
            if not isinstance(targets, GeoTargets):
                raise UserError("--area needs targets in lat/lon")
            targets = targets.with_area(_area(area_file))
        return targets
    if area_file is None and targets_file is None:
        raise UserError("--random needs a survey area: --area AREA.geojson (a Polygon)")
    source = read_geojson(area_file or targets_file)
    if source.area_deg is None:
        raise UserError(f"{area_file or targets_file}: no Polygon feature to draw --random targets in")
    if len(source) and area_file is None:
        raise UserError(f"{targets_file} holds targets; --random draws its own (use --area)")
    check_random_area(source.area_deg, rho_m, f"--area {area_file or targets_file}")
    return random_targets(source.area_deg, random_count, seed)


def _area(area_file: str) -> np.ndarray:
    area = read_geojson(area_file).area_deg
    if area is None:
        raise UserError(f"{area_file}: no Polygon feature (the survey area)")
    return area


def _duration(seconds: float) -> str:
    minutes = int(round(seconds / 60))
    return f"{minutes // 60} h {minutes % 60:02d} min" if minutes >= 60 else f"{seconds / 60:.1f} min"


@click.command()
@click.argument("targets_file", required=False, type=click.Path(dir_okay=False))
@click.option("--random", "random_count", type=LIMITS["count"], metavar="N",
              help="Plan through N seeded uniform random targets inside the --area polygon.")
@click.option("--area", "area_file", type=click.Path(dir_okay=False), metavar="AREA.geojson",
              help="Survey area (a GeoJSON Polygon): for --random, the lower bound and the plot.")
@seed_option
@click.option("--origin", type=LAT_LON, help="Place targets given in local x/y metres on the "
              "earth: LAT,LON of their (0, 0).")
@apply(vehicle_options)
@apply(mission_options)
@click.option("--algorithm", default="auto", show_default=True,
              help="Planner: " + ", ".join(sorted(planners())) + ".")
@click.option("--region", default="bounding", show_default=True,
              help="Rectangle the bead tiling covers: 'bounding', 'min-area', or a sweep "
                   "heading in degrees counter-clockwise from east.")
@click.option("--time-limit", "time_limit_s", type=FiniteFloatRange(min=0.0, max=86400.0), default=None,
              metavar="SECONDS",
              help="Work budget of auto's improvement stage, in seconds of the reference machine "
                   "(a fixed amount of work: the same input, limit and --seed give the same tour "
                   "everywhere). Default 7 s up to 2,000 targets, 2.8 ms more per target "
                   "above, at most 30 s; 0 keeps the best peer's tour.")
@click.option("--fallback/--no-fallback", default=True, show_default=True,
              help="If the RBTA cannot tile (too few targets), plan with the Alternating "
                   "Algorithm instead of failing.")
@click.option("-o", "--output", "outputs", multiple=True, type=click.Path(dir_okay=False),
              help="Write here; the format follows the extension (.plan, .waypoints, .geojson, "
                   ".json tour) unless --format says. Repeatable.")
@click.option("--format", "format_name", help="Output format for every -o, whatever its extension.")
@click.option("--map", "map_file", type=click.Path(dir_okay=False), metavar="FILE.html",
              help="An interactive map of the mission, one self-contained HTML file: targets "
                   "coloured by the predicted miss, the planned path, the mission items in order, "
                   "take-off, the return, the survey area and a geofence (-o *.fence.plan); "
                   "base map from public tile servers when online, the overlay offline too.")
@click.option("--plot", "plot_file", type=click.Path(dir_okay=False), metavar="FILE",
              help="Draw targets, path and waypoints to this picture (.png, .svg, .pdf, .jpg).")
@click.option("--upload", "connection", metavar="CONNECTION",
              help="Upload the mission to this vehicle (udpout:HOST:PORT, ...; see "
                   "`dtsp-mission upload`): its navigation parameters, home and wind estimate are "
                   "read first and the mission designed for them (as with --from-vehicle), then "
                   "uploaded before the files are written.")
@click.option("--from-vehicle", "vehicle_connection", metavar="CONNECTION",
              help="Read the vehicle's navigation parameters, home and (ArduPilot) wind estimate "
                   "over this link and design the mission for them, without uploading; each "
                   "value read is reported.  --home, --home-amsl, --wind and --l1-period given "
                   "still win; --autopilot must be the vehicle's.")
@apply(link_options)
@click.option("--endurance", "endurance_min", type=FiniteFloatRange(min=0.0, min_open=True),
              metavar="MINUTES", help="Longest flight the aircraft can make (take-off to the "
              "return, at --airspeed): a longer mission is split into sorties that each fit.")
@click.option("--photo", is_flag=True, help="Take a picture at every target when it is overflown "
              "(ArduPilot DO_DIGICAM_CONTROL, PX4 IMAGE_START_CAPTURE); a 'photo' column "
              "chooses targets.")
@click.option("--roi", is_flag=True, help="Point the camera at each target from the previous one "
              "on (DO_SET_ROI / DO_SET_ROI_LOCATION), off after the last; a 'roi' column chooses "
              "targets.")
@click.option("--gimbal-pitch", "gimbal_pitch_deg", type=LIMITS["pitch"], metavar="DEG",
              help="Gimbal pitch for targets without a 'gimbal_pitch' of their own (-90 looks "
                   "straight down; DO_MOUNT_CONTROL / DO_GIMBAL_MANAGER_PITCHYAW).")
@click.option("--loiter", "loiter_specs", multiple=True, metavar="TARGET[:TURNS]",
              help="Circle this target (a name from the file or a 1-based number) TURNS whole "
                   "times (default 1) before going on: circles through the target, tangent to "
                   "the tour. Repeatable; a 'loiter_turns' column does the same.")
@click.option("--loiter-radius", "loiter_radius_m", type=LIMITS["distance"], metavar="METRES",
              help="Radius of the loiter circles (default 1.3 x the turn radius).")
@click.option("--max-aim-offset", "max_aim_offset_m", type=LIMITS["distance"], metavar="METRES",
              help="--design guidance: aim each target's waypoint no farther than this from it "
                   "(default: as far as the design needs). Far aims hold targets through the "
                   "guidance's modelled overshoot, which the real autopilot varies: 15 m took ten "
                   "real ArduPlane flights from 29 targets beyond 5 m to 10, at a longer flight "
                   "on some sites (docs/missions.md).")
@click.option("--simulate", is_flag=True, help="Fly the mission in the simulator (an ArduPlane "
              "with --vehicle-params, stock without) and print per-target miss distances.")
@apply(simulation_options)
@apply(console_options)
@reports_errors
def plan(targets_file, random_count, area_file, seed, origin, rho_m, airspeed_m_s, max_bank_deg,
         altitude_m, min_altitude_m, home_deg, home_altitude_amsl_m, launch_bearing_deg, landing_bearing_deg, autopilot,
         return_mode, design, max_miss_m, wind_spread_m_s, tolerance_m, max_items, algorithm, region, time_limit_s,
         fallback, outputs, format_name,
         map_file, plot_file, connection, vehicle_connection, via, verify, signing_key_file, transfer_timeout_s, endurance_min,
         photo, roi, gimbal_pitch_deg, loiter_specs, loiter_radius_m, max_aim_offset_m, simulate, speedup,
         vehicle_params_file, l1_period_s, wind, quiet, as_json) -> None:
    """Plan a Dubins tour through the targets and write it as a mission.

    TARGETS_FILE: CSV with lat,lon columns (optional alt, name), or local x,y metres (with
    --origin to place them), or GeoJSON Point features (a Polygon feature is the survey area).
    Optional columns (or properties) photo, roi, gimbal_pitch and loiter_turns set the actions
    at each target, written in the forms ArduPilot and PX4 each accept.

    Example: dtsp-mission plan examples/site-inspection.csv --radius 80 --alt 120 -o mission.plan
    """
    console.start(quiet, as_json)
    writers = [(output, exporter_for(output, format_name)) for output in outputs]
    if plot_file:
        require_matplotlib()
        plot_format(plot_file)
    inputs = (targets_file, area_file, vehicle_params_file, signing_key_file)
    if map_file:
        require_bokeh()
        if Path(map_file).suffix.lower() not in (".html", ".htm"):
            raise UserError(f"--map {map_file}: the map is an HTML page; name it .html")
    _check_writable([*outputs, *([plot_file] if plot_file else []),
                     *([map_file] if map_file else [])], inputs)
    if algorithm in ("rbta", "auto") and region not in ("bounding", "min-area"):
        region_heading_deg(region)
    if connection and vehicle_connection and connection != vehicle_connection:
        raise UserError("--upload and --from-vehicle name two vehicles; the mission is designed "
                        "for the one it is uploaded to: give one")
    if connection or vehicle_connection:
        (autopilot, designed_for, home_deg, home_altitude_amsl_m, wind) = _from_vehicle(
            connection or vehicle_connection, signing_key_file, autopilot, vehicle_params_file,
            l1_period_s, home_deg, home_altitude_amsl_m, wind)
    else:
        designed_for = designed_for_file(vehicle_params_file, autopilot, l1_period_s)
    rho, rho_source = turn_radius_from(rho_m, airspeed_m_s, max_bank_deg,
                                       designed_for if autopilot == "ardupilot" else None)
    targets = _targets(targets_file, random_count, area_file, seed, rho)
    if targets.unused_columns:
        note(f"{targets_file}: columns not used: {', '.join(targets.unused_columns)} (the "
             "columns read are lat/lon or x/y, alt, name, photo, roi, gimbal_pitch and "
             "loiter_turns)")
    if loiter_specs:
        targets = with_loiters(targets, loiter_specs)
    needs_mission = (any(writer.needs_mission for _, writer in writers) or connection or simulate
                     or map_file)
    # Targets on the earth get a mission (a tour-only output checks its storage); local x/y
    # without --origin get the tour only, unless a mission is asked for (then refused).
    settings = None
    if needs_mission or isinstance(targets, GeoTargets) or origin is not None:
        settings = mission_settings(
            vehicle=designed_for, autopilot=autopilot, altitude_m=altitude_m,
            min_altitude_m=min_altitude_m, airspeed_m_s=airspeed_m_s, home_deg=home_deg,
            home_altitude_amsl_m=home_altitude_amsl_m, launch_bearing_deg=launch_bearing_deg,
            landing_bearing_deg=landing_bearing_deg, return_mode=return_mode, design=design,
            max_miss_m=max_miss_m, wind=wind, wind_spread_m_s=wind_spread_m_s,
            tolerance_m=tolerance_m, max_items=max_items, photo=photo, roi=roi,
            gimbal_pitch_deg=gimbal_pitch_deg, loiter_radius_m=loiter_radius_m,
            tuning=(None if max_aim_offset_m is None
                    else DesignTuning(max_aim_offset_m=max_aim_offset_m)))
        if autopilot == "px4" and any(writer.name == "waypoints" for _, writer in writers):
            note("a .waypoints file holds the home in its row 0, as QGroundControl, Mission "
                 "Planner and MAVProxy read it; a tool that sends every row would make it PX4's "
                 "first item: load it in QGroundControl or send it with `dtsp-mission upload` "
                 "(both leave row 0 out for PX4), or write a .plan")
    parameters = {"region": region} if algorithm in ("rbta", "auto") else {}
    if algorithm == "auto":
        parameters.update(time_limit_s=time_limit_s, seed=seed)
    # Only tour files asked for: the mission is not designed (minutes of predicted flights
    # for the guidance design), only checked against the vehicle's storage.  Without any
    # output the mission is designed: its report is what was asked for.
    tour_only = bool(writers) and not (needs_mission or plot_file)
    request = PlanRequest(targets=targets, rho_m=rho, algorithm=algorithm, parameters=parameters,
                          fallback=fallback, origin=origin, settings=settings,
                          too_large="note" if tour_only else "split",
                          endurance_s=endurance_min and endurance_min * 60)
    check_request(request)           # every check of the request, before any planning
    from ..compiled import kernels_cached
    if not kernels_cached():
        note("first run on this machine: compiling the planning kernels (about a minute, "
             "once; later runs start at once)")
    say(f"{len(targets)} targets; {rho_source}")
    progress, close_progress = progress_reporter("improving the tour")
    designing, close_designing = progress_reporter("designing the waypoints for the guidance")

    def design_progress(fraction: float) -> None:
        close_progress()                    # the tour is done: its bar ends before this one
        designing(int(1000 * fraction), 1000)
    try:
        result = run_plan(request, lambda fraction: progress(int(1000 * fraction), 1000),
                          design_progress)
    finally:
        close_progress()
        close_designing()
    record(targets=len(result.local), rho_m=rho)
    _report(result, settings, airspeed_m_s)
    product = result.product
    sorties = result.sorties
    if sorties and connection:
        raise UserError(f"the mission is split into {len(sorties)} sorties (one file each); "
                        "upload them one at a time with `dtsp-mission upload FILE`")
    # All or nothing: every output is rendered and staged beside its target; the upload (if
    # asked) runs before they are renamed into place, so a failed upload leaves no new file.
    rendered = []
    frame = result.frame
    for output, writer in writers:
        if sorties and writer.needs_mission:
            rendered += [(sortie_path(output, k + 1), writer.description,
                          writer.render_for(sortie.mission, sortie_path(output, k + 1)))
                         for k, sortie in enumerate(sorties)]
        else:
            rendered.append((output, writer.description, writer.render_for(product, output, frame)))
    if sorties:
        _check_writable([path for path, _, _ in rendered], inputs)
    stale = _stale_sorties([(output, writer) for output, writer in writers if writer.needs_mission],
                           {str(path): content for path, _, content in rendered})
    if map_file:
        from ..map import render_map
        fences = [fence for _, writer in writers if hasattr(writer, "geofence_deg")
                  for fence in writer.geofence_deg(product)]
        area = result.geodetic.area_deg if result.geodetic is not None else None
        rendered.append((map_file, "map", render_map(product, max_miss_m, area, fences)))
    if plot_file:
        rendered.append((plot_file, "plot", render_plan(product, plot_format(plot_file),
                                                         result.area_m)))
    upload = None
    if connection:

        def upload() -> None:
            run_upload(product.for_vehicle(), connection, via, verify, signing_key_file,
                       designed_for=designed_for, transfer_timeout_s=transfer_timeout_s)
    write_together([(output, content) for output, _, content in rendered], before_commit=upload,
                   remove=stale)
    for output, description, _ in rendered:
        say(f"wrote {output} ({description})")
        if description in ("plot", "map"):
            record(**{description: str(output)})
        else:
            console.current().summary.setdefault("files", []).append(str(output))
    for path in sorted(stale):
        say(f"removed {path} (written by an earlier run for this output, no longer current)")
        console.current().summary.setdefault("removed", []).append(str(path))
    if simulate:
        from ..sim.fly import planned_targets
        airframe, _, _ = airframe_from(vehicle_params_file, airspeed_m_s, None, l1_period_s,
                                       autopilot=product.autopilot)
        for k, flown in enumerate([s.mission for s in sorties] or [product]):
            if sorties:
                say(f"sortie {k + 1} of {len(sorties)}:")
            run_flight_check(flown.for_vehicle(), planned_targets(flown), airframe, via,
                             speedup, max_miss_m, max_items, wind)
            console.current().summary.setdefault("simulated", []).append(console.current().summary.pop("flight"))
    console.finish()


def _from_vehicle(connection, signing_key_file, autopilot, vehicle_params_file, l1_period_s,
                  home_deg, home_amsl_m, wind):
    """What the mission is designed for, read from the vehicle before anything is designed:
    (autopilot, navigation parameters, home, home AMSL, wind), each value read reported;
    what the user gave explicitly (--home, --home-amsl, --wind, --l1-period) wins.
    UserError when the vehicle does not answer or is not the autopilot asked for."""
    from ..autopilot.navigation import Wind
    from ..autopilot.parameters import checked_parameters
    from ..upload import read_vehicle
    from ..upload.connection import read_signing_key
    key = read_signing_key(signing_key_file) if signing_key_file else None
    try:
        info = read_vehicle(connection, key)
    except DtspError as error:
        raise UserError(f"reading the vehicle before the design: {error}") from None
    flavour = "px4" if info.autopilot == Autopilot.PX4 else "ardupilot"
    explicit = click.get_current_context().get_parameter_source("autopilot")
    if flavour != autopilot and explicit != click.core.ParameterSource.DEFAULT:
        raise UserError(f"the vehicle at {connection} runs {'PX4' if flavour == 'px4' else 'ArduPilot'}, "
                        f"not --autopilot {autopilot}: plan for the vehicle it will fly")
    read = [f"{'PX4' if flavour == 'px4' else 'ArduPilot'}"]
    unread = [name for name in info.asked if name not in info.parameters]
    parameters = checked_parameters(flavour, info.parameters, f"the vehicle at {connection}")
    if info.parameters:
        read.append(", ".join(f"{name} {value:g}" for name, value in info.parameters.items()))
    if unread:
        note(f"could not read {', '.join(unread)} from the vehicle in time: designed with the "
             "stock values")
    if vehicle_params_file:
        note(f"--vehicle-params {vehicle_params_file} set aside: the mission is designed for the "
             "parameters the vehicle has")
    if l1_period_s is not None:
        parameters = replace(parameters, **{"NPFG_PERIOD" if flavour == "px4" else
                                            "NAVL1_PERIOD": l1_period_s})
    if info.home_deg is not None:
        read.append(f"home {info.home_deg[0]:.7f},{info.home_deg[1]:.7f}"
                    + (f" at {info.home_amsl_m:.1f} m AMSL" if info.home_amsl_m is not None else ""))
        source = click.get_current_context().get_parameter_source("home_altitude_amsl_m")
        if home_deg is None:
            home_deg = info.home_deg
            if info.home_amsl_m is not None and source == click.core.ParameterSource.DEFAULT:
                home_amsl_m = info.home_amsl_m
        else:
            note("--home given: the vehicle's home is not used")
    else:
        note("the vehicle reported no home (no position fix yet?)")
    if info.wind is not None:
        speed, from_deg = info.wind
        read.append(f"wind estimate {speed:.1f} m/s from {from_deg:.0f} deg")
        if wind is None and speed >= 0.5:
            wind = Wind(round(speed, 1), round(from_deg) % 360.0)
        elif wind is None:
            note("the vehicle's wind estimate is calm (ArduPilot estimates the wind in flight "
                 "only): designed for calm air; give --wind from a forecast if there is wind")
        elif wind is not None:
            note(f"--wind {wind} given: the vehicle's estimate is not used")
    say(f"read from the vehicle at {connection}: " + "; ".join(read))
    record(vehicle_read={"autopilot": flavour, "parameters": info.parameters,
                         "home_deg": info.home_deg, "home_amsl_m": info.home_amsl_m,
                         "wind": info.wind, "not_read": unread})
    return flavour, parameters, home_deg, home_amsl_m, wind


def _sortie_family(output: str) -> list[Path]:
    """The files that are, by their names, sorties of ``output`` (``mission-<k>.plan``
    beside ``mission.plan``), and ``output`` itself, as they exist now."""
    import re
    base = Path(sortie_path(output, 0))
    pattern = re.compile(re.escape(base.name).replace("\\-0", "-([1-9][0-9]*)", 1) + "$")
    family = [path for path in base.parent.glob("*") if pattern.match(path.name)]
    return family + ([Path(output)] if Path(output).exists() else [])


def _written_by_us(path: Path, fresh: str | bytes | None) -> bool:
    """Whether ``path`` is a mission file dtsp-mission wrote (its marks: a .plan's
    groundStation, a GeoJSON's generator, a tour's format; a .waypoints, which has no room for
    a mark, when its home line is the one written now)."""
    try:
        with open(path, "rb") as stream:
            head = stream.read(1 << 16).decode("utf-8", "replace")
    except OSError:
        return False
    marks = ('"groundStation": "dtsp-mission"', '"generator": "dtsp-mission"',
             '"format": "dtsp-mission/tour"')
    if any(mark in head for mark in marks):
        return True
    if head.startswith("QGC WPL 110") and isinstance(fresh, str):
        return head.splitlines()[1:2] == fresh.splitlines()[1:2]
    return False


def _stale_sorties(writers, fresh: dict[str, str | bytes]) -> list[Path]:
    """The files of earlier runs that this run's mission outputs make stale (sorties of the
    same output it does not write again, or the single file a split run replaces by sorties),
    to be removed with the write; UserError for a file this run would write over that
    dtsp-mission did not write as one of them."""
    stale = []
    written = {Path(path).resolve() for path in fresh}
    for output, _ in writers:
        for path in _sortie_family(output):
            ours = _written_by_us(path, fresh.get(str(path)) or next(iter(fresh.values()), None))
            if path.resolve() in written:
                if path.resolve() != Path(output).resolve() and not ours:
                    raise UserError(f"{path} exists and is not a sortie file dtsp-mission wrote "
                                    f"for {output}: this run's sortie would replace it; move it "
                                    "or choose another output name")
            elif ours and path.is_file():
                stale.append(path)
    return stale


def with_loiters(targets, specs: tuple[str, ...]):
    """The targets with ``--loiter TARGET[:TURNS]`` applied: TARGET a name from the targets
    file or a 1-based number, TURNS whole circles (default 1)."""
    names = targets.names or ()
    turns: dict[int, int] = {}
    for spec in specs:
        label, _, count = spec.rpartition(":") if ":" in spec else (spec, "", "1")
        index = _target_index(label.strip(), names, len(targets))
        try:
            number = float(count)
        except ValueError:
            raise UserError(f"--loiter {spec}: TURNS must be a whole number, got {count!r}") from None
        turns[index] = check_loiter_turns(number, f"--loiter {spec}")
    base = targets.actions if targets.actions is not None else TargetActions.none(len(targets))
    return replace(targets, actions=base.with_options(loiter_turns=turns))


def _target_index(label: str, names: tuple[str, ...], count: int) -> int:
    if label in names:
        rows = [k + 1 for k, name in enumerate(names) if name == label]
        if len(rows) > 1:
            raise UserError(f"--loiter {label!r}: {len(rows)} targets have that name (numbers "
                            f"{', '.join(map(str, rows))}); give the number of the one to circle")
        return names.index(label)
    if label.isdigit() and 1 <= int(label) <= count:
        return int(label) - 1
    known = f" or a name from the file (e.g. {names[0]})" if names else ""
    raise UserError(f"--loiter {label!r}: no such target; give a number from 1 to {count}{known}")


def _report(result: PlanResult, settings: MissionSettings | None,
            airspeed_m_s: float | None) -> None:
    """What the plan did, on the console (and in the --json summary)."""
    _report_tour(result)
    for text in result.notes:
        note(text)
    if result.mission is not None:
        _report_mission(result.mission)
        _report_wind_tour(result)
        _warn_far_home(result.mission, result.local.positions_m, result.frame)
    elif settings is None and airspeed_m_s:
        say(f"flight time of the tour at {airspeed_m_s:g} m/s: "
            f"{_duration(result.tour.length_m / airspeed_m_s)}")
    if result.sorties:
        _report_sorties(result, settings.max_miss_m)


def _report_wind_tour(result: PlanResult) -> None:
    """The tour flown in the forecast wind, against the calm tour and the designed flight."""
    windy, mission = result.wind_tour, result.mission
    if windy is None:
        return
    calm_s = result.tour.length_m / windy.airspeed_m_s
    line = (f"tour in the forecast wind: {_duration(windy.time_s)} at {windy.airspeed_m_s:g} m/s "
            f"(calm air: {_duration(calm_s)}; headings and order improved for the wind)")
    flight_s = mission.guidance.predicted_flight_s if mission.guidance is not None else math.nan
    if math.isfinite(flight_s):
        line += (f"; the mission's predicted flight (take-off to the last target) "
                 f"{_duration(flight_s)}, {flight_s / windy.time_s:.2f} x the tour")
    say(line)
    record(wind_tour_time_s=windy.time_s, wind_tour_air_length_m=windy.air_length_m)


def _report_sorties(result: PlanResult, max_miss_m: float) -> None:
    """The sorties of a mission too large or too long for the vehicle."""
    sorties = result.sorties
    record(sorties=[{"targets": len(s.targets), "items": s.mission.summary["items"],
                     "flight_length_m": s.mission.summary["flight_length_m"],
                     "flight_time_s": s.mission.summary.get("flight_time_s")} for s in sorties])
    say(f"{result.split_reason}: split into {len(sorties)} sorties, each a take-off, a contiguous "
        "part of the tour and the return, balanced by flight time:")
    names = result.geodetic.names
    for k, sortie in enumerate(sorties):
        summary = sortie.mission.summary
        first, last = sortie.targets[0], sortie.targets[-1]
        label = (lambda i: target_name(names, i))
        time_text = (f", {_duration(summary['flight_time_s'])}" if "flight_time_s" in summary
                     else "")
        beyond = targets_beyond(sortie.mission)
        again = sortie.mission.guidance.revisit_waypoints if sortie.mission.guidance else 0
        say(f"  sortie {k + 1}: {len(sortie.targets)} targets ({label(first)} .. "
            f"{label(last)}), {summary['items']} items, "
            f"{summary['flight_length_m'] / 1e3:,.2f} km{time_text}"
            + (f", {again} passing a target again" if again else "")
            + (f", {beyond} predicted beyond the design limit" if beyond else ""))


#: A home farther than this from every target is worth a second look.
FAR_HOME_M = 10_000.0


def _warn_far_home(mission, targets_m: np.ndarray, frame) -> None:
    """A note when home (or the launch point) is far from every target: a wrong --home
    (swapped lat/lon, another site) shows up before the flight, not in it."""
    home_m = frame.to_local(np.array([mission.home.latitude_deg]),
                            np.array([mission.home.longitude_deg]))[0]
    nearest = float(np.hypot(*(targets_m - home_m).T).min())
    if nearest > FAR_HOME_M:
        note(f"home is {nearest / 1000:.1f} km from the nearest target: is --home right? "
             "(the transit there and back is part of every flight)")


def _report_tour(result: PlanResult) -> None:
    tour, bound, elapsed = result.tour, result.bound, result.planning_s
    say(f"planner {tour.planner}: tour {tour.length_m:,.1f} m ({elapsed:.2f} s)")
    record(planner=tour.planner, tour_length_m=tour.length_m, planning_s=elapsed,
           lower_bound_m=bound.one_tree_m)
    if tour.report.get("merged_targets"):
        note(f"{tour.report['merged_targets']} targets lie within "
                   f"{MERGE_RESOLUTION_RHO:g} rho of another and are visited as one")
    if bound.one_tree_m > 1e-3 * tour.rho_m:
        say(f"  certified lower bound (1-tree) {bound.one_tree_m:,.1f} m: ratio "
            f"{tour.length_m / bound.one_tree_m:.3f}; estimate for uniform targets "
            f"{bound.stochastic_m:,.1f} m: ratio {tour.length_m / bound.stochastic_m:.3f}")
    else:       # (nearly) one point: any closed tour is a turn circle, and no ratio means much
        say(f"  certified lower bound (1-tree) {bound.one_tree_m:,.1f} m: the targets are as "
            "good as one point, the tour one turn through it; no ratio to report")
    for phase in tour.report.get("phases", []):
        say(f"  phase {phase['phase']}: meta-beads of {phase['meta_bead_beads'][0]}x"
                   f"{phase['meta_bead_beads'][1]} beads, {phase['serviced']} targets, "
                   f"{phase['length_m']:,.1f} m")
    for name, result in tour.report.get("candidates", {}).items():
        shown = f"{result:,.1f} m" if isinstance(result, float) else result
        say(f"  candidate {name}: {shown}")
    improvement = tour.report.get("improvement")
    if improvement and not improvement["start_m"] > 0:
        say(f"  improvement: none ({improvement['stopped']})")
    elif improvement:
        gain = (1.0 - improvement["length_m"] / improvement["start_m"]
                if improvement["start_m"] > 0 else 0.0)
        spent = improvement["evaluations"] / max(improvement["budget"], 1)
        say(f"  improvement: {improvement['start_m']:,.1f} m -> {improvement['length_m']:,.1f} m "
                   f"({100 * gain:.1f} % shorter; {improvement['kicks']} perturbations, "
                   f"{100 * min(spent, 1.0):.0f} % of the --time-limit budget, "
                   f"{'stopped by the budget' if improvement['stopped'] == 'budget' else improvement['stopped']})")
    if "leftovers" in tour.report:
        say(f"  leftovers (Alternating Algorithm): {tour.report['leftovers']} targets, "
                   f"{tour.report['leftover_length_m']:,.1f} m")


def _wind_text(wind: tuple[float, float]) -> str:
    speed, from_deg = wind
    return "calm" if speed == 0 else f"in a wind of {speed:g} m/s from {from_deg:g} deg"


def _report_mission(mission) -> None:
    summary, guidance = mission.summary, mission.guidance
    flavour = "ArduPilot" if mission.autopilot == Autopilot.ARDUPILOTMEGA else "PX4"
    if guidance is not None:
        misses = guidance.predicted_miss_m
        say(f"mission ({flavour}): {summary['items']} items ({summary['items'] / len(misses):.2f} "
            f"per target, {guidance.shaping_waypoints} shaping waypoints"
            f"{f', {guidance.revisit_waypoints} passing a target again' if guidance.revisit_waypoints else ''}), "
            f"{summary['vehicle_slots']} vehicle slots; designed for the autopilot's "
            f"guidance: targets passed within median {np.median(misses):.1f} m, max "
            f"{misses.max():.1f} m in the flight model, {_wind_text(guidance.design_wind)}")
        say(f"  predicted flight {guidance.predicted_flight_m / 1e3:,.2f} km against "
            f"{guidance.planned_flight_m / 1e3:,.2f} km of exact path (take-off to the "
            "last target, and its loiter if it has one)")
        slowed = [item.params[1] for item in mission.items if item.role == "speed"][1:]
        slow = [v for v in slowed if v < (mission.cruise_speed_m_s or max(slowed, default=0.0))]
        if slow:
            say(f"  {len(slow)} slow zones (DO_CHANGE_SPEED to {min(slow):g} m/s and back) "
                "before targets the guidance holds better slower")
        record(slow_zones=len(slow))
    else:
        say(f"mission ({flavour}): {summary['items']} items, {summary['vehicle_slots']} "
            f"vehicle slots; waypoints within {mission.tolerance_m:.2f} m of the exact path")
    record(autopilot=flavour, items=summary["items"], mission_slots=summary["vehicle_slots"],
           flight_length_m=summary["flight_length_m"], flight_time_s=summary.get("flight_time_s"))
    if guidance is not None:
        record(predicted_miss_m=summary["predicted_miss_m"],
               predicted_flight_m=guidance.predicted_flight_m, design_wind=summary["design_wind"])
    if "actions" in summary:
        say("  actions at the targets: " + ", ".join(f"{count} {role}" for role, count in
                                                      summary["actions"].items()))
        record(actions=summary["actions"])
    line = f"flight: {summary['flight_length_m'] / 1e3:,.2f} km from take-off to the return"
    if "flight_time_s" in summary:
        line += f", {_duration(summary['flight_time_s'])} at {mission.cruise_speed_m_s:g} m/s"
        if guidance is not None and guidance.design_wind[0] > 0:
            line += (f" {_wind_text(guidance.design_wind)} (the model's time; the climb-out "
                     "and return timed against the wind)")
    say(line)
    for text in mission.notes:
        note(text)

