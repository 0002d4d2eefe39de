"""The project's own missions flown by the real autopilots: ArduPlane SITL and PX4 SITL (SIH).

    python benchmarks/real_flights.py --list
    python benchmarks/real_flights.py --cases 'ardupilot/bundled/*' [--budget-s 540]
    python benchmarks/real_flights.py --markdown docs/real-flights.md

Each case plans a mission with ``dtsp-mission plan`` as an operator would (default design,
``--radius 80 --alt 120``, ArduPlane at 22 m/s, PX4 at 18 m/s, ``--wind`` as flown,
``--vehicle-params`` of the tuning flown), uploads it with the project's uploader to a fresh
SITL autopilot (stock but for the tuning and the wind), flies it in AUTO to the last waypoint
and measures every target's miss against the track -- beside the flight model's prediction
for the same mission, aircraft and wind.  Rows are appended to ``docs/real-flights.csv`` (one
per flight) and ``docs/real-flights-targets.csv`` (one per target); ``--markdown`` writes the
table from them.  Cases already in the CSV are skipped unless ``--again``; a run stops
starting new cases after ``--budget-s`` of wall time, so the whole set runs in parts of under
10 minutes.  Needs the SITL builds (``DTSP_SITL_DIR`` or the workplace's ``shared/``); says
so and exits 0 where they are absent.
"""

from __future__ import annotations

import argparse
import csv
import fnmatch
import hashlib
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from mission_items import CENTRE, _site  # noqa: E402  (one generator of the benchmark sites)

from dtsp_mission.autopilot.navigation import CALM, Airframe, Wind  # noqa: E402
from dtsp_mission.autopilot.parameters import ARDUPLANE_DEFAULTS, PX4_DEFAULTS  # noqa: E402
from dtsp_mission.errors import LinkError  # noqa: E402
from dtsp_mission.export import read_mission  # noqa: E402
from dtsp_mission.sitl import compare_with_model, find_binaries, fly_real  # noqa: E402

CACHE = ROOT / "benchmarks" / ".cache" / "real-flights"
#: What each code digest of the CSV was (the commit whose package planned the missions).
CODES = {"3177ef3": "3177ef3, before the real flights (the baseline)",
         "e2921f1e": "e7c4192: the model flies faster in banks, turns at 0.70",
         "9312f3f9": "c3dab92: and the first target beyond the climb-out",
         "d5ab8b13": "2f7befd: the same (a refactor)",
         "177eeaba": "062c66f: and the design judged with the turn rate 4 % either way",
         "1d43758e": "0d85978: the same design (hostile-input checks, fence upload, map)",
         "36df6a15": "87c805a + the design judged also with the aircraft rolling slower and "
                     "turning 6 % either way (a step, not committed)",
         "42075cb5": "and slow zones (DO_CHANGE_SPEED) before second passes (a step, not committed)",
         "b559873e": "and those flights held 0.5 m within the limit, slow zones also for targets "
                     "held by less than 0.5 m, no wider tours (a step, not committed)",
         "b4e643b5": "596fe8f: the same, and the take-off flown where the vehicle stores it",
         "c868f550": "the first of the two designs without its local repair (2-3 x faster plans)",
         "65f0ec6b": "3efe14e: the same design as c868f550 (the local repair's moves flown on both "
                     "cores)",
         "4448bf84": "9e377aa: one round of slow zones; PX4's SIH flown no faster than 13.9 m/s "
                     "(the PX4 missions designed for it)",
         "4f31b0bf": "6cf0426: the same design as 4448bf84",
         "fb944b1d": "67112a6 with DesignTuning.max_aim_offset_m 15 (a trial: not the default)",
         "c0bfd9c1": "da5baf5 with the 15 m cap in the repair's corrections only, the local "
                     "repair's moves free (a trial: not the default)",
         "fad7332d": "4f08efb: the model's roll rate limited (RLL2SRV_RMAX), its roll response "
                     "refitted with it",
         "a5ab03ce": "the design guarded against flipped outcomes (DesignTuning.flip_*): the "
                     "same design as e5d9e3a3 (a step: its docstring before the figures)",
         "e5d9e3a3": "4383e3b: the model's roll rate limited, the design guarded against flipped "
                     "outcomes",
         "d8c7946b": "the same designs as e5d9e3a3 byte for byte (a review: the slower-roll aircraft "
                     "made in one place, the roll limit's arithmetic only where it applies)",
         "04284164": "7adc74c: the model flies to a waypoint whose leg starts already past it "
                     "(ArduPlane's set_next_WP)",
         "db7151b6": "199f907: and no cross-track on the leg after a take-off (ArduPlane's "
                     "verify_takeoff)",
         "ba1d51b7": "7adc74c without the flip guard (DesignTuning.flip_* 0; a trial: not the "
                     "default)",
         "5466a837": "0128abe-6566c7d: the same designs as db7151b6 (a refactor; ArduPlane's SITL "
                     "flown at 40 x)",
         "f23f08ea": "the same designs, the local repair's trials flying their winds one after "
                     "the other, heaviest first, until the bound is met (the README's plan "
                     "29-31 s instead of 34-35)",
         "3781ba7b": "the same designs as f23f08ea (a review: the heaviest wind read from the "
                     "winds' order, not kept apart)",
         "cd1e4a46": "in a forecast wind, the targets passed twice entered along straights "
                     "planned into the tour (1.2 L1 at the fastest ground speed) where that "
                     "design flies shorter in the model; calm designs as before",
         "3b75b7f3": "ade9835: the model's airspeed after a DO_CHANGE_SPEED as the real SITL "
                     "flies it (the demand at 1.5 / 0.48 m/s^2, a rise followed as a "
                     "second-order response that overshoots): every design with slow zones "
                     "made again"}
