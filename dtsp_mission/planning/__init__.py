"""Planners: from targets in the local metric frame to a checked closed Dubins tour.

Every planner, built-in or third-party, registers in the ``dtsp_mission.planners`` entry-point
group (a :class:`~dtsp_mission.planning.base.Planner` subclass); :func:`planners` lists them and
:func:`get_planner` makes one.
"""

from __future__ import annotations

import logging
from importlib.metadata import entry_points
from typing import Any

from ..errors import InputError
from .base import Planner
from .region import Region, bounding_region, minimum_area_region
from .tiling import TilingUnavailable

PLANNER_GROUP = "dtsp_mission.planners"
log = logging.getLogger(__name__)


def planners() -> dict[str, type[Planner] | Exception]:
    """Installed planners by name; a plugin that fails to load maps to the error it raised."""
    found: dict[str, type[Planner] | Exception] = {}
    for entry_point in sorted(entry_points(group=PLANNER_GROUP), key=lambda e: e.name):
        try:
            planner = entry_point.load()
            if not (isinstance(planner, type) and issubclass(planner, Planner)):
                raise TypeError(f"{entry_point.value} is not a Planner subclass")
            found[entry_point.name] = planner
        except Exception as error:  # a broken plugin must not break planning
            log.warning("planner plugin %r is broken: %r", entry_point.name, error)
            found[entry_point.name] = error
    return found


def get_planner(name: str, **parameters: Any) -> Planner:
    """An instance of the planner registered as ``name``."""
    available = planners()
    planner = available.get(name)
    if planner is None:
        working = ", ".join(n for n, p in available.items() if not isinstance(p, Exception))
        raise InputError(f"unknown planner {name!r} (installed: {working})")
    if isinstance(planner, Exception):
        raise InputError(f"planner {name!r} is installed but broken: {planner!r}")
    return planner(**parameters)


__all__ = ["PLANNER_GROUP", "Planner", "Region", "TilingUnavailable", "bounding_region",
           "get_planner", "minimum_area_region", "planners"]
