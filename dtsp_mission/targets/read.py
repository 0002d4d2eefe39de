"""Choosing the reader from the file name."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import FileFormatError
from ..files import STDIN, read_text
from .csv_file import read_csv
from .geojson_file import read_geojson
from .model import GeoTargets, Targets

READERS = {".csv": read_csv, ".txt": read_csv, ".geojson": read_geojson, ".json": read_geojson}


def read_targets(path: str | os.PathLike) -> GeoTargets | Targets:
    """Targets from a CSV (``.csv``/``.txt``) or GeoJSON (``.geojson``/``.json``) file, or
    from standard input (``-``: GeoJSON if it starts with ``{``, else CSV)."""
    if str(path) == STDIN:
        text = read_text(STDIN)
        reader = read_geojson if text.lstrip().startswith("{") else read_csv
        targets = reader("standard input", text)
    else:
        suffix = Path(path).suffix.lower()
        if suffix not in READERS:
            raise FileFormatError(f"{path}: cannot tell the format from {suffix or 'no extension'!r}; "
                                  "targets are read from .csv or .geojson files")
        targets = READERS[suffix](path)
    if len(targets) == 0:
        raise FileFormatError(f"{path}: no point targets, only a survey area (a Polygon): give "
                              "Point features, or draw targets in the area (`count` N with "
                              f"`area` {path})")
    return targets
