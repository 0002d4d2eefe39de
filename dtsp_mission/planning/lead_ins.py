"""Straight lead-ins planned into a tour: the tour changed locally so that chosen targets are
entered along a straight of a given length.

An autopilot's line-following guidance (ArduPlane's L1, PX4's NPFG) passes a target exactly
once it has settled on a straight line through it; it settles within one to two L1 distances.
Where the mission design cannot hold a target from the tour as planned (the turns around it too
tight for the guidance to follow), the tour is changed around that target instead of the
flight: the target is visited at a heading ``theta`` reached along a straight of ``lead_m``
that ends at the target, and ``theta`` (with its neighbours' headings) is chosen so that the
tour grows least.  The visiting order stays; every other leg stays the shortest Dubins path.

Guarantee: the returned tour is a closed chain of exact Dubins paths through every target, at
the same turn radius, whose leg into each chosen target ends with a straight of at least
``lead_m`` (``Tour.lead_in_m`` says how long, per target); it passes the same checker.
"""

from __future__ import annotations

import math

import numpy as np

from ..dubins import chain_of_paths, shortest_length, shortest_words
from ..tour import Tour
from ..tour.model import EMPTY_SEGMENT_RHO, snap_visits

#: Headings tried per target: evenly spaced, plus the one it had.
CANDIDATES = 72


def _leg_m(start: np.ndarray, goal: np.ndarray, lead_m: float, rho_m: float) -> np.ndarray:
    """Length of the leg from pose(s) ``start`` to pose(s) ``goal`` when ``goal`` is entered
    along a straight of ``lead_m`` (0: the shortest Dubins path)."""
    if lead_m <= 0.0:
        return shortest_length(start, goal, rho_m)
    goal = np.asarray(goal, dtype=float)
    back = goal.copy()
    back[..., 0] -= lead_m * np.cos(goal[..., 2])
    back[..., 1] -= lead_m * np.sin(goal[..., 2])
    return shortest_length(start, back, rho_m) + lead_m


def with_lead_ins(tour: Tour, lead_m: dict[int, float], reach: int = 2) -> Tour:
    """``tour`` with the leg into each target ``t`` of ``lead_m`` ending in a straight of
    ``lead_m[t]`` metres (targets already given a lead-in in ``tour`` keep the longer of the
    two).  The headings at those targets and at the ``reach`` targets either side of each are
    chosen anew, jointly, by dynamic programming over :data:`CANDIDATES` headings each (plus the
    heading each had and the directions to its neighbours), between the headings kept fixed
    around them; a stretch is changed only if that shortens it.  Deterministic."""
    n = len(tour.targets_m)
    leads = np.array(tour.lead_in_m if tour.lead_in_m is not None else np.zeros(n), dtype=float)
    for t, metres in lead_m.items():
        leads[int(t)] = max(leads[int(t)], float(metres))
    order = tour.visit_order
    poses = tour.visit_poses()[order].copy()       # visit order
    lead_of = leads[order]
    if n >= 3:
        rank = np.empty(n, dtype=int)
        rank[order] = np.arange(n)
        free = np.zeros(n, dtype=bool)
        for t in lead_m:
            k = int(rank[int(t)])
            free[[(k + j) % n for j in range(-reach, reach + 1)]] = True
        if free.all():
            free[int(np.argmin(lead_of))] = False       # one pose stays: the stretch is open
        for first, count in _stretches(free):
            _choose(poses, lead_of, first, count, tour.rho_m)
    return _tour_of(tour, order, poses, lead_of)


def _stretches(free: np.ndarray) -> list[tuple[int, int]]:
    """(first index, length) of each cyclic run of ``True`` in ``free`` (not all ``True``)."""
    n = len(free)
    start = int(np.flatnonzero(~free)[0])
    runs, k = [], 0
    while k < n:
        i = (start + k) % n
        if free[i]:
            length = 0
            while k < n and free[(start + k) % n]:
                length, k = length + 1, k + 1
            runs.append((i, length))
        else:
            k += 1
    return runs