#: Digests of trials of design options that are not the default: listed beside the default's
#: latest flight of the case, never as the case's result.
TRIALS = {"fb944b1d": "aims within 15 m",
          "c0bfd9c1": "corrections within 15 m",
          "ba1d51b7": "no flip guard"}
CSV_CASES = ROOT / "docs" / "real-flights.csv"
CSV_TARGETS = ROOT / "docs" / "real-flights-targets.csv"
RHO_M, ALTITUDE_M = 80.0, 120.0
AIRSPEED = {"ardupilot": 22.0, "px4": 18.0}

#: Navigation tunings flown: the two of the recorded set ``arduplane-sitl-tuned`` and one more.
TUNINGS = {
    "stock": {},
    "p18": {"NAVL1_PERIOD": 18, "NAVL1_DAMPING": 0.85, "WP_RADIUS": 80},
    "p12": {"NAVL1_PERIOD": 12, "WP_RADIUS": 30, "ROLL_LIMIT_DEG": 45},
    "p20": {"NAVL1_PERIOD": 20, "WP_RADIUS": 60},
}
SITES = ["bundled", "uniform100", "clustered100", "dense100", "uniform400", "clustered400",
         "dense400"]
WINDS = ["calm"] + [f"{s}@{d}" for s in (5, 8) for d in (0, 90, 180, 270)]


def all_cases() -> list[str]:
    """Case names ``autopilot/site/wind/tuning``: ArduPlane on every site, calm and in 5 and
    8 m/s from four directions, stock; the tunings calm and in 5 m/s from 90; PX4 calm."""
    cases = [f"ardupilot/{site}/{wind}/stock" for site in SITES for wind in WINDS]
    cases += [f"ardupilot/{site}/{wind}/{tuning}" for site in SITES for tuning in TUNINGS
              if tuning != "stock" for wind in ("calm", "5@90")]
    cases += [f"px4/{site}/calm/stock" for site in SITES]
    return cases


def _wind(text: str) -> Wind:
    if text == "calm":
        return CALM
    speed, direction = text.split("@")
    return Wind(float(speed), float(direction))


def _targets_file(site: str) -> Path:
    if site == "bundled":
        return ROOT / "examples" / "site-inspection.csv"
    kind, n = site.rstrip("0123456789"), int(site[len(site.rstrip("0123456789")):])
    path = CACHE / f"{site}.csv"
    if not path.exists():
        targets = _site(kind, n, 0)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("lat,lon,name\n" + "".join(
            f"{la:.8f},{lo:.8f},t{k + 1}\n"
            for k, (la, lo) in enumerate(zip(targets.latitudes_deg, targets.longitudes_deg))))
    return path


