"""Targets and survey area from GeoJSON (RFC 7946).

Point and MultiPoint features are targets (``[longitude, latitude]``; a third coordinate is
refused because GeoJSON does not say what it is relative to -- use the ``alt`` property, metres
above home).  Other properties are listed as not used; one that looks like a misspelt property
(``atl``) is refused.  A ``name`` property names a target; ``photo``, ``roi``, ``gimbal_pitch`` and
``loiter_turns`` properties are its actions (:mod:`.actions`).  One Polygon feature, if present, is the
survey area.  Any other geometry is an error.
"""

from __future__ import annotations

import json
import os
from dataclasses import replace
from typing import Any

import numpy as np
import shapely
from shapely.geometry import shape
from shapely.validation import explain_validity

from ..errors import FileFormatError
from ..files import parse_json, read_text
from ..frame import check_geodetic
from ..errors import InputError
from .actions import COLUMNS, actions_from_columns, column_key, parse_cell
from .csv_file import misspelt_column
from .model import GeoTargets, check_altitudes, geodetic_targets


#: The properties read besides the actions.
_KNOWN_PROPERTIES = ("name", "alt")


def _features(data: Any, path) -> list[dict]:
    if not isinstance(data, dict) or "type" not in data:
        raise FileFormatError(f"{path}: not GeoJSON (expected an object with a 'type')")
    if data["type"] == "FeatureCollection":
        features = data.get("features")
        if not isinstance(features, list):
            raise FileFormatError(f"{path}: a FeatureCollection needs a 'features' list")
        return features
    if data["type"] == "Feature":
        return [data]
    return [{"type": "Feature", "geometry": data, "properties": {}}]


#: The names of RFC 7946's one coordinate reference system (WGS 84, longitude then latitude),
#: as older GeoJSON (2008) and GDAL write it in a ``crs`` member.
CRS84 = {"urn:ogc:def:crs:OGC:1.3:CRS84", "urn:ogc:def:crs:OGC::CRS84", "OGC:CRS84",
         "http://www.opengis.net/def/crs/OGC/1.3/CRS84"}


def check_crs(data: Any, path) -> None:
    """:class:`FileFormatError` for a ``crs`` member naming anything but CRS84: RFC 7946
    GeoJSON is [longitude, latitude] on WGS 84, and a file declaring another system (EPSG:4326
    is latitude first; a projected system is metres) would be read at the wrong place."""
    if not isinstance(data, dict) or "crs" not in data or data["crs"] is None:
        return
    crs = data["crs"]
    name = crs.get("properties", {}).get("name") if isinstance(crs, dict) and isinstance(
        crs.get("properties"), dict) else None
    if isinstance(name, str) and name.strip() in CRS84:
        return
    raise FileFormatError(
        f"{path}: declares the coordinate system {name or crs!r}; GeoJSON targets are read as "
        "RFC 7946 (WGS 84 [longitude, latitude], no 'crs'), and another system's coordinates "
        "(EPSG:4326 puts latitude first) would be planned at the wrong place: write RFC 7946 "
        "GeoJSON (e.g. ogr2ogr -f GeoJSON -lco RFC7946=YES out.geojson in.geojson)")


def area_from_geometry(geometry: dict, where: str) -> np.ndarray:
    """The outer ring of a GeoJSON Polygon as (k, 2) rows of (latitude, longitude), checked to be
    a valid (non self-intersecting, non-empty) polygon."""
    try:
        polygon = shape(geometry)
    except (ValueError, TypeError, KeyError, IndexError, shapely.errors.GEOSException) as error:
        raise FileFormatError(f"{where}: not a valid Polygon ({error})") from None
    if not polygon.is_empty and not polygon.is_valid:
        raise FileFormatError(f"{where}: the survey polygon is not valid "
                              f"({explain_validity(polygon)})")
    if polygon.is_empty or polygon.area <= 0.0:
        raise FileFormatError(f"{where}: the survey polygon is empty")
    if len(polygon.interiors):
        raise FileFormatError(f"{where}: the survey polygon has {len(polygon.interiors)} "
                              "hole(s); areas with holes are not supported (targets would be "
                              "drawn and bounded inside them): give the outer ring only, or "
                              "split the area into polygons without holes")
    ring = np.asarray(polygon.exterior.coords)[:, :2]
    check_geodetic(ring[:, 1], ring[:, 0], f"{where}: vertex")
    return ring[:, ::-1].copy()


