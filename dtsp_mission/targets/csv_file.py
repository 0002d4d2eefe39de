"""Targets from CSV: ``lat,lon`` in WGS84 degrees, or ``x,y`` in local metres.

A header row names the columns (case and surrounding spaces ignored):

- ``lat``/``latitude`` and ``lon``/``lng``/``longitude``: degrees -> :class:`GeoTargets`;
- ``x``/``x_m`` and ``y``/``y_m``: metres east and north of an origin -> :class:`Targets`;
- optional ``alt``/``altitude``/``alt_m`` (metres above home; an empty cell: the mission's
  altitude) and ``name``;
- optional actions at the targets (:mod:`.actions`): ``photo`` and ``roi`` (yes/no),
  ``gimbal_pitch`` (degrees) and ``loiter_turns`` (whole circles); an empty cell: none.

Fields are separated by commas, semicolons or tabs (whichever the header uses); lines starting
with ``#`` are comments; a quoted field may hold the separator or a line break.  A column name
that looks like a misspelt one (``atl``, ``nmae``) is refused, saying which was meant; other
columns (and x/y beside lat/lon) are read, not used, and listed in
:attr:`~dtsp_mission.targets.model.GeoTargets.unused_columns`.  Rows at the same position are
merged when they agree and refused, naming both lines, when they differ (altitude, name,
actions).  Errors name the file and the file's line (comments and blank lines counted).
"""

from __future__ import annotations

import csv
import os
from dataclasses import replace

import numpy as np

from ..errors import FileFormatError
from ..files import read_text
from ..frame import check_geodetic
from ..errors import InputError
from .actions import COLUMNS as ACTION_COLUMNS, actions_from_columns, column_key, parse_cell
from .model import GeoTargets, Targets, check_altitudes, geodetic_targets, local_targets

_COLUMNS = {
    "lat": ("lat", "latitude"), "lon": ("lon", "lng", "longitude"),
    "x": ("x", "x_m"), "y": ("y", "y_m"),
    "alt": ("alt", "altitude", "alt_m"), "name": ("name",),
}


_DEGREES = {"lat": 90.0, "lon": 180.0}


def misspelt_column(label: str, found=()) -> str | None:
    """The column name ``label`` looks like a misspelling of (one letter off, letters swapped),
    among the columns not ``found`` already, or None."""
    import difflib
    known = [spelling for key, spellings in {**_COLUMNS, **ACTION_COLUMNS}.items()
             if key not in found for spelling in spellings]
    for name in known:
        if len(label) == len(name) and sorted(label) == sorted(name) and label != name:
            return name                          # letters swapped: atl, lnog
    close = difflib.get_close_matches(label, known, n=1, cutoff=0.8)
    return close[0] if close else None


def _header(path, header: list[str], line: int) -> tuple[dict[str, int], tuple[str, ...]]:
    found: dict[str, int] = {}
    unused = []
    for index, raw in enumerate(header):
        label = raw.strip().lower()
        for key, spellings in _COLUMNS.items():
            if label in spellings:
                if key in found:
                    raise FileFormatError(f"{path}, line {line}: column {key!r} is given twice")
                found[key] = index
                break
        else:
            action = column_key(label)
            if action is None:
                unused.append(raw.strip())
            elif action in found:
                raise FileFormatError(f"{path}, line {line}: column {action!r} is given twice")
            else:
                found[action] = index
    for label in unused:
        meant = misspelt_column(label.lower(), found)
        if meant:
            raise FileFormatError(
                f"{path}, line {line}: column {label!r} is not one this reads: did you mean "
                f"{meant!r}? (rename it; a column of another name is listed as not used)")
    geodetic = "lat" in found and "lon" in found
    local = "x" in found and "y" in found
    if geodetic == local:
        raise FileFormatError(
            f"{path}, line {line}: the header must name either columns lat and lon (degrees) or "
            f"x and y (metres), with optional alt (metres above home) and name; found "
            f"{', '.join(h.strip() for h in header)}")
    unused = list(unused)
    # a coordinate column of the other system beside a whole pair is read by nobody: say so
    for key in ("x", "y") if geodetic else ("lat", "lon"):
        if key in found:
            unused.append(header[found.pop(key)].strip())
    return found, tuple(unused)