def _code_version() -> str:
    """A digest of the package's source: a plan is made again when the code changed."""
    digest = hashlib.sha256()
    for path in sorted((ROOT / "dtsp_mission").rglob("*.py")):
        digest.update(path.read_bytes())
    return digest.hexdigest()


def plan_case(case: str) -> tuple[Path, dict, float]:
    """The case's mission file (planned once, cached by its command), the plan's JSON summary
    and the planning time (s, wall)."""
    autopilot, site, wind, tuning = case.split("/")
    command = [str(ROOT / ".venv" / "bin" / "dtsp-mission") if (ROOT / ".venv").exists()
               else "dtsp-mission", "plan", str(_targets_file(site)), "--radius", f"{RHO_M:g}",
               "--alt", f"{ALTITUDE_M:g}", "--airspeed", f"{AIRSPEED[autopilot]:g}",
               "--autopilot", autopilot, "--json", "-q"]
    if site != "bundled":
        command += ["--home", f"{CENTRE[0]},{CENTRE[1]}"]
    if wind != "calm":
        command += ["--wind", wind]
    if TUNINGS[tuning]:
        parm = CACHE / f"{tuning}.parm"
        parm.parent.mkdir(parents=True, exist_ok=True)
        parm.write_text("".join(f"{k} {v:g}\n" for k, v in TUNINGS[tuning].items()))
        command += ["--vehicle-params", str(parm)]
    key = hashlib.sha256((json.dumps(command[1:]) + _code_version()).encode()).hexdigest()[:16]
    out, summary_file = CACHE / f"{key}.plan", CACHE / f"{key}.json"
    if out.exists() and summary_file.exists():
        summary = json.loads(summary_file.read_text())
        return out, summary, summary.get("_plan_s", math.nan)
    CACHE.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    done = subprocess.run(command + ["-o", str(out)], capture_output=True, text=True, timeout=1800)
    elapsed = time.perf_counter() - started
    if done.returncode not in (0, 1) or not out.exists():
        raise RuntimeError(f"{case}: plan failed: {done.stderr.strip()[-400:]}")
    summary = json.loads(done.stdout)
    summary["_plan_s"] = elapsed
    summary_file.write_text(json.dumps(summary))
    return out, summary, elapsed


def airframe_for(autopilot: str, tuning: str) -> Airframe:
    """The aircraft the model flies for a case: the tuning laid over the stock parameters."""
    if autopilot == "px4":
        return Airframe.from_px4_parameters(PX4_DEFAULTS)
    return Airframe.from_parameters(ARDUPLANE_DEFAULTS.with_values(TUNINGS[tuning]))


CASE_FIELDS = ["case", "autopilot", "site", "wind", "tuning", "targets", "items", "beyond_5m",
               "real_median_m", "real_p95_m", "real_max_m", "model_beyond_5m", "model_max_m",
               "diff_median_m", "diff_p95_m", "diff_max_m", "real_flown_m", "model_flown_m",
               "tour_m", "flown_over_tour", "real_time_s", "model_time_s", "plan_s", "flight_wall_s",
               "worst_target", "when", "code", "tour_time_s", "time_over_tour"]


