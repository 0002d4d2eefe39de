"""Flying a mission: a fixed-wing point mass with bank-limited turns and ArduPlane's
navigation (L1 guidance along the leg between waypoints, acceptance radius or finish line).

Pure computation, no network: :class:`MissionFlight` takes the mission's items in the local
frame (metres east/north of home, altitude above home) and advances by :meth:`step`.  The
turn radius never drops below ``min_turn_radius_m``: the bank angle is limited to
``atan(v^2 / (g rho))`` and follows its command with a first-order lag.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..mission import Command

G = 9.80665
#: ArduPlane defaults: NAVL1_DAMPING, WP_RADIUS (m), the roll controller's time constant.
L1_DAMPING = 0.75
WP_RADIUS_M = 90.0
ROLL_TIME_CONSTANT_S = 0.5
MAX_CLIMB_RATE_M_S = 5.0
MAX_SINK_RATE_M_S = 5.0
TAKEOFF_PITCH_DEG = 15.0

NAV_COMMANDS = {Command.NAV_WAYPOINT, Command.NAV_TAKEOFF, Command.NAV_LAND,
                Command.NAV_RETURN_TO_LAUNCH}


@dataclass(frozen=True)
class Airframe:
    """The simulated aircraft and its autopilot tuning."""

    airspeed_m_s: float = 20.0
    min_turn_radius_m: float = 80.0
    l1_period_s: float = 12.0          # ArduPlane's NAVL1_PERIOD (its default is 17)
    wp_radius_m: float = WP_RADIUS_M
    roll_time_constant_s: float = ROLL_TIME_CONSTANT_S

    def max_bank_rad(self, airspeed_m_s: float) -> float:
        return math.atan(airspeed_m_s ** 2 / (G * self.min_turn_radius_m))


@dataclass(frozen=True)
class LocalItem:
    """A mission item in the local frame; ``x_m``/``y_m`` are NaN for items without position."""

    seq: int
    command: int
    x_m: float
    y_m: float
    alt_m: float
    params: tuple[float, float, float, float]


@dataclass
class AircraftState:
    x_m: float
    y_m: float
    alt_m: float
    heading_rad: float         # counter-clockwise from east
    airspeed_m_s: float
    bank_rad: float = 0.0
    time_s: float = 0.0


def _cross(ax: float, ay: float, bx: float, by: float) -> float:
    return ax * by - ay * bx


@dataclass
class MissionFlight:
    """Flies ``items`` from ``first_seq`` on, starting at home (0, 0) on the ground heading
    ``heading_rad``.  ``reached`` lists (seq, time) of every item completed, in order."""

    items: list[LocalItem]
    airframe: Airframe
    heading_rad: float
    first_seq: int = 0
    state: AircraftState = field(init=False)
    reached: list[tuple[int, float]] = field(default_factory=list)
    finished: bool = False

    def __post_init__(self) -> None:
        self.state = AircraftState(0.0, 0.0, 0.0, self.heading_rad, self.airframe.airspeed_m_s)
        self._index = self.first_seq
        self._previous = (0.0, 0.0, 0.0)     # the leg starts here (x, y, alt)
        self._landing = False
        self._skip_instant_items()

    # -- mission sequencing ------------------------------------------------------------------

    @property
    def current(self) -> LocalItem | None:
        return self.items[self._index] if self._index < len(self.items) else None

    def _complete(self) -> None:
        item = self.current
        self.reached.append((item.seq, self.state.time_s))
        if item.command in NAV_COMMANDS and not math.isnan(item.x_m):
            self._previous = (item.x_m, item.y_m, item.alt_m)
        elif item.command == Command.NAV_TAKEOFF:
            self._previous = (self.state.x_m, self.state.y_m, item.alt_m)
        self._index += 1
        self._skip_instant_items()

    def _skip_instant_items(self) -> None:
        while (item := self.current) is not None and item.command not in NAV_COMMANDS:
            if item.command == Command.DO_CHANGE_SPEED and item.params[1] > 0:
                self.state.airspeed_m_s = float(item.params[1])
            self.reached.append((item.seq, self.state.time_s))
            self._index += 1
        if self.current is None:
            self.finished = True

    def _next_turn_deg(self) -> float:
        """Turn angle at the current waypoint, towards the next one (ArduPlane scales the
        acceptance radius with it)."""
        item = self.current
        following = next((i for i in self.items[self._index + 1:]
                          if i.command in NAV_COMMANDS and not math.isnan(i.x_m)), None)
        if following is None:
            return 90.0
        a = math.atan2(item.y_m - self._previous[1], item.x_m - self._previous[0])
        b = math.atan2(following.y_m - item.y_m, following.x_m - item.x_m)
        return abs(math.degrees(math.remainder(b - a, 2 * math.pi)))

    # -- guidance and dynamics ---------------------------------------------------------------

    def _l1_lateral_accel(self, ax: float, ay: float, bx: float, by: float) -> float:
        """ArduPlane's L1 law (``AP_L1_Control::update_waypoint``): lateral acceleration,
        positive to the left, to track the line from A to B."""
        s = self.state
        speed = s.airspeed_m_s
        vx, vy = speed * math.cos(s.heading_rad), speed * math.sin(s.heading_rad)
        l1 = max(L1_DAMPING * self.airframe.l1_period_s * speed / math.pi, 1.0)
        tx, ty = bx - ax, by - ay
        length = math.hypot(tx, ty)
        if length < 1e-6:
            tx, ty, length = bx - s.x_m, by - s.y_m, math.hypot(bx - s.x_m, by - s.y_m) or 1.0
        tx, ty = tx / length, ty / length
        rx, ry = s.x_m - ax, s.y_m - ay
        distance_a = math.hypot(rx, ry)
        if distance_a > l1 and (rx * tx + ry * ty) / distance_a < -0.7071:
            eta = math.atan2(_cross(vx, vy, -rx, -ry), vx * -rx + vy * -ry)   # fly to A first
        else:
            nu2 = math.atan2(_cross(tx, ty, vx, vy), tx * vx + ty * vy)       # velocity vs track
            nu1 = math.asin(max(-0.7071, min(0.7071, _cross(tx, ty, rx, ry) / l1)))
            eta = -(nu1 + nu2)
        eta = max(-math.pi / 2, min(math.pi / 2, eta))
        return 4 * L1_DAMPING ** 2 * speed ** 2 / l1 * math.sin(eta)

    def _fly(self, dt: float, lateral_accel: float, climb_rate: float, ground_factor: float = 1.0) -> None:
        s = self.state
        limit = self.airframe.max_bank_rad(s.airspeed_m_s)
        command = max(-limit, min(limit, math.atan(lateral_accel / G)))
        s.bank_rad += (command - s.bank_rad) * (1 - math.exp(-dt / self.airframe.roll_time_constant_s))
        s.bank_rad = max(-limit, min(limit, s.bank_rad))
        ground_speed = s.airspeed_m_s * ground_factor
        turn_rate = G * math.tan(s.bank_rad) / ground_speed
        heading = s.heading_rad + turn_rate * dt
        if abs(turn_rate) > 1e-12:    # exact arc of the step
            radius = ground_speed / turn_rate
            s.x_m += radius * (math.sin(heading) - math.sin(s.heading_rad))
            s.y_m -= radius * (math.cos(heading) - math.cos(s.heading_rad))
        else:
            s.x_m += ground_speed * dt * math.cos(heading)
            s.y_m += ground_speed * dt * math.sin(heading)
        s.heading_rad = math.remainder(heading, 2 * math.pi)
        s.alt_m += climb_rate * dt
        s.time_s += dt

    def _toward_alt(self, target_alt: float, dt: float) -> float:
        return max(-MAX_SINK_RATE_M_S, min(MAX_CLIMB_RATE_M_S, (target_alt - self.state.alt_m) / max(dt, 1.0)))

    def step(self, dt: float) -> None:
        """Advance ``dt`` seconds; completed items go to :attr:`reached`."""
        if self.finished:
            return
        s, item = self.state, self.current
        if item.command == Command.NAV_TAKEOFF:
            pitch = math.radians(item.params[0] or TAKEOFF_PITCH_DEG)
            self._fly(dt, 0.0, s.airspeed_m_s * math.sin(pitch), math.cos(pitch))
            if s.alt_m >= item.alt_m:
                s.alt_m = item.alt_m
                self._complete()
            return
        if item.command == Command.NAV_RETURN_TO_LAUNCH:
            target = (0.0, 0.0, self._previous[2])
        else:
            target = (item.x_m, item.y_m, item.alt_m)
        ax, ay, a_alt = self._previous
        bx, by, b_alt = target
        leg = math.hypot(bx - ax, by - ay)
        along = ((s.x_m - ax) * (bx - ax) + (s.y_m - ay) * (by - ay)) / leg if leg > 1e-9 else 0.0
        fraction = min(max(along / leg, 0.0), 1.0) if leg > 1e-9 else 1.0
        wanted_alt = a_alt + (b_alt - a_alt) * fraction       # altitude by leg progress
        if item.command == Command.NAV_LAND:
            climb = (wanted_alt - s.alt_m) / dt if fraction < 1 else -MAX_SINK_RATE_M_S
            climb = max(-MAX_SINK_RATE_M_S, min(MAX_CLIMB_RATE_M_S, climb))
        else:
            climb = self._toward_alt(wanted_alt, dt)
        self._fly(dt, self._l1_lateral_accel(ax, ay, bx, by), climb)
        distance = math.hypot(bx - s.x_m, by - s.y_m)
        past_finish_line = leg > 1e-9 and ((s.x_m - bx) * (bx - ax) + (s.y_m - by) * (by - ay)) > 0
        if item.command == Command.NAV_LAND:
            if s.alt_m <= 0.0:
                s.alt_m = 0.0
                self._complete()
            return
        acceptance = item.params[1] if item.command == Command.NAV_WAYPOINT else 0.0
        if acceptance <= 0:
            l1 = L1_DAMPING * self.airframe.l1_period_s * s.airspeed_m_s / math.pi
            acceptance = min(self.airframe.wp_radius_m, l1) * min(self._next_turn_deg(), 90.0) / 90.0
            if item.command == Command.NAV_RETURN_TO_LAUNCH:
                acceptance = self.airframe.wp_radius_m
        if distance <= acceptance or past_finish_line:
            self._complete()


def closest_approach_m(track_xy: np.ndarray, points_xy: np.ndarray, chunk: int = 256) -> np.ndarray:
    """For each point, the smallest distance to the polyline ``track_xy`` (exact per segment)."""
    a, b = track_xy[:-1], track_xy[1:]
    d = b - a
    length2 = np.maximum((d * d).sum(axis=1), 1e-18)
    result = np.empty(len(points_xy))
    for start in range(0, len(points_xy), chunk):
        p = points_xy[start:start + chunk, None, :]
        t = np.clip(((p - a) * d).sum(axis=2) / length2, 0.0, 1.0)
        nearest = a + t[..., None] * d
        result[start:start + chunk] = np.sqrt(((p - nearest) ** 2).sum(axis=2)).min(axis=1)
    return result
