"""How closely the flight model reproduces a recorded ArduPlane flight.

A case folder holds what a real ArduPlane SITL was given and what it did (the format of
``tests/data/arduplane-sitl``: ``mission.plan``, ``params.parm``, ``track.csv``, ``reached.csv``,
``items.csv`` and, for planned missions, ``misses.csv``).  :func:`compare_case` flies the same
mission, as the vehicle stored it, with the recorded parameters, and measures:

* item timing: each item's MISSION_ITEM_REACHED time after the take-off completed, the model's
  scaled to the real flight's duration, the difference per item;
* the track: the distance of every real 10 Hz position (take-off end to last item) from the
  model's track;
* closest approach: per waypoint (or, for planned missions, per target), the model's least
  distance minus the real one.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..autopilot import Command
from ..autopilot.navigation import MODEL_STEP_S, Airframe, MissionFlight, Wind, closest_approach_m
from ..autopilot.parameters import parse_parameters, read_parameters
from ..export import read_mission
from ..frame import LocalFrame
from ..sim.predict import predict_flight


#: The goals of the simulator issue: name -> (Agreement field, limit).
GOALS = {"timing 2 s": ("timing_max_s", 2.0), "track median 3 m": ("track_median_m", 3.0),
         "track max 10 m": ("track_max_m", 10.0), "closest median 1 m": ("approach_median_m", 1.0),
         "closest max 3 m": ("approach_max_m", 3.0)}

#: The recordings go on this long after the last item was reached.
RECORDED_AFTER_S = 10.0


@dataclass(frozen=True)
class Agreement:
    """The figures of one case (metres and seconds)."""

    case: str
    items_timed: int
    timing_median_s: float
    timing_max_s: float
    track_median_m: float
    track_p95_m: float
    track_max_m: float
    points: int
    approach_median_m: float      # |model - real| closest approach
    approach_max_m: float
    real_approach_median_m: float
    model_approach_median_m: float
    real_length_m: float
    model_length_m: float

    def beyond(self, limits: tuple[float, float, float, float, float]) -> list[str]:
        """Which of (timing max s, track median m, track max m, closest |diff| median m,
        closest |diff| max m) this case exceeds, and whether it flew a mission of another
        length than the real one (more than 2 % off) or timed fewer than 3 items."""
        fields = ("timing_max_s", "track_median_m", "track_max_m", "approach_median_m",
                  "approach_max_m")
        found = [f"{name} {getattr(self, name):.2f} > {limit}"
                 for name, limit in zip(fields, limits) if getattr(self, name) > limit]
        if abs(self.model_length_m - self.real_length_m) > 0.02 * self.real_length_m:
            found.append(f"flown {self.model_length_m:.0f} m against {self.real_length_m:.0f} m")
        if self.items_timed < 3:
            found.append(f"only {self.items_timed} items timed")
        return found

    def missed_goals(self) -> list[str]:
        """The simulator issue's goals this case misses (:data:`GOALS`)."""
        return [name for name, (field, limit) in GOALS.items() if getattr(self, field) > limit]

    def row(self) -> list[str]:
        return [self.case, f"{self.items_timed}", f"{self.timing_median_s:.1f}",
                f"{self.timing_max_s:.1f}", f"{self.track_median_m:.1f}",
                f"{self.track_p95_m:.1f}", f"{self.track_max_m:.1f}", f"{self.points}",
                f"{self.real_approach_median_m:.1f}", f"{self.model_approach_median_m:.1f}",
                f"{self.approach_median_m:.1f}", f"{self.approach_max_m:.1f}",
                f"{self.real_length_m:,.0f}", f"{self.model_length_m:,.0f}",
                ", ".join(self.missed_goals()) or "all met"]


HEADER = ["case", "items timed", "timing median s", "timing max s", "track median m",
          "track p95 m", "track max m", "points", "real closest median m",
          "model closest median m", "closest |diff| median m", "closest |diff| max m",
          "real flown m", "model flown m", "goals missed"]


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def _length(xy: np.ndarray) -> float:
    return float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0


def recorded_wind(folder: Path) -> Wind:
    """The steady wind the SITL flew the case in (``SIM_WIND_SPD``, ``SIM_WIND_DIR``,
    ``SIM_WIND_T_ALT`` of its ``params.parm``; calm without them)."""
    values = parse_parameters((folder / "params.parm").read_text(), str(folder / "params.parm"))
    return Wind(values.get("SIM_WIND_SPD", 0.0), values.get("SIM_WIND_DIR", 0.0),
                values.get("SIM_WIND_T_ALT", 60.0))


def fly_recorded_mission(folder: Path, airframe: Airframe | None = None, dt_s: float = MODEL_STEP_S,
                         ) -> tuple[MissionFlight, np.ndarray, LocalFrame]:
    """The model's flight of the case's mission (as ArduPilot stored it) with the case's
    parameters and wind, on until :data:`RECORDED_AFTER_S` after the last item as recorded:
    the flight, its track rows (time, x, y, altitude) and the local frame at home."""
    airframe = airframe or Airframe.from_parameters(read_parameters(folder / "params.parm"))
    predicted = predict_flight(read_mission(folder / "mission.plan"), airframe, dt_s,
                               RECORDED_AFTER_S, 7200.0, recorded_wind(folder))
    return predicted.flight, predicted.track, predicted.frame