def run_case(case: str, binaries) -> tuple[dict, list[dict]]:
    autopilot, site, wind_text, tuning = case.split("/")
    plan_file, summary, plan_s = plan_case(case)
    mission = read_mission(str(plan_file), None)
    wind = _wind(wind_text)
    parameters = dict(TUNINGS[tuning])
    flight = fly_real(mission, binaries, parameters, wind)
    # the real track and the mission flown, for looking into a case afterwards (not committed)
    np.savez_compressed(CACHE / (case.replace("/", "_") + ".track.npz"), track=flight.track,
                        reached=np.array(sorted(flight.reached.items()), dtype=float).reshape(-1, 2))
    (CACHE / (case.replace("/", "_") + ".flown.plan")).write_bytes(plan_file.read_bytes())
    report = compare_with_model(mission, flight, airframe_for(autopilot, tuning), wind)
    real, model = report.real_miss_m, report.model_miss_m
    diff = np.abs(real - model)
    worst = int(np.argmax(real))
    row = {"case": case, "autopilot": autopilot, "site": site, "wind": wind_text, "tuning": tuning,
           "targets": len(real), "items": summary.get("items"),
           "beyond_5m": int((real > 5).sum()),
           "real_median_m": f"{np.median(real):.2f}", "real_p95_m": f"{np.percentile(real, 95):.2f}",
           "real_max_m": f"{real.max():.2f}", "model_beyond_5m": int((model > 5).sum()),
           "model_max_m": f"{model.max():.2f}", "diff_median_m": f"{np.median(diff):.2f}",
           "diff_p95_m": f"{np.percentile(diff, 95):.2f}", "diff_max_m": f"{diff.max():.2f}",
           "real_flown_m": f"{report.real_flown_m:.0f}", "model_flown_m": f"{report.model_flown_m:.0f}",
           "tour_m": f"{summary['tour_length_m']:.0f}",
           "flown_over_tour": f"{report.real_flown_m / summary['tour_length_m']:.3f}",
           "real_time_s": f"{report.real_time_s:.1f}", "model_time_s": f"{report.model_time_s:.1f}",
           "plan_s": f"{plan_s:.1f}", "flight_wall_s": f"{flight.wall_s:.0f}",
           "worst_target": f"{report.names[worst]} {real[worst]:.1f} m (model {model[worst]:.1f})",
           "when": time.strftime("%Y-%m-%d %H:%M"), "code": _code_version()[:8]}
    tour_s = tour_time_s(summary, autopilot)
    row.update(tour_time_s=f"{tour_s:.1f}", time_over_tour=f"{report.real_time_s / tour_s:.3f}")
    targets = [{"case": case, "target": name, "real_miss_m": f"{r:.3f}", "model_miss_m": f"{m:.3f}",
                "code": row["code"]} for name, r, m in zip(report.names, real, model)]
    return row, targets


def flown_airspeed_m_s(autopilot: str) -> float:
    """The airspeed the case's aircraft flies its mission at: the one asked, but PX4's SIH
    plane flies no faster than it can (13.9 m/s; asked 18)."""
    if autopilot == "px4":
        return Airframe.from_px4_parameters(PX4_DEFAULTS, AIRSPEED["px4"]).airspeed_m_s
    return AIRSPEED[autopilot]


def tour_time_s(summary: dict, autopilot: str) -> float:
    """The tour's flight time the flight is measured against: in wind the tour planned for
    that wind (``plan``'s ``wind_tour_time_s``), in calm air the tour at the airspeed the
    aircraft flies (:func:`flown_airspeed_m_s`)."""
    if "wind_tour_time_s" in summary:
        return float(summary["wind_tour_time_s"])
    return float(summary["tour_length_m"]) / flown_airspeed_m_s(autopilot)


def _filled_tour_times(rows: list[dict]) -> None:
    """The tour's time of every row: in calm air the tour at the airspeed flown
    (:func:`tour_time_s`); in wind as the row has it, or for rows flown before the CSV had
    ``tour_time_s`` from the plans in the cache with the same tour and wind."""
    known = {}
    for path in CACHE.glob("*.json"):
        summary = json.loads(path.read_text())
        wind = summary.get("design_wind") or {}
        if "wind_tour_time_s" in summary:
            key = (round(summary["tour_length_m"]), f"{wind['speed_m_s']:g}@{wind['from_deg']:g}")
            known[key] = summary["wind_tour_time_s"]
    for row in rows:
        if row["wind"] == "calm":
            tour_s = float(row["tour_m"]) / flown_airspeed_m_s(row["autopilot"])
        elif row.get("tour_time_s"):
            continue
        else:
            tour_s = known.get((round(float(row["tour_m"])), row["wind"]), math.nan)
        row["tour_time_s"] = f"{tour_s:.1f}"
        row["time_over_tour"] = f"{float(row['real_time_s']) / tour_s:.3f}"


