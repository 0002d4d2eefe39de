"""Seeded uniform random targets inside a survey polygon."""

from __future__ import annotations

import numpy as np
import shapely

from ..errors import InputError
from ..frame import LocalFrame
from .model import GeoTargets, geodetic_targets


def random_targets(area_deg: np.ndarray, count: int, seed: int) -> GeoTargets:
    """``count`` targets uniformly distributed (by area, in the mission's local frame) inside
    the polygon ``area_deg`` ((k, 2) rows of latitude, longitude).  The same seed gives the same
    targets."""
    if count < 1:
        raise InputError(f"random targets: the count (--random) must be at least 1, got {count}")
    area = np.asarray(area_deg, dtype=float)
    frame = LocalFrame.around(area[:, 0], area[:, 1], "survey area vertices")
    polygon = shapely.Polygon(frame.to_local(area[:, 0], area[:, 1]))
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