def _delimiter(header_line: str) -> str:
    """The separator the header uses: a tab, a semicolon or (the default) a comma."""
    counts = {delimiter: header_line.count(delimiter) for delimiter in ("\t", ";", ",")}
    best = max(counts, key=counts.get)
    return best if counts[best] else ","


def read_csv(path: str | os.PathLike, text: str | None = None) -> GeoTargets | Targets:
    """Targets from a CSV file (``text``: its content, already read); duplicates (same
    coordinates) are merged and counted."""
    text = read_text(path) if text is None else text
    lines = text.splitlines(keepends=True)
    content = [line for line in lines if line.strip() and not line.lstrip().startswith("#")]
    if not content:
        raise FileFormatError(f"{path}: the file is empty")
    delimiter = _delimiter(content[0])
    # comment lines are blanked, not dropped, so that the reader's line count is the file's
    reader = csv.reader(("\n" if line.lstrip().startswith("#") else line for line in lines),
                        delimiter=delimiter, strict=True)
    rows, line_of = [], []
    last = 0
    try:
        for row in reader:
            first_line, last = last + 1, reader.line_num
            if last > first_line and any(delimiter in part for cell in row
                                         for part in cell.splitlines()[1:]):
                # a quoted field may span lines, but one that holds whole rows is a quote left
                # open, which swallows the targets after it
                raise FileFormatError(f"{path}, line {first_line}: a quoted field runs on to line "
                                      f"{last} and takes in lines that look like rows (a quote "
                                      "left open?)")
            if any(cell.strip() for cell in row):
                rows.append(row)
                line_of.append(first_line)
    except csv.Error as error:
        if "end of data" in str(error):
            raise FileFormatError(f"{path}, line {last + 1}: a quote opened here is never closed "
                                  "(it would take every line after it into one cell)") from None
        raise FileFormatError(f"{path}, line {reader.line_num}: {error}") from None
    columns, unused = _header(path, rows[0], line_of[0])
    geodetic = "lat" in columns
    first, second = ("lat", "lon") if geodetic else ("x", "y")
    numbers: dict[str, list[float]] = {key: [] for key in (first, second, "alt") if key in columns}
    names: list[str] = []
    actions: dict[str, list] = {key: [] for key in columns if column_key(key)}
    for line, row in zip(line_of[1:], rows[1:]):
        if len(row) != len(rows[0]):
            raise FileFormatError(f"{path}, line {line}: {len(row)} fields where the header has "
                                  f"{len(rows[0])}")
        for key, values in numbers.items():
            cell = row[columns[key]].strip()
            if key == "alt" and not cell:
                values.append(float("nan"))          # the mission's altitude
                continue
            try:
                value = float(cell)
            except ValueError:
                raise FileFormatError(f"{path}, line {line}: {key} must be a number, got "
                                      f"{cell!r}") from None
            if not np.isfinite(value):
                raise FileFormatError(f"{path}, line {line}: {key} must be a finite number, "
                                      f"got {cell!r}")
            limit = _DEGREES.get(key)
            if limit is not None and abs(value) > limit:
                raise FileFormatError(f"{path}, line {line}: {key} {cell.strip()} is not a number "
                                      f"between -{limit:g} and {limit:g} degrees")
            values.append(value)
        if "name" in columns:
            names.append(row[columns["name"]].strip())
        for key, cells in actions.items():
            try:
                cells.append(parse_cell(key, row[columns[key]], f"{path}, line {line}"))
            except InputError as error:
                raise FileFormatError(str(error)) from None
    if not names and not numbers[first]:
        raise FileFormatError(f"{path}: there are no targets below the header")
    altitudes = np.array(numbers["alt"]) if "alt" in numbers else None
    row_names = [f"line {line}" for line in line_of[1:]]
    check_altitudes(altitudes, str(path), row_names)
    if altitudes is not None and np.isnan(altitudes).all():
        altitudes = None
    name_tuple = tuple(names) if "name" in columns else None
    action_arrays = actions_from_columns(actions, len(numbers[first]))
    if geodetic:
        check_geodetic(numbers["lat"], numbers["lon"], f"{path}: target")
        targets = geodetic_targets(numbers["lat"], numbers["lon"], name_tuple, altitudes,
                                   actions=action_arrays, where=str(path), rows=row_names)
    else:
        targets = local_targets(np.column_stack([numbers["x"], numbers["y"]]), name_tuple,
                                altitudes, action_arrays, where=str(path), rows=row_names)
    return replace(targets, unused_columns=unused) if unused else targets
