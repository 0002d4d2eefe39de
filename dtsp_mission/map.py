"""An interactive map of a mission (``plan --map mission.html``): one self-contained HTML file.

Drawn with Bokeh (``pip install dtsp-mission[plot]``), its JavaScript embedded in the file
(``bokeh.resources.INLINE``), so the overlay -- targets, the planned tour, the mission items in
order, take-off, the return, a geofence, the survey area -- opens and reads offline; the base
map comes from OpenStreetMap's public tile servers when the browser is online,
and is simply blank otherwise.  Positions are shown in Web Mercator (EPSG:3857), the tiles'
projection; hovering a target shows its name, visit number, the predicted miss and its
waypoint item, hovering an item its number, command, role, altitude and target.  Targets are
coloured by the miss the design predicts (the guidance design), on a scale from 0 to the
mission's ``--max-miss``.
"""

from __future__ import annotations

import html
import math

import numpy as np

from .errors import InputError
from .mission import Command, Mission

#: The base map: OpenStreetMap's standard tiles (public, no key, attributed on the map).
TILES = "OpenStreetMap Mapnik"


def require_bokeh() -> None:
    """Raise :class:`InputError` now, before any work, if Bokeh is missing."""
    try:
        import bokeh  # noqa: F401
    except ImportError:
        raise InputError("drawing a map needs Bokeh: pip install 'dtsp-mission[plot]'") from None


def _mercator(latitudes_deg, longitudes_deg) -> tuple[np.ndarray, np.ndarray]:
    from pyproj import Transformer
    to_3857 = Transformer.from_crs("EPSG:4326", "EPSG:3857", always_xy=True)
    x, y = to_3857.transform(np.asarray(longitudes_deg, dtype=float),
                             np.asarray(latitudes_deg, dtype=float))
    return np.atleast_1d(x), np.atleast_1d(y)


def _command_name(command: int) -> str:
    try:
        return Command(command).name
    except ValueError:
        return f"command {command}"


