"""What the aircraft does at each target, besides overflying it: the per-target columns of a
targets file and the ``plan`` options that set them for every target.

- ``photo`` -- take one picture when the target is overflown;
- ``roi`` -- point the camera at the target (region of interest) from the previous target on;
- ``gimbal_pitch`` -- the gimbal's pitch in degrees (-90 straight down) from the previous
  target on;
- ``loiter_turns`` -- whole circles flown through the target before the tour goes on.

The MAVLink items each autopilot accepts for them are made in
:mod:`dtsp_mission.mission.actions`; here they are plain per-target arrays in target order.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError

#: Column (or GeoJSON property) names, and the other spellings accepted for them.
COLUMNS = {"photo": ("photo", "capture", "camera"), "roi": ("roi",),
           "gimbal_pitch": ("gimbal_pitch", "gimbal_pitch_deg", "pitch"),
           "loiter_turns": ("loiter_turns", "loiter")}
_TRUE = {"1", "yes", "y", "true", "x"}
_FALSE = {"", "0", "no", "n", "false", "-"}
#: Most circles a target may have (ArduPilot stores LOITER_TURNS' count in a byte).
MAX_LOITER_TURNS = 255


def column_key(label: str) -> str | None:
    """The action a column header names, or None."""
    label = label.strip().lower()
    return next((key for key, spellings in COLUMNS.items() if label in spellings), None)


@dataclass(frozen=True)
class TargetActions:
    """Per target (target order): ``photo`` and ``roi`` flags, ``gimbal_pitch_deg`` (NaN: not
    set) and ``loiter_turns`` (0: none)."""

    photo: np.ndarray
    roi: np.ndarray
    gimbal_pitch_deg: np.ndarray
    loiter_turns: np.ndarray

    @classmethod
    def none(cls, count: int) -> "TargetActions":
        return cls(np.zeros(count, bool), np.zeros(count, bool), np.full(count, np.nan),
                   np.zeros(count, np.int64))

    def __len__(self) -> int:
        return len(self.photo)

    @property
    def any(self) -> bool:
        return bool(self.photo.any() or self.roi.any() or (~np.isnan(self.gimbal_pitch_deg)).any()
                    or self.loiter_turns.any())

    def pick(self, keep: np.ndarray) -> "TargetActions":
        keep = np.asarray(keep, dtype=np.int64)
        return TargetActions(self.photo[keep], self.roi[keep], self.gimbal_pitch_deg[keep],
                             self.loiter_turns[keep])

    def with_options(self, photo: bool = False, roi: bool = False,
                     gimbal_pitch_deg: float | None = None,
                     loiter_turns: dict[int, int] | None = None) -> "TargetActions":
        """These actions with the options for every target added (``gimbal_pitch_deg`` where a
        target has none of its own) and ``loiter_turns`` (target index -> turns) set."""
        pitch = self.gimbal_pitch_deg
        if gimbal_pitch_deg is not None:
            check_gimbal_pitch(gimbal_pitch_deg, "`gimbal_pitch_deg`")
            pitch = np.where(np.isnan(pitch), float(gimbal_pitch_deg), pitch)
        turns = self.loiter_turns.copy()
        for index, count in (loiter_turns or {}).items():
            turns[index] = check_loiter_turns(count, "`loiter_turns`")
        return replace(self, photo=self.photo | photo, roi=self.roi | roi, gimbal_pitch_deg=pitch,
                       loiter_turns=turns)


def check_gimbal_pitch(value: float, where: str) -> float:
    if not (np.isfinite(value) and -180.0 <= value <= 180.0):
        raise InputError(f"{where}: a gimbal pitch is degrees between -180 and 180 (-90 looks "
                         f"straight down), got {value!r}")
    return float(value)


def check_loiter_turns(value: float, where: str) -> int:
    """A loiter's count of circles: a whole number 0..255 (the circles are flown through the
    target and end where they began, so that the tour goes on unchanged)."""
    if not (np.isfinite(value) and float(value).is_integer() and 0 <= value <= MAX_LOITER_TURNS):
        raise InputError(f"{where}: loiter turns must be a whole number from 0 to "
                         f"{MAX_LOITER_TURNS} (whole circles through the target), got {value!r}")
    return int(value)


def parse_cell(key: str, cell, where: str):
    """One action cell of a targets file (text, or a GeoJSON property value) as its value."""
    if key in ("photo", "roi"):
        if cell is None or isinstance(cell, bool):
            return bool(cell)
        text = str(cell).strip().lower()
        if text in _TRUE:
            return True
        if text in _FALSE:
            return False
        raise InputError(f"{where}: {key} must be yes/no (1/0, true/false, or empty), got {cell!r}")
    if cell is None or (isinstance(cell, str) and not cell.strip()):
        return np.nan if key == "gimbal_pitch" else 0
    try:
        value = float(cell)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {key} must be a number, got {cell!r}") from None
    if key == "gimbal_pitch":
        return check_gimbal_pitch(value, where)
    return check_loiter_turns(value, where)


def actions_from_columns(values: dict[str, list], count: int) -> TargetActions | None:
    """Actions from parsed cells (key -> one value per target), or None if no column set any."""
    if not values:
        return None
    actions = TargetActions.none(count)
    fields = {"photo": "photo", "roi": "roi", "gimbal_pitch": "gimbal_pitch_deg",
              "loiter_turns": "loiter_turns"}
    arrays = {}
    for key, cells in values.items():
        template = getattr(actions, fields[key])
        arrays[fields[key]] = np.asarray(cells, dtype=template.dtype)
    actions = replace(actions, **arrays)
    return actions if actions.any else None
