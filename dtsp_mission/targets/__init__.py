"""Reading targets: the first step of the pipeline.

Targets come as local metres (:class:`Targets`, what the planners take) or as WGS84 degrees
(:class:`GeoTargets`, what users usually have); :class:`~dtsp_mission.frame.LocalFrame` turns
one into the other.  Readers merge exact duplicates and count them, and say which line or
feature is wrong when something is.
"""

from .csv_file import read_csv
from .geojson_file import read_geojson
from .model import GeoTargets, Targets, merge_duplicates
from .random_area import random_targets
from .read import read_targets

__all__ = ["GeoTargets", "Targets", "merge_duplicates", "random_targets", "read_csv",
           "read_geojson", "read_targets"]
