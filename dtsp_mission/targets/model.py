"""Target sets in the local frame and in WGS84 degrees."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Sequence

import numpy as np
from scipy.spatial import cKDTree

from ..errors import InputError
from .actions import TargetActions

if TYPE_CHECKING:
    from ..frame import LocalFrame


@dataclass(frozen=True)
class Targets:
    """Target positions (n, 2) in a local frame (x east, y north, metres).

    ``altitudes_m`` (optional) is the altitude above home at which each target is overflown.
    """

    positions_m: np.ndarray
    names: tuple[str, ...] | None = None
    merged_duplicates: int = 0      # how many repeated positions were dropped
    altitudes_m: np.ndarray | None = None      # NaN: the mission's altitude
    unused_columns: tuple[str, ...] = ()       # columns of the file that were not used
    actions: TargetActions | None = None       # what to do at each target (None: overfly)

    def __len__(self) -> int:
        return len(self.positions_m)

    def to_geodetic(self, frame: "LocalFrame") -> "GeoTargets":
        """The same targets in degrees, through ``frame``."""
        latitudes, longitudes = frame.to_geodetic(self.positions_m)
        return GeoTargets(latitudes, longitudes, self.names, self.merged_duplicates,
                          self.altitudes_m, unused_columns=self.unused_columns,
                          actions=self.actions)


@dataclass(frozen=True)
class GeoTargets:
    """Targets in WGS84 degrees, with an optional survey area.

    ``area_deg`` is the outer ring of the survey polygon as (k, 2) rows of (latitude, longitude)
    or None.  ``altitudes_m`` as in :class:`Targets`.
    """

    latitudes_deg: np.ndarray
    longitudes_deg: np.ndarray
    names: tuple[str, ...] | None = None
    merged_duplicates: int = 0
    altitudes_m: np.ndarray | None = None      # NaN: the mission's altitude
    area_deg: np.ndarray | None = None
    unused_columns: tuple[str, ...] = ()       # columns of the file that were not used
    actions: TargetActions | None = None       # what to do at each target (None: overfly)
    rows: tuple[str, ...] | None = None        # where each target came from ("line 7")

    def __post_init__(self) -> None:
        """Raise :class:`InputError` (a message for a caller of the API, naming no command-line
        option) unless the coordinates are equally long 1-D arrays of finite WGS84 degrees and
        names and altitudes, where given, have one entry per target."""
        latitudes = np.asarray(self.latitudes_deg, dtype=float)
        longitudes = np.asarray(self.longitudes_deg, dtype=float)
        if latitudes.ndim != 1 or longitudes.ndim != 1 or len(latitudes) != len(longitudes):
            raise InputError(f"GeoTargets needs one latitude and one longitude per target: got "
                             f"{latitudes.size} latitudes and {longitudes.size} longitudes")
        from ..frame import check_geodetic
        check_geodetic(latitudes, longitudes)
        for label, values in (("names", self.names), ("altitudes", self.altitudes_m),
                              ("actions", self.actions), ("rows", self.rows)):
            if values is not None and len(values) != len(latitudes):
                raise InputError(f"GeoTargets has {len(latitudes)} targets but {len(values)} {label}")
        object.__setattr__(self, "latitudes_deg", latitudes)
        object.__setattr__(self, "longitudes_deg", longitudes)

    def __len__(self) -> int:
        return len(self.latitudes_deg)

    def in_frame(self, frame: "LocalFrame") -> Targets:
        """The same targets in the local frame (after checking they fit in it)."""
        frame.check_extent(self.latitudes_deg, self.longitudes_deg)
        return Targets(frame.to_local(self.latitudes_deg, self.longitudes_deg), self.names,
                       self.merged_duplicates, self.altitudes_m, self.unused_columns, self.actions)

    def with_area(self, area_deg: np.ndarray | None) -> "GeoTargets":
        return replace(self, area_deg=area_deg)

    def label(self, index: int) -> str:
        """How a message names target ``index`` (input order): the row of its file ("line
        7"), else its number; with its name where it has one."""
        name = self.names[index] if self.names else ""
        row = target_name(self.rows, index)
        return f"{row} ({name})" if name else row

    def subset(self, indices: np.ndarray) -> "GeoTargets":
        """The targets at ``indices`` (in that order), with their names, altitudes and actions."""
        keep = np.asarray(indices, dtype=np.int64)
        return replace(self, latitudes_deg=self.latitudes_deg[keep],
                       longitudes_deg=self.longitudes_deg[keep], names=_pick(self.names, keep),
                       altitudes_m=_pick(self.altitudes_m, keep), merged_duplicates=0,
                       actions=_pick(self.actions, keep), rows=_pick(self.rows, keep))


def target_name(names: Sequence[str] | None, index: int) -> str:
    """How the product names target ``index`` (input order): its name, else "target N"."""
    return names[index] if names else f"target {index + 1}"


#: The highest altitude above home a target or mission may use: beyond it a number is far more
#: likely a typo (or feet) than a fixed-wing survey.
MAX_ALTITUDE_M = 10_000.0


def check_altitudes(altitudes_m: np.ndarray | None, where: str,
                    rows: Sequence[str] | None = None) -> None:
    """Raise :class:`InputError` unless every altitude is a finite number above zero (or NaN:
    not given, the mission's altitude); the error names the row as ``rows`` does (``"line
    7"``), or the target's number.  The floor above home is the mission's to check."""
    if altitudes_m is None:
        return
    given = ~np.isnan(altitudes_m)
    bad = given & (~np.isfinite(altitudes_m) | (altitudes_m <= 0.0) | (altitudes_m > MAX_ALTITUDE_M))
    if bad.any():
        index = int(np.argmax(bad))
        row = target_name(rows, index)
        raise InputError(f"{where}, {row}: altitude {float(altitudes_m[index])!r} m must be "
                         f"a number above 0 and at most {MAX_ALTITUDE_M:,.0f} (metres above home)")


def _same(a, b) -> bool:
    return bool(a == b or (isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b)))


