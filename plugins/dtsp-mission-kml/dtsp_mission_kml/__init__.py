"""KML (OGC KML 2.2) export of a dtsp-mission mission, for Google Earth and similar viewers.

A first-party plugin that uses only dtsp-mission's public API (``dtsp_mission.export``,
``dtsp_mission.mission``).  The document holds three folders:

* *Flight path*: the ground track, sampled from the exact lines and arcs by
  :func:`dtsp_mission.export.flight_path_deg` (within 1.5e-4 rho of the planned path), clamped
  to the ground: the mission's altitudes are above home, which KML cannot express;
* *Targets*: one placemark per target, named as in the input (or ``T<k>``), with its visit
  number, overflight altitude above home and mission item index;
* *Home*: the home position.

The XML is built with the standard library's ElementTree (escaping names correctly) and written
atomically by the exporter base class.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from dtsp_mission.export import Exporter, flight_path_deg
from dtsp_mission.export.base import lengths_text
from dtsp_mission.mission import Mission

KML_NAMESPACE = "http://www.opengis.net/kml/2.2"
PATH_COLOUR = "ff00d7ff"        # aabbggrr: opaque gold
TARGET_COLOUR = "ff3c14dc"      # opaque crimson


def _text(parent: ET.Element, tag: str, text: str) -> ET.Element:
    element = ET.SubElement(parent, tag)
    element.text = text
    return element


def _coordinates(longitudes, latitudes) -> str:
    return " ".join(f"{lon:.8f},{lat:.8f},0" for lon, lat in zip(longitudes, latitudes))


def _point(folder: ET.Element, name: str, description: str, style: str, latitude: float,
           longitude: float) -> None:
    placemark = ET.SubElement(folder, "Placemark")
    _text(placemark, "name", name)
    _text(placemark, "description", description)
    _text(placemark, "styleUrl", style)
    point = ET.SubElement(placemark, "Point")
    _text(point, "coordinates", _coordinates([longitude], [latitude]))


def _style(document: ET.Element, identifier: str, colour: str, line_width: float | None) -> None:
    style = ET.SubElement(document, "Style", id=identifier)
    if line_width is None:
        icon = ET.SubElement(style, "IconStyle")
        _text(icon, "color", colour)
        _text(icon, "scale", "0.6")
    else:
        line = ET.SubElement(style, "LineStyle")
        _text(line, "color", colour)
        _text(line, "width", f"{line_width:g}")


def kml_document(mission: Mission) -> ET.Element:
    """The mission as a KML element tree (root ``kml``)."""
    root = ET.Element("kml", xmlns=KML_NAMESPACE)
    document = ET.SubElement(root, "Document")
    tour = mission.tour
    _text(document, "name", f"dtsp-mission: {len(tour.targets_m)} targets, {tour.planner}")
    _text(document, "description",
          f"{lengths_text(mission)[:-1]}: the closed Dubins tour for turn radius "
          f"{mission.rho_m:g} m); {len(mission.items)} mission items; altitudes are above home.")
    _style(document, "path", PATH_COLOUR, 3.0)
    _style(document, "target", TARGET_COLOUR, None)
    _style(document, "home", "ffffffff", None)

    path_folder = ET.SubElement(document, "Folder")
    _text(path_folder, "name", "Flight path")
    placemark = ET.SubElement(path_folder, "Placemark")
    _text(placemark, "name", "flight path")
    _text(placemark, "styleUrl", "#path")
    line = ET.SubElement(placemark, "LineString")
    _text(line, "tessellate", "1")
    _text(line, "altitudeMode", "clampToGround")
    latitudes, longitudes = flight_path_deg(mission)
    _text(line, "coordinates", _coordinates(longitudes, latitudes))

    target_folder = ET.SubElement(document, "Folder")
    _text(target_folder, "name", "Targets")
    visit_rank = mission.visit_numbers
    latitudes, longitudes = mission.target_positions_deg
    for target, item_index in enumerate(mission.target_items):
        item = mission.items[item_index]
        name = (mission.target_names[target] if mission.target_names is not None
                else f"target {target + 1}")
        _point(target_folder, name,
               f"target {target + 1}, visit {visit_rank[target] + 1} of {len(visit_rank)}; "
               f"overfly at {item.altitude_m:g} m above home; mission item {item_index + 1}",
               "#target", latitudes[target], longitudes[target])

    home_folder = ET.SubElement(document, "Folder")
    _text(home_folder, "name", "Home")
    home = mission.home
    _point(home_folder, "home", f"{home.altitude_amsl_m:g} m above mean sea level", "#home",
           home.latitude_deg, home.longitude_deg)
    return root


class KMLExporter(Exporter):
    """KML for Google Earth (``.kml``): ground track, targets, home."""

    name = "kml"
    extensions = (".kml",)
    description = "KML file (Google Earth)"

    def render(self, mission: Mission) -> bytes:
        tree = kml_document(mission)
        ET.indent(tree)
        return ET.tostring(tree, encoding="utf-8", xml_declaration=True) + b"\n"