def _closest_while_current(track: np.ndarray, reached: dict[int, float], seq: int,
                           point: np.ndarray) -> float:
    """Least distance of the track to ``point`` while item ``seq`` or the next is current:
    from the reaching of the item before it to the reaching of the one after (or the end)."""
    begin = reached.get(seq - 1, 0.0)
    end = reached.get(seq + 1, np.inf)
    window = (track[:, 0] >= begin) & (track[:, 0] <= end)
    return float(closest_approach_m(track[window, 1:3], point[None, :])[0])


def timed_and_tracked(folder: Path, frame: LocalFrame, model: np.ndarray,
                      model_reached: dict[int, float], real_reached: dict[int, float],
                      start_real: float, start_model: float, first_timed: int):
    """What the real and the model's flights share: the items both reached from
    ``first_timed`` on, the |difference| of each one's reach time after the start (the model's
    scaled to the real flight's duration), the real track (``track.csv``) and the model's over
    the same span, and the distance of each real position from the model's track."""
    common = sorted(seq for seq in real_reached if seq in model_reached and seq >= first_timed)
    end = common[-1]
    scale = (real_reached[end] - start_real) / max(model_reached[end] - start_model, 1e-9)
    timing = np.array([abs((model_reached[q] - start_model) * scale - (real_reached[q] - start_real))
                       for q in common])
    rows = _rows(folder / "track.csv")
    real_t = np.array([float(r["time_s"]) for r in rows])
    real_xy = frame.to_local(np.array([float(r["lat"]) for r in rows]),
                             np.array([float(r["lon"]) for r in rows]))
    real_xy = real_xy[(real_t >= start_real) & (real_t <= real_reached[end])]
    model_xy = model[(model[:, 0] >= start_model) & (model[:, 0] <= model_reached[end]), 1:3]
    return common, timing, real_xy, model_xy, closest_approach_m(model_xy, real_xy)


def agreement(name: str, common: list[int], timing: np.ndarray, real_xy: np.ndarray,
              model_xy: np.ndarray, track: np.ndarray, real_closest: np.ndarray,
              model_closest: np.ndarray) -> Agreement:
    """The figures of one case from what :func:`timed_and_tracked` measured and the real and
    the model's closest approaches."""
    difference = np.abs(model_closest - real_closest)
    return Agreement(name, len(common), float(np.median(timing)), float(timing.max()),
                     float(np.median(track)), float(np.percentile(track, 95)), float(track.max()),
                     len(real_closest), float(np.median(difference)), float(difference.max()),
                     float(np.median(real_closest)), float(np.median(model_closest)),
                     _length(real_xy), _length(model_xy))


def compare_case(folder: str | Path, airframe: Airframe | None = None) -> Agreement:
    """The model against the recorded flight in ``folder``."""
    folder = Path(folder)
    flight, model, frame = fly_recorded_mission(folder, airframe)
    model_reached = dict(flight.reached)

    real_reached = {int(r["seq"]): float(r["time_s"]) for r in _rows(folder / "reached.csv")
                    if r["event"] == "reached" and r["time_s"]}
    # the take-off's reach (seq 1), or where a recording lost it, the first item reached after it
    start_real = real_reached.get(1, real_reached[min(real_reached)])
    start_model = model_reached.get(1, 0.0)
    common, timing, real_xy, model_xy, track = timed_and_tracked(
        folder, frame, model, model_reached, real_reached, start_real, start_model, 2)
    end = common[-1]

    after_takeoff = model[:, 0] >= start_model
    if (folder / "misses.csv").exists():       # targets: the whole track after take-off
        points = _rows(folder / "misses.csv")
        real_closest = np.array([float(r["miss_m"]) for r in points])
        xy = frame.to_local(np.array([float(r["lat"]) for r in points]),
                            np.array([float(r["lon"]) for r in points]))
        model_closest = closest_approach_m(model[after_takeoff, 1:3], xy)
    else:                                      # waypoints: while it or the next is current
        points = [r for r in _rows(folder / "items.csv") if int(r["command"]) == Command.NAV_WAYPOINT
                  and int(r["seq"]) <= end]
        real_closest = np.array([float(r["closest_m"]) for r in points])
        xy = frame.to_local(np.array([float(r["lat"]) for r in points]),
                            np.array([float(r["lon"]) for r in points]))
        model_closest = np.array([_closest_while_current(model, model_reached, int(r["seq"]), p)
                                  for r, p in zip(points, xy)])
    return agreement(folder.name, common, timing, real_xy, model_xy, track, real_closest,
                     model_closest)


def cases(root: str | Path) -> list[Path]:
    """The case folders under ``root`` (those with a recorded track)."""
    return sorted(p for p in Path(root).iterdir() if (p / "track.csv").exists())


def markdown_table(results: list[Agreement]) -> str:
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    lines += ["| " + " | ".join(r.row()) + " |" for r in results]
    return "\n".join(lines) + "\n"


def as_json(results: list[Agreement]) -> str:
    return json.dumps([r.__dict__ for r in results], indent=2)
