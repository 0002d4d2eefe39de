"""Regenerates examples/site-local.csv: 420 inspection points of a made-up industrial site in a
local frame (metres, x east, y north): pylons along two power lines, tank rims, a fenced yard
perimeter and scattered survey points.  Seeded: the same file every time."""

from pathlib import Path

import numpy as np

rng = np.random.default_rng(2026)
points, names = [], []
for k, (start, end) in enumerate([((0, 300), (3200, 900)), ((400, 2100), (2900, 1500))]):
    for i, t in enumerate(np.linspace(0, 1, 60)):
        points.append(np.add(start, t * np.subtract(end, start)) + rng.normal(0, 3, 2))
        names.append(f"line{k + 1}-pylon{i + 1:02d}")
for k, centre in enumerate([(1500, 1200), (1650, 1250), (1580, 1050)]):
    for i, angle in enumerate(np.linspace(0, 2 * np.pi, 24, endpoint=False)):
        points.append(np.add(centre, 35 * np.array([np.cos(angle), np.sin(angle)])))
        names.append(f"tank{k + 1}-{i + 1:02d}")
for i, t in enumerate(np.linspace(0, 4, 80, endpoint=False)):
    side, f = int(t), t - int(t)
    corners = np.array([(2200, 200), (3000, 200), (3000, 700), (2200, 700), (2200, 200)])
    points.append(corners[side] + f * (corners[side + 1] - corners[side]))
    names.append(f"fence-{i + 1:02d}")
for i in range(420 - len(points)):
    points.append(rng.uniform([0, 0], [3200, 2200]))
    names.append(f"survey-{i + 1:03d}")
lines = ["name,x,y"] + [f"{n},{x:.2f},{y:.2f}" for n, (x, y) in zip(names, points)]
Path(__file__).with_name("site-local.csv").write_text("\n".join(lines) + "\n")