def _append(path: Path, fields: list[str], rows: list[dict]) -> None:
    """``rows`` appended to the CSV at ``path``; a CSV written with fewer columns is
    rewritten first with ``fields`` (the new columns empty in its rows)."""
    if path.exists():
        with path.open(newline="") as handle:
            reader = csv.DictReader(handle)
            if reader.fieldnames != fields:
                old = list(reader)
                with path.open("w", newline="") as out:
                    writer = csv.DictWriter(out, fieldnames=fields, restval="")
                    writer.writeheader()
                    writer.writerows(old)
    new = not path.exists()
    with path.open("a", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=fields)
        if new:
            writer.writeheader()
        writer.writerows(rows)


def _done() -> set[str]:
    if not CSV_CASES.exists():
        return set()
    with CSV_CASES.open() as handle:
        current = _code_version()[:8]
        return {row["case"] for row in csv.DictReader(handle) if row.get("code") == current}


def markdown(out: Path) -> None:
    """The table of every flight in the CSV (the latest row of a case repeated is shown,
    earlier ones counted), and the model-against-real distribution over all targets."""
    with CSV_CASES.open() as handle:
        rows = list(csv.DictReader(handle))
    _filled_tour_times(rows)
    trials = [row for row in rows if row["code"] in TRIALS]
    every = rows
    rows = [row for row in rows if row["code"] not in TRIALS]
    latest, runs, earlier = {}, {}, {}
    for row in rows:
        earlier.setdefault(row["case"], row)          # the first flight of the case
        latest[row["case"]] = row
        runs[row["case"]] = runs.get(row["case"], 0) + 1
    earlier = {case: row for case, row in earlier.items() if row["code"] != latest[case]["code"]}
    lines = ["# The project's missions flown by the real autopilots",
             "",
             "Written by `python benchmarks/real_flights.py --markdown docs/real-flights.md` from "
             "`docs/real-flights.csv`. Each mission is planned by `dtsp-mission plan` (default "
             "design, rho 80 m, 120 m; ArduPlane 22 m/s, PX4 18 m/s; the case's `--wind` and "
             "`--vehicle-params`), uploaded to a fresh real SITL autopilot (ArduPlane V4.8.0-dev, "
             "PX4 v1.16.0 SIH; stock but for the tuning and the wind) and flown to the last "
             "waypoint (PX4's SIH has no wind: PX4 is flown in calm air only). *beyond* counts "
             "targets the real track passed farther than 5 m from; "
             "*model vs real* is |real miss - model miss| per target, the model flying the same "
             "mission, aircraft and wind; *flown / tour* the real track from the take-off's "
             "completion to the last waypoint over the closed tour at rho 80; *time / tour* that "
             "flight's time over the tour's: in calm air the tour at the airspeed flown (PX4's "
             "SIH plane flies 13.9 m/s, asked 18), in wind the tour planned for that wind "
             "(`plan`'s *tour in the forecast wind*).",
             "",
             "Tunings: `p18` NAVL1_PERIOD 18, NAVL1_DAMPING 0.85, WP_RADIUS 80; `p12` NAVL1_PERIOD 12, "
             "WP_RADIUS 30, ROLL_LIMIT_DEG 45; `p20` NAVL1_PERIOD 20, WP_RADIUS 60.",
             "",
             "*was*: the case's first flight, from an earlier version of the code (column `code` of "
             "the CSV: a digest of the package's source; every flight is listed at the end).",
             "",
             "| case | targets | items | beyond 5 m | real miss median / p95 / max m | model: beyond, max m "
             "| model vs real median / p95 / max m | flown / tour | time / tour | real / model time s "
             "| plan s | worst | flights |",
             "|---|---:|---:|---:|---|---|---|---:|---:|---|---:|---|---:|"]
    for case in sorted(latest, key=lambda c: all_cases().index(c) if c in all_cases() else 1e9):
        r = latest[case]
        was = f" (was {earlier[case]['beyond_5m']})" if case in earlier else ""
        lines.append(f"| {case} | {r['targets']} | {r['items']} | {r['beyond_5m']}{was} | "
                     f"{float(r['real_median_m']):.1f} / {float(r['real_p95_m']):.1f} / "
                     f"{float(r['real_max_m']):.1f} | {r['model_beyond_5m']}, "
                     f"{float(r['model_max_m']):.1f} | {float(r['diff_median_m']):.1f} / "
                     f"{float(r['diff_p95_m']):.1f} / {float(r['diff_max_m']):.1f} | "
                     f"{r['flown_over_tour']} | {r['time_over_tour']} | {float(r['real_time_s']):.0f} / "
                     f"{float(r['model_time_s']):.0f} | {r['plan_s']} | {r['worst_target']} | "
                     f"{runs[case]} |")
    clean = sum(1 for r in latest.values() if int(r["beyond_5m"]) == 0)
    lines += ["", f"{len(latest)} cases flown, {clean} with every target within 5 m."]
    if CSV_TARGETS.exists():
        with CSV_TARGETS.open() as handle:
            flown = {(c, r["code"]) for c, r in latest.items()}
            per = [r for r in csv.DictReader(handle) if (r["case"], r["code"]) in flown]
        real = np.array([float(r["real_miss_m"]) for r in per])
        model = np.array([float(r["model_miss_m"]) for r in per])
        diff = np.abs(real - model)
        lines += ["", "## Model against real, every target of every flight", "",
                  f"{len(real)} targets: |real - model| median {np.median(diff):.2f} m, p95 "
                  f"{np.percentile(diff, 95):.2f} m, max {diff.max():.2f} m (goal: p95 within 2 m, "
                  "max within 4 m).", "",
                  "| model's miss m | targets | real miss p95 m | real max m | real > 5 m |",
                  "|---|---:|---:|---:|---:|"]
        for low, high in ((0, 1), (1, 2), (2, 3), (3, 3.5), (3.5, 5), (5, math.inf)):
            chosen = (model >= low) & (model < high)
            if chosen.any():
                lines.append(f"| {low:g}-{high:g} | {chosen.sum()} | "
                             f"{np.percentile(real[chosen], 95):.1f} | {real[chosen].max():.1f} | "
                             f"{(real[chosen] > 5).sum()} |")
    if trials:
        lines += ["", "## Design options flown beside the default", "",
                  "The same case planned with an option of the design that is not the default "
                  "(its code digest below), against the default's latest flight of the case "
                  "(*option / default*).", "",
                  "| case | option | beyond 5 m | real max m | model vs real p95 / max m "
                  "| flown / tour | time / tour |", "|---|---|---|---|---|---|---|"]
        for r in trials:
            d = latest.get(r["case"])
            if d is None:
                continue
            lines.append(f"| {r['case']} | {TRIALS[r['code']]} | {r['beyond_5m']} / "
                         f"{d['beyond_5m']} | {float(r['real_max_m']):.1f} / "
                         f"{float(d['real_max_m']):.1f} | {float(r['diff_p95_m']):.1f} / "
                         f"{float(r['diff_max_m']):.1f} against {float(d['diff_p95_m']):.1f} / "
                         f"{float(d['diff_max_m']):.1f} | {r['flown_over_tour']} / "
                         f"{d['flown_over_tour']} | {r['time_over_tour']} / {d['time_over_tour']} |")
    rows = every
    lines += ["", "## Every flight", "",
              "Code digests: " + "; ".join(f"`{k}` {v}" for k, v in CODES.items()) + ".", "",
              "| case | code | when | beyond 5 m | real max m | model vs real p95 / max m | flown / tour "
              "| time / tour |",
              "|---|---|---|---:|---:|---|---:|---:|"]
    lines += [f"| {r['case']} | {r['code']} | {r['when']} | {r['beyond_5m']} | {float(r['real_max_m']):.1f} | "
              f"{float(r['diff_p95_m']):.1f} / {float(r['diff_max_m']):.1f} | {r['flown_over_tour']} "
              f"| {r['time_over_tour']} |" for r in rows]
    out.write_text("\n".join(lines) + "\n")
    print(f"wrote {out}")