def check_conflicts(leader: np.ndarray, names, altitudes_m, actions: "TargetActions | None",
                    where: str, rows: Sequence[str] | None) -> None:
    """Raise :class:`InputError` naming both rows when two targets at the same position ask
    for different altitudes, actions or names (merging would silently drop one of them);
    ``leader`` is :func:`cluster_positions`' second result mapped back to row indices."""
    fields = []
    if altitudes_m is not None:
        fields.append(("altitude", lambda i: float(altitudes_m[i])))
    if names is not None:
        fields.append(("name", lambda i: names[i]))
    if actions is not None:
        fields += [("photo", lambda i: bool(actions.photo[i])), ("roi", lambda i: bool(actions.roi[i])),
                   ("gimbal_pitch", lambda i: float(actions.gimbal_pitch_deg[i])),
                   ("loiter_turns", lambda i: int(actions.loiter_turns[i]))]
    for j in np.flatnonzero(leader != np.arange(len(leader))):
        i = int(leader[j])
        for label, value in fields:
            if not _same(value(i), value(int(j))):
                first, second = target_name(rows, i), target_name(rows, int(j))
                raise InputError(f"{where}: {first} and {second} are at the same position with a "
                                 f"different {label} ({value(i)!r} and {value(int(j))!r}); "
                                 "remove one of them or move it")


def cluster_positions(positions: np.ndarray, resolution: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Group positions closer than ``resolution`` (``0``: exactly equal).

    Returns ``keep``, the indices (in input order) of the positions that stand for a group, and
    ``leader``, for every position the index into ``keep`` of the one standing for it.  Every
    position lies within ``resolution`` of its leader, and the first position of a group leads.
    """
    points = np.asarray(positions, dtype=float)
    points = points.reshape(len(points), points.shape[-1] if points.ndim > 1 else 1)
    n = len(points)
    lead = np.arange(n)
    if n > 1:
        pairs = cKDTree(points).query_pairs(float(resolution), output_type="ndarray")
        if len(pairs):
            pairs = np.sort(pairs, axis=1)
            pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
            for i, j in pairs:        # i < j, in input order: a leader is never led
                if lead[i] == i and lead[j] == j:
                    lead[j] = i
    keep = np.flatnonzero(lead == np.arange(n))
    index_in_keep = np.empty(n, dtype=np.int64)
    index_in_keep[keep] = np.arange(len(keep))
    return keep, index_in_keep[lead]


def merge_duplicates(positions: np.ndarray) -> tuple[np.ndarray, int]:
    """Indices (in input order) of the first target at each distinct position, and how many
    were dropped.  ``positions`` is any (n, 2) coordinate array; equality is exact."""
    keep, _ = cluster_positions(positions)
    return keep, len(positions) - len(keep)


def _pick(values, keep):
    if values is None:
        return None
    if isinstance(values, tuple):
        return tuple(values[i] for i in keep)
    if isinstance(values, TargetActions):
        return values.pick(keep)
    return np.asarray(values)[keep]


def _merged(positions, names, altitudes_m, actions, where: str, rows):
    keep, index_in_keep = cluster_positions(positions)
    if len(keep) < len(positions):
        check_conflicts(keep[index_in_keep], names, altitudes_m, actions, where, rows)
    return keep, len(positions) - len(keep)


def local_targets(positions_m: np.ndarray, names=None, altitudes_m=None,
                  actions: TargetActions | None = None, where: str = "targets",
                  rows: Sequence[str] | None = None) -> Targets:
    """:class:`Targets` with exact duplicates merged (the first one kept); :class:`InputError`
    if duplicates differ in altitude, name or actions (naming the two as ``rows`` does)."""
    keep, merged = _merged(np.asarray(positions_m, dtype=float), names, altitudes_m, actions,
                           where, rows)
    return Targets(np.asarray(positions_m, dtype=float)[keep], _pick(names, keep), merged,
                   _pick(altitudes_m, keep), actions=_pick(actions, keep))


def geodetic_targets(latitudes_deg: np.ndarray, longitudes_deg: np.ndarray, names=None,
                     altitudes_m=None, area_deg=None,
                     actions: TargetActions | None = None, where: str = "targets",
                     rows: Sequence[str] | None = None) -> GeoTargets:
    """:class:`GeoTargets` with exact duplicates merged (the first one kept); as
    :func:`local_targets` for duplicates that differ."""
    latitudes = np.asarray(latitudes_deg, dtype=float)
    longitudes = np.asarray(longitudes_deg, dtype=float)
    keep, merged = _merged(np.column_stack([latitudes, longitudes]), names, altitudes_m, actions,
                           where, rows)
    return GeoTargets(latitudes[keep], longitudes[keep], _pick(names, keep), merged,
                      _pick(altitudes_m, keep), area_deg, actions=_pick(actions, keep),
                      rows=_pick(tuple(rows), keep) if rows is not None else None)
