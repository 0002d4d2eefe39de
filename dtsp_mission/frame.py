"""The local metric frame: the one place where geodetic coordinates become metres and back.

The planner works in a flat frame (x east, y north, metres).  This module maps WGS84 latitude
and longitude to that frame with pyproj's azimuthal equidistant projection centred on the
mission, and back.  Distances and bearings from the centre are exact (geodesics on the
ellipsoid); away from the centre lengths across the radial direction grow by the factor
``(d / R) / sin(d / R)``, about ``1 + d^2 / (6 R^2)``.  A frame refuses points where that
scale error exceeds :data:`MAX_SCALE_ERROR` (1e-4, i.e. 0.1 m per km, reached about 150 km
from the centre), so the flat tour and the flown tour differ by less than that.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from pyproj import Proj, Transformer

from .errors import InputError

#: Largest relative length error of the flat frame accepted at any mission point.
MAX_SCALE_ERROR = 1e-4


def check_geodetic(latitudes_deg: np.ndarray, longitudes_deg: np.ndarray,
                   what: str = "target") -> None:
    """Raise :class:`InputError` naming the first coordinate that is not a finite latitude in
    [-90, 90] or longitude in [-180, 180] degrees."""
    latitudes = np.asarray(latitudes_deg, dtype=float).reshape(-1)
    longitudes = np.asarray(longitudes_deg, dtype=float).reshape(-1)
    for name, values, limit in (("latitude", latitudes, 90.0), ("longitude", longitudes, 180.0)):
        bad = ~np.isfinite(values) | (np.abs(values) > limit)
        if bad.any():
            index = int(np.argmax(bad))
            raise InputError(f"{what} {index + 1}: {name} {float(values[index])!r} is not a number "
                             f"between -{limit:g} and {limit:g} degrees")


def mission_centre(latitudes_deg: np.ndarray, longitudes_deg: np.ndarray) -> tuple[float, float]:
    """A centre for the frame: middle of the latitude range and of the longitude range, the
    latter taken on the circle so that missions across the antimeridian are centred on it."""
    latitudes = np.asarray(latitudes_deg, dtype=float)
    longitudes = np.radians(np.asarray(longitudes_deg, dtype=float))
    mean_direction = np.arctan2(np.mean(np.sin(longitudes)), np.mean(np.cos(longitudes)))
    relative = np.degrees(np.angle(np.exp(1j * (longitudes - mean_direction))))
    centre_lon = np.degrees(mean_direction) + 0.5 * (relative.min() + relative.max())
    centre_lon = (centre_lon + 180.0) % 360.0 - 180.0
    return 0.5 * float(latitudes.min() + latitudes.max()), float(centre_lon)


@dataclass(frozen=True)
class LocalFrame:
    """Azimuthal equidistant frame on WGS84 centred at (``origin_lat_deg``, ``origin_lon_deg``).

    ``to_local`` and ``to_geodetic`` are inverse to about a micrometre (measured in the tests
    over 30 km).  Both accept arrays.
    """

    origin_lat_deg: float
    origin_lon_deg: float
    _projection: Proj = field(init=False, repr=False, compare=False)
    _forward: Transformer = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        check_geodetic(self.origin_lat_deg, self.origin_lon_deg, "frame origin")
        definition = (f"+proj=aeqd +lat_0={self.origin_lat_deg!r} +lon_0={self.origin_lon_deg!r} "
                      "+x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs")
        object.__setattr__(self, "_projection", Proj(definition))
        object.__setattr__(self, "_forward", Transformer.from_proj("EPSG:4326", definition,
                                                                   always_xy=True))

    def to_local(self, latitudes_deg: np.ndarray, longitudes_deg: np.ndarray) -> np.ndarray:
        """Local positions (k, 2), x east and y north in metres."""
        x, y = self._forward.transform(np.asarray(longitudes_deg, dtype=float),
                                       np.asarray(latitudes_deg, dtype=float), errcheck=True)
        return np.column_stack([np.reshape(x, -1), np.reshape(y, -1)])

    def to_geodetic(self, positions_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Latitudes and longitudes (degrees, longitudes in [-180, 180]) of local positions."""
        positions = np.asarray(positions_m, dtype=float).reshape(-1, 2)
        lon, lat = self._forward.transform(positions[:, 0], positions[:, 1],
                                           direction="INVERSE", errcheck=True)
        lon = (np.asarray(lon) + 180.0) % 360.0 - 180.0
        return np.asarray(lat, dtype=float), lon

    def scale_error(self, latitudes_deg: np.ndarray, longitudes_deg: np.ndarray) -> np.ndarray:
        """Largest relative length error of the flat frame at each point (0 at the centre)."""
        factors = self._projection.get_factors(np.asarray(longitudes_deg, dtype=float),
                                               np.asarray(latitudes_deg, dtype=float))
        return np.maximum(np.abs(np.asarray(factors.tissot_semimajor) - 1.0),
                          np.abs(np.asarray(factors.tissot_semiminor) - 1.0))

    def check_extent(self, latitudes_deg: np.ndarray, longitudes_deg: np.ndarray,
                     what: str = "targets") -> None:
        """Raise :class:`InputError` if any point is too far from the centre for the flat frame
        (scale error above :data:`MAX_SCALE_ERROR`)."""
        latitudes = np.asarray(latitudes_deg, dtype=float).reshape(-1)
        longitudes = np.asarray(longitudes_deg, dtype=float).reshape(-1)
        if latitudes.size == 0:
            return
        error = self.scale_error(latitudes, longitudes)
        error = np.where(np.isfinite(error), error, np.inf)
        worst = int(np.argmax(error))
        if error[worst] > MAX_SCALE_ERROR:
            distance_km = float(np.hypot(*self.to_local(latitudes[worst], longitudes[worst])[0])) / 1e3
            raise InputError(
                f"the {what} span too large an area for one flat mission frame: point "
                f"{worst + 1} ({latitudes[worst]:.6f}, {longitudes[worst]:.6f}) is "
                f"{distance_km:,.0f} km from the mission centre ({self.origin_lat_deg:.6f}, "
                f"{self.origin_lon_deg:.6f}), where lengths would be off by "
                f"{error[worst] * 1e3:.2g} m per km (the limit is {MAX_SCALE_ERROR * 1e3:g} m per "
                "km, about 150 km from the centre); split the targets into smaller missions")

    @classmethod
    def around(cls, latitudes_deg: np.ndarray, longitudes_deg: np.ndarray,
               what: str = "targets") -> "LocalFrame":
        """The frame centred on the points, after checking they are valid and fit in it."""
        check_geodetic(latitudes_deg, longitudes_deg, what.rstrip("s"))
        frame = cls(*mission_centre(latitudes_deg, longitudes_deg))
        frame.check_extent(latitudes_deg, longitudes_deg, what)
        return frame