def remodel(cases: list[str], airframe_change: dict | None = None) -> None:
    """The model against the real flights already flown (their tracks in the cache), with the
    flight model as it is now: for working on the model without flying again."""
    from dataclasses import replace

    from dtsp_mission.sim.fly import targets_in
    from dtsp_mission.sitl.flight import RealFlight, compare_with_model, mission_seqs
    from dtsp_mission.frame import LocalFrame
    every = []
    for case in cases:
        saved = CACHE / (case.replace("/", "_") + ".track.npz")
        if not saved.exists():
            continue
        mission = read_mission(str(CACHE / (case.replace("/", "_") + ".flown.plan")), None)
        data = np.load(saved)
        first, last = mission_seqs(mission)
        flight = RealFlight(case.split("/")[0], data["track"],
                            {int(s): float(t) for s, t in data["reached"]}, first, last,
                            LocalFrame(mission.home.latitude_deg, mission.home.longitude_deg),
                            None, 0.0)
        airframe = airframe_for(case.split("/")[0], case.split("/")[3])
        if airframe_change:
            airframe = replace(airframe, **airframe_change)
        report = compare_with_model(mission, flight, airframe, _wind(case.split("/")[2]),
                                    targets_in(mission))
        diff = np.abs(report.real_miss_m - report.model_miss_m)
        every.append(diff)
        print(f"{case}: real beyond 5 m {(report.real_miss_m > 5).sum()}, model beyond "
              f"{(report.model_miss_m > 5).sum()} (max {report.model_miss_m.max():.1f}); model vs "
              f"real median {np.median(diff):.2f} p95 {np.percentile(diff, 95):.2f} max "
              f"{diff.max():.2f} m; flown real {report.real_flown_m:.0f} model "
              f"{report.model_flown_m:.0f} m in {report.real_time_s:.0f} / {report.model_time_s:.0f} s")
    if every:
        diff = np.concatenate(every)
        print(f"all {len(diff)} targets: model vs real median {np.median(diff):.2f} p95 "
              f"{np.percentile(diff, 95):.2f} max {diff.max():.2f} m")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="*", help="glob over autopilot/site/wind/tuning "
                        "(comma-separated globs allowed)")
    parser.add_argument("--list", action="store_true")
    parser.add_argument("--again", action="store_true", help="fly cases already in the CSV")
    parser.add_argument("--budget-s", type=float, default=540.0,
                        help="start no case after this much wall time")
    parser.add_argument("--plan-only", action="store_true", help="plan (cache) without flying")
    parser.add_argument("--markdown", type=Path)
    parser.add_argument("--remodel", action="store_true", help="the model against the flights "
                        "already flown (cached tracks), with the flight model as it is now")
    parser.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                        help="with --remodel: an Airframe field changed (trying a model change)")
    args = parser.parse_args()
    if args.markdown:
        markdown(args.markdown)
        return
    globs = args.cases.split(",")
    chosen = [c for c in all_cases() if any(fnmatch.fnmatch(c, g) for g in globs)]
    if args.list:
        print("\n".join(chosen))
        return
    if args.remodel:
        remodel(chosen, {k: float(v) for k, v in (x.split("=", 1) for x in args.set)})
        return
    binaries = find_binaries()
    CACHE.mkdir(parents=True, exist_ok=True)
    lock = (CACHE / "flying.lock").open("w")
    try:          # one run at a time: two would start their autopilots on the same ports
        import fcntl
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        sys.exit("another benchmarks/real_flights.py is running (its autopilots use the same ports)")
    started, done = time.monotonic(), _done()
    for case in chosen:
        if case in done and not args.again:
            continue
        if time.monotonic() - started > args.budget_s:
            print(f"budget of {args.budget_s:g} s spent: stopping before {case}")
            break
        if args.plan_only:
            print(case, plan_case(case)[0])
            continue
        why = binaries.missing(case.split("/")[0])
        if why:
            print(f"{case}: skipped: {why}")
            continue
        try:
            row, targets = run_case(case, binaries)
        except (LinkError, RuntimeError) as error:
            print(f"{case}: FAILED: {error}")
            continue
        _append(CSV_CASES, CASE_FIELDS, [row])
        _append(CSV_TARGETS, ["case", "target", "real_miss_m", "model_miss_m", "code"], targets)
        print(f"{case}: {row['beyond_5m']} of {row['targets']} beyond 5 m, real max "
              f"{row['real_max_m']} m, model vs real p95 {row['diff_p95_m']} / max "
              f"{row['diff_max_m']} m, flown/tour {row['flown_over_tour']} "
              f"({row['flight_wall_s']} s)", flush=True)


if __name__ == "__main__":
    main()
