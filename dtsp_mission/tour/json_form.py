"""The JSON form of a tour (schema in ``docs/tour-json.md`` and ``schemas/tour.schema.json``).

Floats are written with Python's shortest round-trip representation, so reading a written
tour gives back exactly the same numbers.  Reading validates structure and values and raises
:class:`~dtsp_mission.errors.FileFormatError` naming the offending field.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import FileFormatError
from ..files import read_json, read_text, write_atomic
from ..segments import SegmentChain
from .model import Tour

FORMAT = "dtsp-mission/tour"
VERSION = 1


def tour_to_dict(tour: Tour, origin_deg: tuple[float, float] | None = None) -> dict[str, Any]:
    """The tour as plain JSON-ready data; ``origin_deg`` (latitude, longitude) places the local
    frame on the earth (azimuthal equidistant on WGS84 centred there)."""
    frame: dict[str, Any] = {"type": "local", "x": "east", "y": "north",
                             "heading": "radians counter-clockwise from east"}
    if origin_deg is not None:
        frame["origin"] = {"latitude_deg": float(origin_deg[0]),
                           "longitude_deg": float(origin_deg[1]),
                           "projection": "azimuthal equidistant, WGS84"}
    chain = tour.chain
    segments = []
    for (x, y, heading), length, curvature in zip(chain.starts.tolist(), chain.lengths_m.tolist(),
                                                   chain.curvatures_1_m.tolist()):
        segment = {"type": "line" if curvature == 0.0 else "arc", "x_m": x, "y_m": y,
                   "heading_rad": heading, "length_m": length}
        if curvature != 0.0:
            segment["turn"] = "left" if curvature > 0 else "right"
            segment["radius_m"] = 1.0 / abs(curvature)
        segments.append(segment)
    order = tour.visit_order
    return {
        "format": FORMAT,
        "version": VERSION,
        "frame": frame,
        "rho_m": tour.rho_m,
        "length_m": tour.length_m,
        "planner": {"name": tour.planner, "parameters": tour.parameters, "report": tour.report},
        "targets": [{"x_m": x, "y_m": y} for x, y in tour.targets_m.tolist()],
        "visits": [{"target": int(i), "s_m": float(tour.visit_s_m[i])} for i in order],
        "segments": segments,
    }


def _number(record: dict, key: str, where: str, minimum: float | None = None) -> float:
    value = record.get(key)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise FileFormatError(f"{where}: '{key}' must be a finite number, got {value!r}")
    if minimum is not None and value < minimum:
        raise FileFormatError(f"{where}: '{key}' must be at least {minimum}, got {value!r}")
    return float(value)


def tour_from_dict(data: Any) -> Tour:
    """A tour from its JSON form; :class:`FileFormatError` if anything is missing or wrong."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise FileFormatError(f"not a tour: expected \"format\": \"{FORMAT}\"")
    if data.get("version") != VERSION:
        raise FileFormatError(f"tour version {data.get('version')!r} is not supported "
                              f"(this program reads version {VERSION})")
    rho = _number(data, "rho_m", "tour")
    if rho <= 0:
        raise FileFormatError(f"tour: 'rho_m' must be positive, got {rho!r}")
    for key in ("targets", "visits", "segments"):
        if not isinstance(data.get(key), list):
            raise FileFormatError(f"tour: '{key}' must be a list")
    targets = np.array([[_number(t, "x_m", f"targets[{i}]"), _number(t, "y_m", f"targets[{i}]")]
                        for i, t in enumerate(_records(data["targets"], "targets"))]).reshape(-1, 2)
    if len(targets) == 0:
        raise FileFormatError("tour: it visits no targets (a tour goes through at least one)")
    visit_s = np.full(len(targets), np.nan)
    for k, visit in enumerate(_records(data["visits"], "visits")):
        target = visit.get("target")
        if isinstance(target, bool) or not isinstance(target, int) or not 0 <= target < len(targets):
            raise FileFormatError(f"visits[{k}]: 'target' must be a target index, got {target!r}")
        if not math.isnan(visit_s[target]):
            raise FileFormatError(f"visits[{k}]: target {target} is visited twice")
        visit_s[target] = _number(visit, "s_m", f"visits[{k}]", minimum=0.0)
    if np.isnan(visit_s).any():
        raise FileFormatError(f"tour: target {int(np.argmax(np.isnan(visit_s)))} has no visit")
    starts, lengths, curvatures = [], [], []
    for k, segment in enumerate(_records(data["segments"], "segments")):
        where = f"segments[{k}]"
        starts.append([_number(segment, "x_m", where), _number(segment, "y_m", where),
                       _number(segment, "heading_rad", where)])
        lengths.append(_number(segment, "length_m", where, minimum=0.0))
        kind = segment.get("type")
        if kind == "line":
            curvatures.append(0.0)
        elif kind == "arc":
            radius = _number(segment, "radius_m", where)
            if radius <= 0:
                raise FileFormatError(f"{where}: 'radius_m' must be positive, got {radius!r}")
            turn = segment.get("turn")
            if turn not in ("left", "right"):
                raise FileFormatError(f"{where}: 'turn' must be \"left\" or \"right\", got {turn!r}")
            curvatures.append((1.0 if turn == "left" else -1.0) / radius)
        else:
            raise FileFormatError(f"{where}: 'type' must be \"line\" or \"arc\", got {kind!r}")
    chain = SegmentChain(np.array(starts).reshape(-1, 3), np.array(lengths), np.array(curvatures))
    if "length_m" in data:
        stated = _number(data, "length_m", "tour")
        if abs(stated - chain.length_m) > 1e-6 * max(rho, chain.length_m):
            raise FileFormatError(f"tour: 'length_m' says {stated:,.6g} m, but its segments are "
                                  f"{chain.length_m:,.6g} m long")
    planner = data.get("planner") or {}
    if not isinstance(planner, dict):
        raise FileFormatError("tour: 'planner' must be an object")
    return Tour(chain, rho, targets, visit_s, str(planner.get("name", "")),
                dict(planner.get("parameters") or {}), dict(planner.get("report") or {}))


def _records(items: list, name: str) -> list[dict]:
    for k, item in enumerate(items):
        if not isinstance(item, dict):
            raise FileFormatError(f"{name}[{k}] must be an object")
    return items


def dumps(tour: Tour, origin_deg: tuple[float, float] | None = None) -> str:
    return json.dumps(tour_to_dict(tour, origin_deg), indent=1, allow_nan=False) + "\n"


def write_tour(tour: Tour, path: str | os.PathLike,
               origin_deg: tuple[float, float] | None = None) -> Path:
    """Write the tour's JSON form atomically."""
    return write_atomic(path, dumps(tour, origin_deg))


def origin_from_dict(data: dict[str, Any]) -> tuple[float, float] | None:
    """The (latitude, longitude) origin of a tour document's frame, if it has one."""
    frame = data.get("frame") if isinstance(data, dict) else None
    origin = frame.get("origin") if isinstance(frame, dict) else None
    if origin is None:
        return None
    if not isinstance(origin, dict):
        raise FileFormatError("tour: 'frame.origin' must be an object")
    return (_number(origin, "latitude_deg", "frame.origin"),
            _number(origin, "longitude_deg", "frame.origin"))


def read_tour(path: str | os.PathLike) -> Tour:
    """Read a tour file; errors name the file and what is wrong in it."""
    data = read_json(path)
    try:
        return tour_from_dict(data)
    except FileFormatError as error:
        raise FileFormatError(f"{path}: {error}") from None