def render_map(mission: Mission, max_miss_m: float | None = None,
               area_deg: np.ndarray | None = None,
               fences_deg: list[tuple[bool, np.ndarray]] = (), title: str = "") -> str:
    """The HTML page of ``mission``'s map.  ``area_deg``: the survey area (rows lat, lon);
    ``fences_deg``: geofence polygons (inclusion, rows lat, lon).  Guarantees: one file, no
    reference to anything but the tile servers (the overlay needs nothing else)."""
    require_bokeh()
    from bokeh.embed import file_html
    from bokeh.models import (ColorBar, ColumnDataSource, HoverTool, LinearColorMapper)
    from bokeh.palettes import Turbo256
    from bokeh.plotting import figure
    from bokeh.resources import INLINE

    from .export.base import flight_path_deg

    plot = figure(x_axis_type="mercator", y_axis_type="mercator", match_aspect=True,
                  sizing_mode="stretch_both", tools="pan,wheel_zoom,box_zoom,reset,save",
                  active_scroll="wheel_zoom",
                  title=title or f"{len(mission.tour.targets_m)} targets, {len(mission.items)} "
                                 f"mission items ({'PX4' if int(mission.autopilot) == 12 else 'ArduPilot'})")
    plot.add_tile(TILES, retina=True)
    if area_deg is not None:
        x, y = _mercator(area_deg[:, 0], area_deg[:, 1])
        plot.patch(x, y, fill_color="#8fbc8f", fill_alpha=0.15, line_color="#5a8a5a",
                   legend_label="survey area")
    for inclusion, ring in fences_deg:
        x, y = _mercator(ring[:, 0], ring[:, 1])
        plot.patch(np.append(x, x[:1]), np.append(y, y[:1]), fill_alpha=0.0,
                   line_color="#d62728" if inclusion else "#7f0000", line_width=2,
                   line_dash="dashed", legend_label="geofence")
    # the planned tour: the exact path (lines and arcs) the mission was made from
    latitudes, longitudes = flight_path_deg(mission)
    x, y = _mercator(latitudes, longitudes)
    plot.line(x, y, line_color="#1f5fa8", line_width=2, legend_label="planned path")
    # the mission items in order: what the autopilot is sent
    positioned = [(seq, item) for seq, item in enumerate(mission.items, start=1)
                  if item.has_position and item.command < 100]
    names = mission.target_names
    if positioned:
        ix, iy = _mercator([i.latitude_deg for _, i in positioned],
                           [i.longitude_deg for _, i in positioned])
        items = ColumnDataSource({
            "x": ix, "y": iy, "item": [seq for seq, _ in positioned],
            "command": [_command_name(int(i.command)) for _, i in positioned],
            "role": [i.role for _, i in positioned],
            "altitude": [f"{i.altitude_m:.0f} m" for _, i in positioned],
            "target": [("" if i.target < 0 else html.escape(
                names[i.target] if names else f"target {i.target + 1}")) for _, i in positioned]})
        plot.line("x", "y", source=items, line_color="#f28e2b", line_width=1, line_alpha=0.8,
                  legend_label="mission items, in order")
        dots = plot.scatter("x", "y", source=items, size=6, marker="square",
                            fill_color="#f28e2b", line_color="#8a4b0f",
                            legend_label="mission items, in order")
        plot.add_tools(HoverTool(renderers=[dots], tooltips=[
            ("item", "@item"), ("command", "@command"), ("role", "@role"),
            ("altitude", "@altitude"), ("target", "@target")]))
    # home: take-off and the return
    hx, hy = _mercator([mission.home.latitude_deg], [mission.home.longitude_deg])
    plot.scatter(hx, hy, size=16, marker="triangle", fill_color="black",
                 legend_label="home: take-off and return")
    if positioned:
        plot.line([hx[0], ix[0]], [hy[0], iy[0]], line_color="#555555", line_dash="dotted",
                  legend_label="home: take-off and return")
        if mission.items[-1].command in (Command.NAV_RETURN_TO_LAUNCH, Command.NAV_LAND):
            plot.line([ix[-1], hx[0]], [iy[-1], hy[0]], line_color="#555555", line_dash="dashed",
                      legend_label="home: take-off and return")
    # the targets, coloured by the predicted miss
    tlat, tlon = mission.target_positions_deg
    tx, ty = _mercator(tlat, tlon)
    count = len(tx)
    miss = (np.asarray(mission.guidance.predicted_miss_m, dtype=float)
            if mission.guidance is not None else np.full(count, np.nan))
    waypoint_item = {item.target: seq for seq, item in enumerate(mission.items, start=1)
                     if item.role == "target"}
    targets = ColumnDataSource({
        "x": tx, "y": ty,
        "name": [html.escape(names[k] if names else f"target {k + 1}") for k in range(count)],
        "visit": (mission.visit_numbers + 1).tolist(),
        "miss": np.where(np.isfinite(miss), miss, -1.0),
        "miss_text": [f"{m:.1f} m" if math.isfinite(m) else "not predicted (geometry design)"
                      for m in miss],
        "item": [waypoint_item.get(k, "") for k in range(count)]})
    top = max_miss_m if max_miss_m else float(np.nanmax(miss)) if np.isfinite(miss).any() else 1.0
    colours = LinearColorMapper(palette=Turbo256[40:230], low=0.0, high=max(top, 1e-3),
                                low_color="#bbbbbb", high_color="#7a0403")
    dots = plot.scatter("x", "y", source=targets, size=11, line_color="black",
                        fill_color={"field": "miss", "transform": colours},
                        legend_label="targets (colour: predicted miss)")
    plot.add_tools(HoverTool(renderers=[dots], tooltips=[
        ("target", "@name"), ("visit", "@visit"), ("predicted miss", "@miss_text"),
        ("waypoint item", "@item")]))
    plot.add_layout(ColorBar(color_mapper=colours, title="predicted miss, m", width=10), "right")
    plot.legend.location = "top_left"
    plot.legend.click_policy = "hide"
    return file_html(plot, resources=INLINE, title=title or "dtsp-mission: mission map")
