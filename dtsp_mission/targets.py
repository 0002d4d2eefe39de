"""Reading targets: the first step of the pipeline.

Local-metre CSV: a header with ``x`` and ``y`` columns (``x_m``/``y_m`` also accepted; other
columns are ignored except ``name``).  Errors say which line and column are wrong.
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass

import numpy as np

from .errors import FileFormatError
from .files import read_text


@dataclass(frozen=True)
class Targets:
    """Target positions (n, 2) in the local frame and optional names."""

    positions_m: np.ndarray
    names: tuple[str, ...] | None = None
    merged_duplicates: int = 0      # how many repeated positions were dropped


def _column(header: list[str], choices: tuple[str, ...]) -> int | None:
    lowered = [h.strip().lower() for h in header]
    for choice in choices:
        if choice in lowered:
            return lowered.index(choice)
    return None


def merge_duplicates(positions_m: np.ndarray, names: tuple[str, ...] | None = None) -> Targets:
    """Keep the first of targets at exactly the same position (in input order)."""
    _, first = np.unique(positions_m, axis=0, return_index=True)
    keep = np.sort(first)
    merged = len(positions_m) - len(keep)
    kept_names = tuple(names[i] for i in keep) if names is not None else None
    return Targets(positions_m[keep], kept_names, merged)


def read_local_csv(path: str | os.PathLike) -> Targets:
    """Targets from a CSV file in local metres; duplicates are merged (and counted)."""
    text = read_text(path)
    rows = list(csv.reader(io.StringIO(text)))
    rows = [row for row in rows if any(cell.strip() for cell in row)]
    if not rows:
        raise FileFormatError(f"{path}: the file is empty")
    header = rows[0]
    x_column = _column(header, ("x", "x_m"))
    y_column = _column(header, ("y", "y_m"))
    if x_column is None or y_column is None:
        raise FileFormatError(f"{path}: the header must name columns 'x' and 'y' (metres); "
                              f"found {', '.join(h.strip() for h in header)}")
    name_column = _column(header, ("name",))
    positions, names = [], []
    for line, row in enumerate(rows[1:], start=2):
        try:
            x, y = float(row[x_column]), float(row[y_column])
        except (ValueError, IndexError):
            raise FileFormatError(f"{path}, line {line}: x and y must be numbers, got "
                                  f"{row!r}") from None
        if not (np.isfinite(x) and np.isfinite(y)):
            raise FileFormatError(f"{path}, line {line}: x and y must be finite numbers")
        positions.append((x, y))
        if name_column is not None:
            names.append(row[name_column].strip() if name_column < len(row) else "")
    if not positions:
        raise FileFormatError(f"{path}: there are no targets below the header")
    return merge_duplicates(np.array(positions), tuple(names) if name_column is not None else None)
