"""Regenerates the geodetic examples: a made-up industrial site in open farmland (the points of
examples/site-local.csv without the random survey points, placed on the earth) and a polygon
survey area next to it.  Seeded and deterministic: the same files every time.

    examples/site-inspection.csv   lat,lon,alt,name (alt: metres above home)
    examples/survey-area.geojson   one Polygon feature (for --random N --area ...)
"""

import csv
import json
from pathlib import Path

import numpy as np
from pyproj import Transformer

HERE = Path(__file__).parent
ORIGIN_LAT, ORIGIN_LON = 46.80512, 6.94087         # (0, 0) of site-local.csv
ALTITUDE_BY_KIND = {"line": 90.0, "tank": 70.0, "fence": 60.0}

to_degrees = Transformer.from_proj("EPSG:4326", f"+proj=aeqd +lat_0={ORIGIN_LAT} "
                                   f"+lon_0={ORIGIN_LON} +ellps=WGS84 +units=m", always_xy=True)
with open(HERE / "site-local.csv", newline="") as stream:
    rows = [row for row in csv.DictReader(stream) if not row["name"].startswith("survey")]
x = np.array([float(row["x"]) for row in rows])
y = np.array([float(row["y"]) for row in rows])
lon, lat = to_degrees.transform(x, y, direction="INVERSE")
lines = ["lat,lon,alt,name"]
for row, latitude, longitude in zip(rows, lat, lon):
    kind = row["name"].split("-")[0].rstrip("0123456789")
    lines.append(f"{latitude:.8f},{longitude:.8f},{ALTITUDE_BY_KIND[kind]:.0f},{row['name']}")
(HERE / "site-inspection.csv").write_text("\n".join(lines) + "\n")

# A 4 km x 2.5 km field block east of the site, with one corner cut off.
corners = np.array([(3600, 0), (7600, 200), (7400, 2700), (5000, 2600), (3700, 1900)])
lon, lat = to_degrees.transform(corners[:, 0], corners[:, 1], direction="INVERSE")
ring = [[round(a, 8), round(b, 8)] for a, b in zip(lon, lat)]
area = {"type": "FeatureCollection", "features": [{
    "type": "Feature", "properties": {"name": "survey area"},
    "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}]}
(HERE / "survey-area.geojson").write_text(json.dumps(area, indent=1) + "\n")
