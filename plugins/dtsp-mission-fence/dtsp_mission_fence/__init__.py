"""A QGroundControl ``.plan`` with a safety net: an inclusion geofence around the flight path and
a rally point, for ``-o mission.fence.plan`` (or ``--format plan-fence``).

A first-party plugin using only dtsp-mission's public API.  It is the built-in ``.plan``
exporter (same mission items, same loader checks, readable by ``upload``) with two additions:

* ``geoFence``: one inclusion polygon, convex, holding the whole flight path with at least
  ``fence_margin_m`` to spare everywhere (the turn radius, and never less than 50 m: the
  distance an aircraft that lags its path by one turn radius can stray);
* ``rallyPoints``: one point above home at the highest altitude the mission flies, so a return
  to launch (ArduPlane RTL loiters at the nearest rally point) stays at a safe height.

The polygon is the convex hull of the exact path (sampled within 1.5e-4 rho), simplified, then
widened by the margin plus the simplification tolerance, with few vertices per corner:
autopilots keep fence vertices in small tables.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import shapely

from dtsp_mission.export.qgc_plan import QGCPlanExporter
from dtsp_mission.mission import Mission

MIN_MARGIN_M = 50.0
#: Corner segments per quarter circle of the widened hull; the chords of these corners stay
#: at least cos(pi / 8) of the widening away from the hull, which the widening allows for.
QUAD_SEGMENTS = 2


def fence_margin_m(mission: Mission) -> float:
    """Room between the flight path and the fence: rho, at least 50 m."""
    return max(MIN_MARGIN_M, mission.rho_m)


def fence_polygon_local(mission: Mission) -> np.ndarray:
    """Vertices (x_m, y_m in the mission's local frame, counter-clockwise, not closed) of a
    convex polygon holding every point of the flight path at least the margin inside."""
    chain = mission.path.chain
    s = np.linspace(0.0, chain.length_m, max(64, int(chain.length_m / (0.05 * mission.rho_m))))
    hull = shapely.convex_hull(shapely.MultiPoint(chain.pose_at(s)[:, :2]))
    margin = fence_margin_m(mission)
    # Sampling every 0.05 rho misses at most rho (1 - cos(0.025)) ~ 3e-4 rho of an arc.
    tolerance = 0.1 * margin
    simple = shapely.simplify(hull, tolerance, preserve_topology=True)
    widening = (margin + tolerance + 1e-3 * mission.rho_m) / math.cos(math.pi / (4 * QUAD_SEGMENTS))
    fence = shapely.convex_hull(shapely.buffer(simple, widening, quad_segs=QUAD_SEGMENTS))
    fence = shapely.geometry.polygon.orient(fence, 1.0)
    return np.asarray(fence.exterior.coords)[:-1]


class FencedPlanExporter(QGCPlanExporter):
    """QGroundControl plan with an inclusion geofence and a rally point (``.fence.plan``)."""

    name = "plan-fence"
    extensions = (".fence.plan",)
    description = "QGroundControl .plan file with geofence and rally point"

    def geofence_deg(self, mission: Mission) -> list[tuple[bool, np.ndarray]]:
        """The geofence polygons this writes: (inclusion, rows of latitude, longitude) -- for
        a map of the mission."""
        latitudes, longitudes = mission.frame.to_geodetic(fence_polygon_local(mission))
        return [(True, np.column_stack([latitudes, longitudes]))]

    def document(self, mission: Mission) -> dict[str, Any]:
        data = super().document(mission)
        latitudes, longitudes = mission.frame.to_geodetic(fence_polygon_local(mission))
        data["geoFence"]["polygons"] = [{
            "inclusion": True,
            "polygon": [[float(lat), float(lon)] for lat, lon in zip(latitudes, longitudes)],
            "version": 1,
        }]
        highest = max(item.altitude_m for item in mission.items if item.has_position)
        home = mission.home
        data["rallyPoints"]["points"] = [[home.latitude_deg, home.longitude_deg, float(highest)]]
        return data
