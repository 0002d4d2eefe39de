"""The actions at the targets placed among the mission's items: a camera trigger or a loiter
after a target's waypoint, a region of interest or gimbal pitch on the leg to it, in the forms
each autopilot accepts (:mod:`.actions`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..frame import LocalFrame
from ..targets import GeoTargets
from ..targets.actions import TargetActions
from ..autopilot.commands import AUTOPILOTS, Command
from . import actions as action_items
from .model import FlightPath, MissionItem
from .settings import MissionSettings


def target_actions(targets: GeoTargets, settings: MissionSettings) -> TargetActions:
    """The targets' own actions with the settings' for every target added."""
    base = targets.actions if targets.actions is not None else TargetActions.none(len(targets))
    return base.with_options(settings.photo, settings.roi, settings.gimbal_pitch_deg)


@dataclass(frozen=True)
class AtTargets:
    """The action items of a mission: ``before[t]`` go after the previous target's items (the
    leg to ``t``), ``after[t]`` after ``t``'s waypoint, ``end`` after the last target's."""

    before: dict[int, list[MissionItem]]
    after: dict[int, list[MissionItem]]
    end: list[MissionItem]
    first: int                      # the first target visited
    next_of: dict[int, int]         # target -> the one visited after it

    @property
    def count(self) -> int:
        return (sum(map(len, self.before.values())) + sum(map(len, self.after.values()))
                + len(self.end))

    def inserted(self, items: list[MissionItem]) -> list[MissionItem]:
        """``items`` (take-off, waypoints, return) with the action items in their places."""
        if not self.count:
            return items
        out: list[MissionItem] = []
        started = False
        visited = 0
        total = sum(item.role == "target" for item in items)
        for item in items:
            if not started and item.command == Command.NAV_WAYPOINT:
                out += self.before.get(self.first, [])
                started = True
            out.append(item)
            if item.role == "target":
                visited += 1
                out += self.after.get(item.target, [])
                following = self.next_of.get(item.target)
                if following is not None:
                    out += self.before.get(following, [])
                if visited == total:
                    out += self.end
        return out


def action_items_of(path: FlightPath, frame: LocalFrame, targets: GeoTargets,
                  actions: TargetActions, settings: MissionSettings) -> AtTargets:
    autopilot = AUTOPILOTS[settings.autopilot]
    order = [int(t) for t in np.argsort(path.target_s_m, kind="stable")]
    loiters = {span.target: span for span in path.loiters}
    before: dict[int, list[MissionItem]] = {}
    after: dict[int, list[MissionItem]] = {}
    pitch_now = math.nan
    for t in order:
        leg: list[MissionItem] = []
        if actions.roi[t]:
            leg.append(action_items.roi_item(autopilot, targets.latitudes_deg[t],
                                             targets.longitudes_deg[t], t))
        pitch = actions.gimbal_pitch_deg[t]
        if not math.isnan(pitch) and pitch != pitch_now:
            leg.append(action_items.gimbal_item(autopilot, float(pitch), t))
            pitch_now = pitch
        if leg:
            before[t] = leg
        at: list[MissionItem] = []
        if actions.photo[t]:
            at.append(action_items.photo_item(autopilot, t))
        if t in loiters:
            span = loiters[t]
            latitude, longitude = frame.to_geodetic(span.centre_m.reshape(1, 2))
            altitude = float(path.altitude_m(np.array([span.start_s_m]))[0])
            at.append(action_items.loiter_item(autopilot, (float(latitude[0]), float(longitude[0])),
                                               altitude, span.radius_m, span.clockwise, span.turns,
                                               settings.airspeed_m_s, t))
        if at:
            after[t] = at
    end = [action_items.roi_off_item(autopilot)] if actions.roi.any() else []
    return AtTargets(before, after, end, order[0] if order else -1, dict(zip(order, order[1:])))
