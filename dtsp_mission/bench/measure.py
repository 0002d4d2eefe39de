"""Timing and peak-memory measurement shared by every benchmark."""

from __future__ import annotations

import statistics
import time
import tracemalloc
from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Measurement:
    median_s: float
    runs_s: tuple[float, ...]
    peak_bytes: int          # peak of Python and numpy allocations during one run


def measure(function: Callable[[], object], repeats: int) -> Measurement:
    """Run ``function`` ``repeats`` times (after one warm-up run, which also compiles
    anything compiled lazily) and return the median wall time and the peak traced memory."""
    function()
    runs = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        runs.append(time.perf_counter() - start)
    tracemalloc.start()
    try:
        function()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return Measurement(statistics.median(runs), tuple(runs), peak)


def format_table(header: list[str], rows: list[list[str]]) -> str:
    """A plain-text table with right-aligned columns."""
    widths = [max(len(str(cell)) for cell in column) for column in zip(header, *rows)]
    lines = ["  ".join(str(cell).rjust(width) for cell, width in zip(row, widths))
             for row in [header, *rows]]
    lines.insert(1, "  ".join("-" * width for width in widths))
    return "\n".join(lines)
