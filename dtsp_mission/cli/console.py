"""What a command tells its user: human lines, notes, and a summary a script can read.

Each command starts one :class:`Console` (:func:`start`) from its ``-q`` / ``--json`` options
and writes through :func:`say`, :func:`note` and :func:`record`.  Guarantees: with ``--json``
standard output carries exactly one JSON object (the human lines go to standard error), with
``-q`` nothing but errors and that object is printed; errors always reach standard error.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field

import click
import numpy as np


@dataclass
class Console:
    quiet: bool = False
    as_json: bool = False
    summary: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


_current = Console()

#: ``-q`` and ``--json``, for every command that reports.
console_options = [
    click.option("-q", "--quiet", is_flag=True,
                 help="Print nothing but errors (and the --json summary)."),
    click.option("--json", "as_json", is_flag=True,
                 help="Print one JSON summary on standard output at the end (lengths, items, "
                      "times, misses, files, notes); the other lines go to standard error."),
]


#: The library names the parameters a user sets in backticks, in its own terms (`max_items`);
#: a command prints the option that sets each.  Names not listed are printed as they are.
OPTIONS = {
    "max_items": "--max-items", "max_miss_m": "--max-miss", "min_altitude_m": "--min-alt",
    "gimbal_pitch_deg": "--gimbal-pitch", "loiter_turns": "--loiter",
    "loiter_radius_m": "--loiter-radius", "wind": "--wind", "wind_spread_m_s": "--wind-spread",
    "tolerance_m": "--tolerance", "endurance_s": "--endurance", "return_mode": "--return",
    "airspeed_m_s": "--airspeed", "autopilot": "--autopilot", "origin": "--origin",
    "signing_key": "--signing-key", "via": "--via", "verify=False": "--no-verify",
    "count": "--random", "format_name": "--format", "design": "--design",
    "landing_bearing_deg": "--landing-bearing", "home_deg": "--home", "area": "--area", "launch_bearing_deg": "--launch-bearing",
}


def in_cli_terms(text: str) -> str:
    """``text`` with each parameter the library names in backticks replaced by its option."""
    return re.sub(r"`([^`]+)`", lambda match: OPTIONS.get(match.group(1), match.group(0)), text)


def start(quiet: bool = False, as_json: bool = False) -> Console:
    """The console of the command now running."""
    global _current
    _current = Console(quiet, as_json)
    return _current


def current() -> Console:
    return _current


def say(text: str) -> None:
    """A line of the report (standard error with --json; nothing with -q)."""
    if not _current.quiet:
        click.echo(in_cli_terms(text), err=_current.as_json)


def note(text: str) -> None:
    """A note: kept for the summary, shown on standard error unless -q."""
    text = in_cli_terms(text)
    _current.notes.append(text)
    if not _current.quiet:
        click.echo(f"note: {text}", err=True)


def record(**values) -> None:
    """Values for the JSON summary."""
    _current.summary.update(values)


def finish() -> None:
    """Print the JSON summary (with --json)."""
    if _current.as_json:
        click.echo(json.dumps({**_current.summary, "notes": _current.notes}, default=_plain,
                              allow_nan=False, indent=2))


def _plain(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return str(value)
