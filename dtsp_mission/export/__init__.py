"""Exporters: the mission (or tour) as files other tools read.

Every exporter, built-in or third-party, registers in the ``dtsp_mission.exporters``
entry-point group as an :class:`Exporter` subclass; :func:`exporters` lists them and
:func:`exporter_for` picks one by name (``format_name``) or from the file extension.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from ..plugins import load_group, working
from .base import Exporter, flight_path_deg

EXPORTER_GROUP = "dtsp_mission.exporters"


def exporters() -> dict[str, type[Exporter] | Exception]:
    """Installed exporters by name; a plugin that fails to load maps to its error."""
    return load_group(EXPORTER_GROUP, lambda e: isinstance(e, type) and issubclass(e, Exporter),
                      "an Exporter subclass")


def exporter_for(path: str | os.PathLike, format_name: str | None = None,
                 reading: bool = False) -> Exporter:
    """The exporter named ``format_name``, or else the one whose extensions match ``path``;
    ``reading``: among the formats a mission is read from (and the tour)."""
    available = working(exporters())
    if reading:
        available = {n: e for n, e in available.items() if e.readable or n == "tour"}
    if format_name is not None:
        if format_name not in available:
            raise InputError(f"unknown output format {format_name!r} (installed: "
                             f"{', '.join(sorted(available))})")
        return available[format_name]()
    name = Path(path).name.lower()
    matches = [(len(ext), n) for n, e in available.items() for ext in e.extensions
               if name.endswith(ext)]
    if not matches:
        known = ", ".join(sorted(ext for e in available.values() for ext in e.extensions))
        raise InputError(f"{path}: cannot tell the {'mission' if reading else 'output'} format "
                         f"from the file name; {'this reads' if reading else 'use'} one of "
                         f"{known}, or name the format (`format_name`)")
    return available[max(matches)[1]]()


def read_mission(path: str | os.PathLike, format_name: str | None = None):
    """The :class:`~dtsp_mission.mission.VehicleMission` in a mission file (``.plan``,
    ``.waypoints``, or any readable plugin format)."""
    exporter = exporter_for(path, format_name, reading=True)
    if not exporter.readable:
        readable = ", ".join(sorted(ext for e in working(exporters()).values() if e.readable
                                    for ext in e.extensions))
        raise InputError(f"{path}: {exporter.description or exporter.name} files hold no mission "
                         f"items; give one of {readable}")
    return exporter.read(path)


__all__ = ["EXPORTER_GROUP", "Exporter", "exporter_for", "exporters", "flight_path_deg", "read_mission"]
