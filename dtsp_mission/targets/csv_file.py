"""Targets from CSV: ``lat,lon`` in WGS84 degrees, or ``x,y`` in local metres.

A header row names the columns (case and surrounding spaces ignored):

- ``lat``/``latitude`` and ``lon``/``lng``/``longitude``: degrees -> :class:`GeoTargets`;
- ``x``/``x_m`` and ``y``/``y_m``: metres east and north of an origin -> :class:`Targets`;
- optional ``alt``/``altitude``/``alt_m`` (metres above home) and ``name``.

Any other column is an error, so a typo is never silently ignored.  Errors name the file, line
and column.
"""

from __future__ import annotations

import csv
import io
import os

import numpy as np

from ..errors import FileFormatError
from ..files import read_text
from ..frame import check_geodetic
from .model import GeoTargets, Targets, check_altitudes, geodetic_targets, local_targets

_COLUMNS = {
    "lat": ("lat", "latitude"), "lon": ("lon", "lng", "longitude"),
    "x": ("x", "x_m"), "y": ("y", "y_m"),
    "alt": ("alt", "altitude", "alt_m"), "name": ("name",),
}


def _header(path, header: list[str]) -> dict[str, int]:
    found: dict[str, int] = {}
    for index, raw in enumerate(header):
        label = raw.strip().lower()
        for key, spellings in _COLUMNS.items():
            if label in spellings:
                if key in found:
                    raise FileFormatError(f"{path}, line 1: column {key!r} is given twice")
                found[key] = index
                break
        else:
            raise FileFormatError(
                f"{path}, line 1: unknown column {raw.strip()!r}; the columns are lat and lon "
                "(degrees) or x and y (metres), with optional alt (metres above home) and name")
    geodetic = "lat" in found and "lon" in found
    local = "x" in found and "y" in found
    if geodetic == local:
        raise FileFormatError(
            f"{path}, line 1: the header must name either columns lat and lon (degrees) or "
            f"x and y (metres); found {', '.join(h.strip() for h in header)}")
    return found


def read_csv(path: str | os.PathLike) -> GeoTargets | Targets:
    """Targets from a CSV file; duplicates (same coordinates) are merged and counted."""
    text = read_text(path)
    rows = [row for row in csv.reader(io.StringIO(text)) if any(cell.strip() for cell in row)]
    if not rows:
        raise FileFormatError(f"{path}: the file is empty")
    columns = _header(path, rows[0])
    geodetic = "lat" in columns
    first, second = ("lat", "lon") if geodetic else ("x", "y")
    numbers: dict[str, list[float]] = {key: [] for key in (first, second, "alt") if key in columns}
    names: list[str] = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(rows[0]):
            raise FileFormatError(f"{path}, line {line}: {len(row)} fields where the header has "
                                  f"{len(rows[0])}")
        for key, values in numbers.items():
            cell = row[columns[key]].strip()
            try:
                value = float(cell)
            except ValueError:
                raise FileFormatError(f"{path}, line {line}: {key} must be a number, got "
                                      f"{cell!r}") from None
            if not np.isfinite(value):
                raise FileFormatError(f"{path}, line {line}: {key} must be a finite number, "
                                      f"got {cell!r}")
            values.append(value)
        if "name" in columns:
            names.append(row[columns["name"]].strip())
    if not names and not numbers[first]:
        raise FileFormatError(f"{path}: there are no targets below the header")
    altitudes = np.array(numbers["alt"]) if "alt" in numbers else None
    check_altitudes(altitudes, str(path))
    name_tuple = tuple(names) if "name" in columns else None
    if geodetic:
        check_geodetic(numbers["lat"], numbers["lon"], f"{path}: target")
        return geodetic_targets(numbers["lat"], numbers["lon"], name_tuple, altitudes)
    return local_targets(np.column_stack([numbers["x"], numbers["y"]]), name_tuple, altitudes)