def read_geojson(path: str | os.PathLike, text: str | None = None) -> GeoTargets:
    """Targets (possibly none, if the file only holds a survey area) and the survey area;
    ``text``: the content, already read from ``path``."""
    text = read_text(path) if text is None else text
    data = parse_json(text, str(path))
    check_crs(data, path)
    latitudes: list[float] = []
    longitudes: list[float] = []
    names: list[str] = []
    altitudes: list[float] = []
    action_cells: dict[str, list] = {}
    unused: dict[str, None] = {}
    row_names: list[str] = []
    area = None
    for number, feature in enumerate(_features(data, path), start=1):
        where = f"{path}, feature {number}"
        geometry = feature.get("geometry") if isinstance(feature, dict) else None
        if not isinstance(geometry, dict):
            raise FileFormatError(f"{where}: has no geometry")
        properties = feature.get("properties")
        if properties is None:
            properties = {}
        if not isinstance(properties, dict):
            raise FileFormatError(f"{where}: 'properties' must be an object (name, alt, photo, "
                                  f"...) or null, got {properties!r}")
        kind = geometry.get("type")
        if kind == "Polygon":
            if area is not None:
                raise FileFormatError(f"{where}: a second Polygon; give one survey area")
            area = area_from_geometry(geometry, where)
            continue
        if kind not in ("Point", "MultiPoint"):
            raise FileFormatError(f"{where}: {kind!r} geometry is not supported (Point and "
                                  "MultiPoint are targets, one Polygon is the survey area)")
        points = [geometry.get("coordinates")] if kind == "Point" else geometry.get("coordinates")
        for point in points if isinstance(points, list) else [None]:
            if (not isinstance(point, list) or len(point) < 2
                    or not all(isinstance(c, (int, float)) for c in point[:2])):
                raise FileFormatError(f"{where}: coordinates must be [longitude, latitude], "
                                      f"got {point!r}")
            if len(point) > 2:
                raise FileFormatError(
                    f"{where}: a third coordinate ({point[2]!r}) is an altitude of unknown "
                    "reference (GeoJSON's is above the ellipsoid); give [longitude, latitude] "
                    "and the altitude above home as the 'alt' property")
            longitudes.append(float(point[0]))
            latitudes.append(float(point[1]))
            row_names.append(f"feature {number}")
            for key in properties:
                if (str(key).strip().lower() not in _KNOWN_PROPERTIES and column_key(str(key)) is None):
                    meant = misspelt_column(str(key).strip().lower(), ())
                    if meant:
                        raise FileFormatError(f"{where}: property {key!r} is not one this reads: "
                                              f"did you mean {meant!r}?")
                    unused[str(key)] = None
            names.append(str(properties.get("name", "")))
            altitude = properties.get("alt")
            if altitude is not None and (isinstance(altitude, bool)
                                         or not isinstance(altitude, (int, float))):
                raise FileFormatError(f"{where}: 'alt' must be a number of metres above home, "
                                      f"got {altitude!r}")
            altitudes.append(np.nan if altitude is None else altitude)
            for key, spellings in COLUMNS.items():
                given = next((properties[p] for p in spellings if p in properties), None)
                if given is None and key not in action_cells:
                    continue
                cells = action_cells.setdefault(key, [parse_cell(key, None, where)] * (len(latitudes) - 1))
                try:
                    cells.append(parse_cell(key, given, where))
                except InputError as error:
                    raise FileFormatError(str(error)) from None
    if not latitudes and area is None:
        raise FileFormatError(f"{path}: no Point features (targets) and no Polygon (area)")
    check_geodetic(latitudes, longitudes, f"{path}: target")
    given = [a for a in altitudes if not (isinstance(a, float) and np.isnan(a))]
    altitude_array = None
    if given:
        if len(given) != len(altitudes):
            raise FileFormatError(f"{path}: give the 'alt' property on every target or on none")
        try:
            altitude_array = np.array(altitudes, dtype=float)
        except (TypeError, ValueError):
            raise FileFormatError(f"{path}: every 'alt' property must be a number") from None
        check_altitudes(altitude_array, str(path), row_names)
    name_tuple = tuple(names) if any(names) else None
    targets = geodetic_targets(latitudes, longitudes, name_tuple, altitude_array, area,
                               actions_from_columns(action_cells, len(latitudes)), where=str(path),
                               rows=row_names)
    return replace(targets, unused_columns=tuple(unused)) if unused else targets
