"""GeoJSON (RFC 7946) for GIS tools: the flown path, the targets, the waypoints and home.

Positions are ``[longitude, latitude]`` in WGS84 degrees; altitudes (metres above home) are
in the properties, because a GeoJSON third coordinate would mean height above the ellipsoid.
The path is sampled from the exact segments by :func:`~dtsp_mission.export.base.flight_path_deg`
(arcs every 2 degrees of turn, lines only at their ends).
"""

from __future__ import annotations

import json

import numpy as np

from ..mission import Mission
from .base import Exporter, flight_path_deg


def _point(latitude: float, longitude: float, properties: dict) -> dict:
    return {"type": "Feature", "geometry": {"type": "Point", "coordinates": [longitude, latitude]},
            "properties": properties}


def line_geometry(latitudes: np.ndarray, longitudes: np.ndarray) -> dict:
    """A LineString, or -- for a line that crosses the antimeridian -- a MultiLineString cut
    there, each part ending on +-180 degrees at the interpolated crossing (RFC 7946, 3.1.9)."""
    longitudes = np.asarray(longitudes, dtype=float)
    latitudes = np.asarray(latitudes, dtype=float)
    jumps = np.flatnonzero(np.abs(np.diff(longitudes)) > 180.0)
    if not len(jumps):
        return {"type": "LineString", "coordinates": np.column_stack([longitudes, latitudes]).tolist()}
    parts, current = [], [[longitudes[0], latitudes[0]]]
    for k in range(1, len(longitudes)):
        a, b = longitudes[k - 1], longitudes[k]
        if abs(b - a) > 180.0:
            side = 180.0 if a > 0 else -180.0               # the edge the line leaves by
            t = (side - a) / ((b + 2 * side) - a)           # b unwrapped to the same side
            crossing = float(latitudes[k - 1] + t * (latitudes[k] - latitudes[k - 1]))
            parts.append(current + [[side, crossing]])
            current = [[-side, crossing]]
        current.append([longitudes[k], latitudes[k]])
    parts.append(current)
    return {"type": "MultiLineString",
            "coordinates": [[[float(x), float(y)] for x, y in part] for part in parts]}


def geojson_dict(mission: Mission) -> dict:
    """The mission as a GeoJSON FeatureCollection."""
    path = mission.path
    latitudes, longitudes = flight_path_deg(mission)
    features = [{
        "type": "Feature",
        "geometry": line_geometry(latitudes, longitudes),
        # length_m: this line (take-off's end to the last target); flight_length_m: what plan
        # reports as the flight (take-off to the return); tour_length_m: the closed tour.
        "properties": {"kind": "flight_path", "length_m": path.chain.length_m,
                       "flight_length_m": mission.summary["flight_length_m"],
                       "rho_m": mission.rho_m, "tour_length_m": mission.tour.length_m,
                       "planner": mission.tour.planner},
    }]
    home = mission.home
    features.append(_point(home.latitude_deg, home.longitude_deg,
                           {"kind": "home", "altitude_amsl_m": home.altitude_amsl_m}))
    item_of_target = mission.target_items
    rank = mission.visit_numbers
    latitudes, longitudes = mission.target_positions_deg
    for target, item_index in enumerate(item_of_target):
        item = mission.items[item_index]
        # Numbers as the user sees them elsewhere: the target's 1-based row in the targets
        # file, its 1-based place in the visiting order, its mission item as QGroundControl
        # numbers it (1-based; home is 0).
        properties = {"kind": "target", "target": target + 1, "visit": int(rank[target]) + 1,
                      "item": item_index + 1, "altitude_m": item.altitude_m,
                      "s_m": float(path.target_s_m[target])}
        if mission.target_names is not None:
            properties["name"] = mission.target_names[target]
        features.append(_point(latitudes[target], longitudes[target], properties))
    for index, item in enumerate(mission.items):
        if item.has_position and item.role != "roi_off":     # ArduPilot's "no ROI" is at 0, 0
            kind = {"roi": "roi", "loiter": "loiter"}.get(item.role, "waypoint")
            features.append(_point(item.latitude_deg, item.longitude_deg,
                                   {"kind": kind, "item": index + 1, "command": int(item.command),
                                    "role": item.role, "altitude_m": item.altitude_m}))
    # "generator": a foreign member (RFC 7946, 6.1) saying who wrote it, read by nothing but
    # dtsp-mission itself (which replaces only the sortie files it wrote)
    return {"type": "FeatureCollection", "generator": GENERATOR, "features": features}


#: The ``generator`` member of every GeoJSON file dtsp-mission writes.
GENERATOR = "dtsp-mission"


class GeoJSONExporter(Exporter):
    """GeoJSON (``.geojson``)."""

    name = "geojson"
    extensions = (".geojson",)
    description = "GeoJSON file"

    def render(self, mission: Mission) -> str:
        return json.dumps(geojson_dict(mission), allow_nan=False) + "\n"