def _choose(poses: np.ndarray, lead_of: np.ndarray, first: int, count: int, rho_m: float) -> None:
    """Headings of the ``count`` poses from ``first`` on (cyclic), between the fixed poses
    before and after them, that make that stretch shortest: dynamic programming over candidate
    headings (in place; kept as they were unless strictly shorter)."""
    n = len(poses)
    index = [(first + j) % n for j in range(count)]
    before, after = poses[(first - 1) % n], poses[(first + count) % n]
    angles = 2.0 * math.pi * np.arange(CANDIDATES) / CANDIDATES
    options = []
    for j, i in enumerate(index):
        towards = [poses[(i + 1) % n, :2] - poses[i, :2], poses[i, :2] - poses[(i - 1) % n, :2]]
        extra = [math.atan2(d[1], d[0]) for d in towards if np.hypot(*d) > 1e-9]
        headings = np.concatenate(([poses[i, 2]], extra, angles))
        option = np.repeat(poses[i][None], len(headings), axis=0)
        option[:, 2] = headings
        options.append(option)
    # cost[j][a, b]: leg from option a of stretch pose j-1 (j=0: the fixed pose before) to b.
    value = _leg_m(before[None], options[0], lead_of[index[0]], rho_m)       # (K0,)
    back = []
    for j in range(1, count):
        legs = _leg_m(options[j - 1][:, None], options[j][None], lead_of[index[j]], rho_m)
        total = value[:, None] + legs
        back.append(np.argmin(total, axis=0))
        value = total[back[-1], np.arange(total.shape[1])]
    value = value + _leg_m(options[-1], after[None], lead_of[(first + count) % n], rho_m)
    pick = [int(np.argmin(value))]
    for j in range(count - 1, 0, -1):
        pick.append(int(back[j - 1][pick[-1]]))
    pick.reverse()
    current = (_leg_m(before, poses[index[0]], lead_of[index[0]], rho_m)
               + sum(_leg_m(poses[index[j - 1]], poses[index[j]], lead_of[index[j]], rho_m)
                     for j in range(1, count))
               + _leg_m(poses[index[-1]], after, lead_of[(first + count) % n], rho_m))
    if float(value[pick[-1]]) < float(current) - 1e-9:
        for j, i in enumerate(index):
            poses[i] = options[j][pick[j]]


def _tour_of(tour: Tour, order: np.ndarray, poses: np.ndarray, lead_of: np.ndarray) -> Tour:
    """The closed chain through ``poses`` (visit order), each leg the shortest Dubins path to
    the straight's start of its goal's lead-in and then that straight."""
    rho = tour.rho_m
    starts, goals, visit_leg = [], [], []
    for k in range(len(poses)):
        goal = poses[(k + 1) % len(poses)]
        lead = lead_of[(k + 1) % len(poses)]
        if lead > 0.0:
            back = goal.copy()
            back[:2] -= lead * np.array([math.cos(goal[2]), math.sin(goal[2])])
            starts += [poses[k], back]
            goals += [back, goal]
        else:
            starts.append(poses[k])
            goals.append(goal)
        visit_leg.append(len(starts))       # the leg that leaves target k+1 starts here
    starts, goals = np.array(starts), np.array(goals)
    words, lengths = shortest_words(starts, goals, rho)
    chain = chain_of_paths(starts, words, lengths, rho).without_empty(EMPTY_SEGMENT_RHO * rho)
    leg_start = np.concatenate(([0.0], np.cumsum(lengths.sum(axis=1))))
    visit = np.empty(len(poses))
    n = len(poses)
    for k in range(n):                      # target order[k] is the goal of the legs before
        visit[order[k]] = leg_start[visit_leg[k - 1] % len(starts)] if k else 0.0
    visit = snap_visits(chain, tour.targets_m, visit)
    leads = np.zeros(n)
    leads[order] = lead_of
    return Tour(chain, rho, tour.targets_m, visit, tour.planner, dict(tour.parameters),
                dict(tour.report), lead_in_m=leads)
