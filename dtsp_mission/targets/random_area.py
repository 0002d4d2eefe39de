"""Seeded uniform random targets inside a survey polygon."""

from __future__ import annotations

import numpy as np
import shapely

from ..dubins.path import check_radius
from ..errors import InputError
from ..frame import LocalFrame
from .model import GeoTargets, geodetic_targets


def _local_polygon(area_deg: np.ndarray) -> tuple[LocalFrame, shapely.Polygon]:
    area = np.asarray(area_deg, dtype=float)
    frame = LocalFrame.around(area[:, 0], area[:, 1], "survey area vertices")
    return frame, shapely.Polygon(frame.to_local(area[:, 0], area[:, 1]))


def check_random_area(area_deg: np.ndarray, rho_m: float, where: str) -> None:
    """:class:`InputError` unless the polygon is at least one turn circle (pi rho^2) in area:
    uniform targets in anything smaller measure nothing but the aircraft's turning (and in a
    square centimetre lie closer together than any position fix resolves)."""
    check_radius(rho_m)
    _, polygon = _local_polygon(area_deg)
    turn = np.pi * rho_m ** 2
    if not polygon.area >= turn:
        raise InputError(f"{where}: the area is {polygon.area:,.3g} m^2, smaller than one turn "
                         f"of the aircraft (pi rho^2 = {turn:,.0f} m^2 at rho {rho_m:g} m): "
                         "random targets in it would test nothing but turning; draw them in a "
                         "larger area or give the targets themselves")


def random_targets(area_deg: np.ndarray, count: int, seed: int) -> GeoTargets:
    """``count`` targets uniformly distributed (by area, in the mission's local frame) inside
    the polygon ``area_deg`` ((k, 2) rows of latitude, longitude).  The same seed gives the same
    targets."""
    if count < 1:
        raise InputError(f"random targets: the count (`count`) must be at least 1, got {count}")
    area = np.asarray(area_deg, dtype=float)
    frame, polygon = _local_polygon(area)
    if not polygon.area > 0:
        raise InputError("random targets: the survey area has no extent to draw targets in")
    shapely.prepare(polygon)
    x_min, y_min, x_max, y_max = polygon.bounds
    generator = np.random.default_rng(seed)
    fill = polygon.area / ((x_max - x_min) * (y_max - y_min))
    accepted: list[np.ndarray] = []
    have = 0
    while have < count:
        batch = int(1.2 * (count - have) / fill) + 16
        points = generator.uniform((x_min, y_min), (x_max, y_max), size=(batch, 2))
        inside = points[shapely.contains_xy(polygon, points[:, 0], points[:, 1])]
        accepted.append(inside)
        have += len(inside)
    positions = np.concatenate(accepted)[:count]
    latitudes, longitudes = frame.to_geodetic(positions)
    return geodetic_targets(latitudes, longitudes, None, None, area)
