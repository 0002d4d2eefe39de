"""Planners: from targets in the local metric frame to a checked closed Dubins tour.

Every planner, built-in or third-party, registers in the ``dtsp_mission.planners`` entry-point
group (a :class:`~dtsp_mission.planning.base.Planner` subclass); :func:`planners` lists them and
:func:`get_planner` makes one.
"""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..plugins import load_group
from .base import Planner
from .region import Region, bounding_region, minimum_area_region
from .tiling import TilingUnavailable

PLANNER_GROUP = "dtsp_mission.planners"


def planners() -> dict[str, type[Planner] | Exception]:
    """Installed planners by name; a plugin that fails to load maps to the error it raised."""
    return load_group(PLANNER_GROUP, lambda p: isinstance(p, type) and issubclass(p, Planner),
                      "a Planner subclass")


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
