"""Sorties: a tour too long for the vehicle's mission storage, flown as several missions.

Each sortie takes off, flies a contiguous part of the tour (its legs exactly as planned) and
returns.  The parts are chosen to balance the flight time: the cut points minimise the longest
sortie's estimated flight (climb-out and straight way to the first target, the tour between
its first and last target, straight way home), over every place the closed tour can be opened;
the number of sorties is the smallest whose missions all fit ``max_items``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError, MissionTooLarge
from ..frame import LocalFrame
from ..targets import GeoTargets
from ..tour import Tour, tour_through_poses
from .build import build_mission
from .widening import targets_beyond, with_turn_margin
from .settings import MissionSettings
from .model import Mission

#: Most sorties tried before giving up.
MAX_SORTIES = 64


@dataclass(frozen=True)
class Sortie:
    """One mission of a split: the indices of its targets (tour order) and the mission."""

    targets: np.ndarray
    mission: Mission


def _cuts(arc_m: np.ndarray, to_home_m: np.ndarray, count: int, first: int,
          most: int | None = None) -> tuple[list[int], float]:
    """Cut the closed visiting order (legs ``arc_m[i]`` from visit i to i+1, straight distance
    home ``to_home_m``) opened before visit ``first`` into ``count`` contiguous parts of
    near-equal estimated flight, each of at most ``most`` visits (no limit if None); the part
    starts and the longest estimate."""
    n = len(arc_m)
    order = (first + np.arange(n)) % n
    legs = arc_m[order]
    home = to_home_m[order]
    cumulative = np.concatenate([[0.0], np.cumsum(legs)])      # distance from the first visit

    def flight(i: int, j: int) -> float:                        # visits i..j (inclusive)
        return home[i] + cumulative[j] - cumulative[i] + home[j]

    def parts_within(limit: float) -> list[int] | None:
        starts, i = [0], 0
        while True:
            j = i
            while j + 1 < n and flight(i, j + 1) <= limit and (most is None or j + 1 - i < most):
                j += 1
            if j + 1 >= n:
                return starts
            if len(starts) == count:
                return None
            i = j + 1
            starts.append(i)

    low = max(flight(i, i) for i in range(n))
    high = flight(0, n - 1)
    for _ in range(40):
        middle = 0.5 * (low + high)
        if parts_within(middle) is None:
            low = middle
        else:
            high = middle
    starts = parts_within(high) or [0]
    return [int(order[s]) for s in starts], high


def split_into_sorties(tour: Tour, frame: LocalFrame, targets: GeoTargets,
                       settings: MissionSettings, home_m: np.ndarray,
                       endurance_s: float | None = None,
                       replan: Callable[[np.ndarray, float], Tour] | None = None) -> list[Sortie]:
    """The fewest sorties (at least 2) whose missions each fit ``settings.max_items`` and,
    with ``endurance_s``, each fly within it (from take-off to the return, at the mission's
    airspeed), balanced by estimated flight time; :class:`InputError` if none up to
    :data:`MAX_SORTIES` does.

    With ``replan(positions_m, rho_m)`` (a planner), a guidance-designed sortie whose targets
    are predicted beyond ``settings.max_miss_m`` is planned again with the wider turn radii of
    :func:`~.build.with_turn_margin`, as a single mission is, where that holds more of its
    targets and still fits the storage and the endurance."""
    n = len(tour.targets_m)
    order = tour.visit_order
    poses = tour.visit_poses()[order]
    s = tour.visit_s_m[order]
    arc = np.diff(np.append(s, s[0] + tour.length_m))
    to_home = np.hypot(*(tour.targets_m[order] - np.asarray(home_m, dtype=float)).T)
    last_error: Exception | None = None
    attempts = [(count, most) for count in range(2, min(MAX_SORTIES, n) + 1)
                for most in (None, -(-n // count))]
    for count, most in attempts:
        # Balanced by flight time first; where that leaves a part too large for the storage
        # (a far target alone, the rest together), by flight time with the targets shared out.
        candidates = range(0, n, max(1, n // 64))
        starts, _ = min((_cuts(arc, to_home, count, first, most) for first in candidates),
                        key=lambda result: result[1])
        pieces = []
        for k, start in enumerate(starts):
            end = starts[(k + 1) % len(starts)]
            length = (end - start) % n or n
            pieces.append((start + np.arange(length)) % n)
        try:
            sorties = []
            for piece in pieces:
                chosen = order[piece]
                part = tour_through_poses(tour.targets_m[chosen], np.arange(len(chosen)),
                                          poses[piece, 2], tour.rho_m, tour.planner, tour.parameters)
                mission = build_mission(part, frame, targets.subset(chosen), settings)
                flight_s = mission.summary.get("flight_time_s", 0.0)
                fits = endurance_s is None or flight_s <= endurance_s
                if replan is not None and fits and targets_beyond(mission):
                    mission = _widened(mission, chosen, tour, targets, settings, endurance_s, replan)
                    flight_s = mission.summary.get("flight_time_s", 0.0)
                if endurance_s is not None and flight_s > endurance_s:
                    raise _TooLong(f"a sortie would fly {flight_s / 60:.1f} min, more than the "
                                   f"endurance of {endurance_s / 60:g} min")
                sorties.append(Sortie(chosen, mission))
            return sorties
        except (MissionTooLarge, _TooLong) as error:
            last_error = error
    max_items = settings.checked(tour.rho_m).max_items
    limits = (f"{max_items} items"
              f"{f', {endurance_s / 60:g} min of endurance' if endurance_s else ''}")
    if isinstance(last_error, MissionTooLarge):
        # Splitting further is what was just tried: only more room helps.
        raise InputError(f"even {min(MAX_SORTIES, n)} sorties do not fit the vehicle ({limits}): "
                         f"a sortie needs at least {last_error.needed} items but the vehicle holds "
                         f"{last_error.capacity} (`max_items`); allow more if it has the space "
                         "(ArduPilot with the mission on SD card holds about 4,300)")
    raise InputError(f"even {min(MAX_SORTIES, n)} sorties do not fit the vehicle ({limits}): "
                     f"{last_error}")


def _widened(mission, chosen, tour, targets, settings, endurance_s, replan):
    """The sortie's mission planned with a wider turn radius if that holds more targets and
    still flies within the endurance; else ``mission``."""
    positions = tour.targets_m[chosen]
    candidate = with_turn_margin(mission, lambda rho: replan(positions, rho),
                                 targets.subset(chosen), settings)
    if endurance_s is not None and candidate.summary.get("flight_time_s", 0.0) > endurance_s:
        return mission
    return candidate


class _TooLong(Exception):
    """A sortie longer than the endurance."""


def sortie_path(path: str, index: int) -> str:
    """``mission.plan`` -> ``mission-<index>.plan`` (1-based)."""
    stem, dot, extension = path.rpartition(".")
    if not dot or "/" in extension:
        return f"{path}-{index}"
    return f"{stem}-{index}.{extension}"

