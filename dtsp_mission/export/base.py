"""The exporter interface: one subclass per file format, registered as a plugin."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..frame import LocalFrame
from ..files import write_atomic
from ..mission import Mission, VehicleMission
from ..mission.discretise import candidate_s
from ..tour import Tour

#: Arcs of the flight path are sampled at least this often for drawing formats.
PATH_STEP_RAD = math.radians(2.0)


def lengths_text(mission: Mission) -> str:
    """The flight and the tour as ``plan`` reports them: 'flight: X km from take-off to the
    return (tour Y m)'; for plots and documents, so every output names the same two lengths."""
    return (f"flight: {mission.summary['flight_length_m'] / 1e3:,.2f} km from take-off to the "
            f"return (tour {mission.tour.length_m:,.1f} m)")


def flight_path_deg(mission: Mission, step_rad: float = PATH_STEP_RAD) -> tuple[np.ndarray, np.ndarray]:
    """Latitudes and longitudes (WGS84 degrees) of the flown path, sampled from its exact
    segments: every segment end, and arcs every ``step_rad`` of turn, so the polyline stays
    within ``rho (1 - cos(step_rad / 2))`` of the path (1.5e-4 rho at the default)."""
    s, _ = candidate_s(mission.path.chain, step_rad, np.zeros(0), 0.0)
    return mission.frame.to_geodetic(mission.path.chain.pose_at(s)[:, :2])


class Exporter:
    """Writes a mission (or, for formats that allow it, a bare tour) to a file.

    Subclasses set ``name``, ``extensions`` (lower case, with the dot), ``description`` and
    ``needs_mission``, and implement :meth:`render`.  :meth:`write` is the public method: it
    checks the input, renders the whole file in memory and writes it atomically, so a failure
    never leaves a half-written file.
    """

    name: str = ""
    extensions: tuple[str, ...] = ()
    description: str = ""
    needs_mission: bool = True

    def write(self, product: Mission | Tour, path: str | os.PathLike) -> Path:
        return write_atomic(path, self.render_for(product, path))

    def render_for(self, product: Mission | Tour, path: str | os.PathLike,
                   frame: LocalFrame | None = None) -> str | bytes:
        """The file's content for ``path``, or :class:`InputError` if this format needs a
        mission and ``product`` is a bare tour.  ``frame`` places a bare tour on the earth for
        formats that can say where it is (:meth:`render_tour`)."""
        if self.needs_mission and not isinstance(product, Mission):
            raise InputError(f"{path}: a {self.description or self.name} needs a mission in "
                             "degrees; give targets in lat/lon, or local x/y with an `origin`")
        if isinstance(product, Tour) and frame is not None:
            return self.render_tour(product, frame)
        return self.render(product)

    def render_tour(self, tour: Tour, frame: LocalFrame) -> str | bytes:
        """A bare tour planned in ``frame`` (formats that need no mission); by default as
        :meth:`render` writes it."""
        return self.render(tour)

    def render(self, product: Mission | Tour) -> str | bytes:
        """The complete file content."""
        raise NotImplementedError

    #: True when :meth:`read` gives back the mission items of a file of this format.
    readable: bool = False

    def read(self, path: str | os.PathLike) -> VehicleMission:
        """The items, home and autopilot of a file of this format; raises
        :class:`~dtsp_mission.errors.FileFormatError` naming what is wrong."""
        raise InputError(f"{path}: {self.description or self.name} files cannot be read back "
                         "as a mission")
