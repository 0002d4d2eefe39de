"""The exact tour (tour JSON, ``docs/tour-json.md``) as an exporter."""

from __future__ import annotations

from ..frame import LocalFrame
from ..mission import Mission
from ..tour import Tour
from ..tour.json_form import dumps
from .base import Exporter


class TourJSONExporter(Exporter):
    """Tour JSON (``.json``): exact segments; with a mission, also the frame's origin."""

    name = "tour"
    extensions = (".json",)
    description = "tour JSON file"
    needs_mission = False

    def render(self, product: Mission | Tour) -> str:
        if isinstance(product, Mission):
            return dumps(product.tour, (product.frame.origin_lat_deg, product.frame.origin_lon_deg))
        return dumps(product)

    def render_tour(self, tour: Tour, frame: LocalFrame) -> str:
        return dumps(tour, (frame.origin_lat_deg, frame.origin_lon_deg))
