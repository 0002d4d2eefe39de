"""Flying a mission the way ArduPlane navigates it: a fixed-wing point mass in coordinated
turns, steered by ArduPlane's L1 guidance (``AP_L1_Control``: the leg between waypoints, the
loiter circle), with its waypoint completion (acceptance radius scaled by the turn, the finish
line), LOITER_TURNS with fractional turns and the tangent exit, take-off and a TECS-like climb.

Pure computation, no network: :class:`MissionFlight` takes the mission's items in the local
frame (metres east/north of home, altitude above home) and advances by :meth:`step`.  The bank
angle is limited to the roll limit (``ROLL_LIMIT_DEG``; without one, to ``atan(v^2 / (g
rho))`` for the airframe's minimum turn radius) and follows its command as a damped
second-order response, whose frequency and damping were fitted to ArduPlane SITL's roll
(``tests/data/arduplane-sitl``).  Its parameters come from :class:`Airframe`, usually made from
the vehicle's parameters (:meth:`Airframe.from_parameters`).
"""

from __future__ import annotations

import copy as _copy
import math
from dataclasses import dataclass, field, replace

import numpy as np

from .commands import Command, Frame
from .parameters import ARDUPLANE_DEFAULTS, VehicleParameters

G = 9.80665
#: ArduPlane defaults: NAVL1_DAMPING, WP_RADIUS (m).
L1_DAMPING = 0.75
WP_RADIUS_M = 90.0
MAX_CLIMB_RATE_M_S = 5.0
MAX_SINK_RATE_M_S = 5.0
TAKEOFF_PITCH_DEG = 15.0
#: The roll response of ArduPlane SITL's stock plane to a step in demanded roll (a damped
#: second-order lag fitted to the recorded corners: peak after 0.9 s, 9 % overshoot).
ROLL_NATURAL_RAD_S = 4.4
ROLL_DAMPING = 0.6
#: ArduPlane SITL's stock plane turns at this fraction of the coordinated-turn rate for its
#: bank (regression of the recorded course rate on the recorded roll: 0.73-0.80 over the
#: cases; 0.73 agrees best with the tracks, docs/arduplane-agreement.md).
SITL_TURN_EFFICIENCY = 0.73
#: The time step the model's agreement with recorded ArduPlane flights was measured at
#: (docs/arduplane-agreement.md): the flight that predicts, verifies and simulates a mission.
MODEL_STEP_S = 0.02
#: LOITER_TURNS with the tangent exit leaves when the course is this close to the next waypoint.
LOITER_EXIT_HEADING_RAD = math.radians(10.0)

NAV_COMMANDS = {Command.NAV_WAYPOINT, Command.NAV_TAKEOFF, Command.NAV_LAND,
                Command.NAV_RETURN_TO_LAUNCH, Command.NAV_LOITER_TURNS, Command.NAV_LOITER_TIME}
#: ArduPilot's MAV_CMD_NAV_LAST: commands above it do not navigate (a DO_SET_ROI's location is
#: where the camera looks, not where the aircraft goes).
NAV_LAST = 95


@dataclass(frozen=True)
class Airframe:
    """The simulated aircraft and its autopilot tuning."""

    airspeed_m_s: float = 20.0
    min_turn_radius_m: float = 80.0
    l1_period_s: float = 12.0          # ArduPlane's NAVL1_PERIOD
    wp_radius_m: float = WP_RADIUS_M
    roll_natural_rad_s: float = ROLL_NATURAL_RAD_S
    roll_damping: float = ROLL_DAMPING
    l1_damping: float = L1_DAMPING
    roll_limit_deg: float | None = None     # None: the bank that turns at min_turn_radius_m
    loiter_radius_m: float = 80.0
    max_climb_m_s: float = MAX_CLIMB_RATE_M_S
    max_sink_m_s: float = MAX_SINK_RATE_M_S
    altitude_time_constant_s: float = 1.0
    #: Take-off as ArduPlane SITL's stock plane flies it at full throttle (fitted to the
    #: recorded climbs): ground roll accelerating at this rate, lift-off at 85 % of the cruise
    #: airspeed, climb at this rate up to 116 % of it.  0: airborne at once, climbing at the
    #: take-off pitch.
    takeoff_accel_m_s2: float = 0.0
    takeoff_climb_m_s: float = 9.7
    #: Turn rate over the coordinated-turn rate g tan(bank) / v at the same bank: 1 for an
    #: ideal airframe; ArduPlane SITL's stock plane turns at about 0.76 of it (regression of
    #: the recorded course rate on the recorded roll, 0.73-0.80 over the cases).
    turn_efficiency: float = 1.0
    #: How often the navigation runs (lateral demand, waypoint completion); 0: every step.
    navigation_hz: float = 0.0

    @classmethod
    def from_parameters(cls, parameters: VehicleParameters = ARDUPLANE_DEFAULTS,
                        airspeed_m_s: float | None = None) -> "Airframe":
        """The airframe an ArduPlane with these parameters flies as (its cruise airspeed
        unless ``airspeed_m_s`` is given)."""
        speed = airspeed_m_s or parameters.AIRSPEED_CRUISE
        roll = math.radians(parameters.ROLL_LIMIT_DEG)
        return cls(speed, speed ** 2 / (G * math.tan(roll)), parameters.NAVL1_PERIOD,
                   parameters.WP_RADIUS, l1_damping=parameters.NAVL1_DAMPING,
                   roll_limit_deg=parameters.ROLL_LIMIT_DEG,
                   loiter_radius_m=parameters.WP_LOITER_RAD,
                   max_climb_m_s=parameters.TECS_CLMB_MAX, max_sink_m_s=parameters.TECS_SINK_MAX,
                   altitude_time_constant_s=parameters.TECS_TIME_CONST, takeoff_accel_m_s2=7.0,
                   turn_efficiency=SITL_TURN_EFFICIENCY, navigation_hz=parameters.SCHED_LOOP_RATE)

    def max_bank_rad(self, airspeed_m_s: float) -> float:
        if self.roll_limit_deg is not None:
            return math.radians(self.roll_limit_deg)
        return math.atan(airspeed_m_s ** 2 / (G * self.min_turn_radius_m))

    def l1_distance_m(self, speed_m_s: float) -> float:
        return max(self.l1_damping * self.l1_period_s * speed_m_s / math.pi, 1.0)


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
    bank_rate_rad_s: float = 0.0
    time_s: float = 0.0


#: Commands without a position, whatever frame a vehicle stores them in.
_NO_POSITION = {Command.NAV_RETURN_TO_LAUNCH}


def local_items(wire: list, frame, home_amsl_m: float) -> list[LocalItem]:
    """Mission items (MISSION_ITEM_INT form, :class:`~dtsp_mission.autopilot.storage.WireItem`)
    in the local ``frame`` (a :class:`~dtsp_mission.frame.LocalFrame` at home), altitudes above
    home; items without a position get NaN coordinates."""
    items = []
    for item in wire:
        if item.frame == Frame.MISSION or item.command in _NO_POSITION or item.command > NAV_LAST:
            x = y = math.nan
        else:
            x, y = frame.to_local(np.array([item.x / 1e7]), np.array([item.y / 1e7]))[0]
        altitude = item.z - home_amsl_m if item.frame in (Frame.GLOBAL, Frame.GLOBAL_INT) else item.z
        items.append(LocalItem(item.seq, item.command, float(x), float(y), altitude,
                               (item.param1, item.param2, item.param3, item.param4)))
    return items


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
        self._loiter: dict | None = None
        self._demand = 0.0
        self._next_navigation_s = 0.0
        self._skip_instant_items()

    def copy(self, items: list[LocalItem] | None = None) -> "MissionFlight":
        """The flight as it is now, continuing on its own from here: stepping the copy leaves
        this one as it is.  ``items`` (same seqs, other positions or parameters) are flown
        from here on instead of the flight's own."""
        other = _copy.copy(self)
        other.items = self.items if items is None else items
        other.state = replace(self.state)
        other.reached = list(self.reached)
        other._loiter = None if self._loiter is None else dict(self._loiter)
        return other

    # -- mission sequencing ------------------------------------------------------------------

    @property
    def current(self) -> LocalItem | None:
        return self.items[self._index] if self._index < len(self.items) else None

    def _complete(self, leg_start: tuple[float, float, float] | None = None) -> None:
        item = self.current
        self.reached.append((item.seq, self.state.time_s))
        if leg_start is not None:
            self._previous = leg_start
        elif item.command in NAV_COMMANDS and not math.isnan(item.x_m):
            self._previous = (item.x_m, item.y_m, item.alt_m)
        elif item.command == Command.NAV_TAKEOFF:
            self._previous = (self.state.x_m, self.state.y_m, item.alt_m)
        self._index += 1
        self._loiter = None
        self._skip_instant_items()

    def _skip_instant_items(self) -> None:
        while (item := self.current) is not None and item.command not in NAV_COMMANDS:
            if item.command == Command.DO_CHANGE_SPEED and item.params[1] > 0:
                self.state.airspeed_m_s = float(item.params[1])
            self.reached.append((item.seq, self.state.time_s))
            self._index += 1
        if self.current is None:
            self.finished = True

    def _following(self) -> LocalItem | None:
        """The next navigation item with a position after the current one."""
        items = self.items
        for k in range(self._index + 1, len(items)):
            item = items[k]
            if item.command in NAV_COMMANDS and not math.isnan(item.x_m):
                return item
        return None

    def _next_turn_deg(self) -> float:
        """Turn angle at the current waypoint, towards the next one (ArduPlane scales the
        acceptance radius with it); 90 when the next item is no waypoint."""
        item, following = self.current, self._following()
        if following is None or following.command != Command.NAV_WAYPOINT:
            return 90.0
        a = math.atan2(item.y_m - self._previous[1], item.x_m - self._previous[0])
        b = math.atan2(following.y_m - item.y_m, following.x_m - item.x_m)
        return abs(math.degrees(math.remainder(b - a, 2 * math.pi)))

    # -- guidance ----------------------------------------------------------------------------

    def _velocity(self) -> tuple[float, float]:
        s = self.state
        return s.airspeed_m_s * math.cos(s.heading_rad), s.airspeed_m_s * math.sin(s.heading_rad)

    def _l1_lateral_accel(self, ax: float, ay: float, bx: float, by: float) -> float:
        """ArduPlane's L1 law for the line from A to B: lateral acceleration, positive to the
        left.  Behind A and farther than L1 it flies to A; well past B, to B."""
        s = self.state
        speed = s.airspeed_m_s
        vx, vy = self._velocity()
        l1 = self.airframe.l1_distance_m(speed)
        tx, ty = bx - ax, by - ay
        length = math.hypot(tx, ty)
        if length < 1e-6:
            tx, ty, length = bx - s.x_m, by - s.y_m, math.hypot(bx - s.x_m, by - s.y_m) or 1.0
        tx, ty = tx / length, ty / length
        rx, ry = s.x_m - ax, s.y_m - ay
        distance_a = math.hypot(rx, ry)
        along = rx * tx + ry * ty
        if distance_a > l1 and along / distance_a < -0.7071:
            eta = math.atan2(_cross(vx, vy, -rx, -ry), vx * -rx + vy * -ry)   # fly to A first
        elif along > length + 3.0 * speed:
            px, py = bx - s.x_m, by - s.y_m                                     # past B: to B
            eta = math.atan2(_cross(vx, vy, px, py), vx * px + vy * py)
        else:
            nu2 = math.atan2(_cross(tx, ty, vx, vy), tx * vx + ty * vy)       # velocity vs track
            nu1 = math.asin(max(-0.7071, min(0.7071, _cross(tx, ty, rx, ry) / l1)))
            eta = -(nu1 + nu2)
        eta = max(-math.pi / 2, min(math.pi / 2, eta))
        damping = self.airframe.l1_damping
        return 4 * damping ** 2 * speed ** 2 / l1 * math.sin(eta)

    def _loiter_lateral_accel(self, cx: float, cy: float, radius: float, direction: int) -> tuple[float, bool]:
        """ArduPlane's L1 loiter law around (cx, cy): lateral acceleration (positive to the
        left) and whether it is on the circle (not capturing it).  ``direction`` +1 clockwise."""
        s = self.state
        speed = s.airspeed_m_s
        vx, vy = self._velocity()
        l1 = self.airframe.l1_distance_m(speed)
        damping = self.airframe.l1_damping
        omega = 2 * math.pi / self.airframe.l1_period_s
        rx, ry = s.x_m - cx, s.y_m - cy
        distance = math.hypot(rx, ry)
        ux, uy = (rx / distance, ry / distance) if distance > 0.1 else (vx / speed, vy / speed)
        # In ArduPilot's sense: right-positive, cross products of north-east vectors.
        xtrack_velocity = -_cross(ux, uy, vx, vy)        # velocity across the radial line
        ltrack_velocity = -(vx * ux + vy * uy)           # velocity towards the centre
        nu = max(-math.pi / 2, min(math.pi / 2, math.atan2(xtrack_velocity, ltrack_velocity)))
        capture = 4 * damping ** 2 * speed ** 2 / l1 * math.sin(nu)
        error = distance - radius
        pd = error * omega ** 2 + -ltrack_velocity * 2 * damping * omega
        tangent = xtrack_velocity * direction
        if ltrack_velocity < 0 and tangent < 0:
            pd = max(pd, 0.0)
        circle = direction * (pd + tangent ** 2 / max(0.5 * radius, radius + error))
        if error > 0 and direction * capture < direction * circle:
            return -capture, False
        return -circle, True

    # -- dynamics ----------------------------------------------------------------------------

    def _fly(self, dt: float, lateral_accel: float, climb_rate: float, ground_factor: float = 1.0) -> None:
        s = self.state
        frame = self.airframe
        limit = frame.max_bank_rad(s.airspeed_m_s)
        command = max(-limit, min(limit, math.atan(lateral_accel / G)))
        # Damped second-order roll response, integrated semi-implicitly.
        w, z = frame.roll_natural_rad_s, frame.roll_damping
        s.bank_rate_rad_s += (w * w * (command - s.bank_rad) - 2 * z * w * s.bank_rate_rad_s) * dt
        s.bank_rad = max(-limit, min(limit, s.bank_rad + s.bank_rate_rad_s * dt))
        ground_speed = s.airspeed_m_s * ground_factor
        turn_rate = frame.turn_efficiency * G * math.tan(s.bank_rad) / s.airspeed_m_s
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
        frame = self.airframe
        rate = (target_alt - self.state.alt_m) / max(dt, frame.altitude_time_constant_s)
        return max(-frame.max_sink_m_s, min(frame.max_climb_m_s, rate))

    # -- items -------------------------------------------------------------------------------

    def _step_loiter_turns(self, item: LocalItem, dt: float) -> None:
        """LOITER_TURNS: capture the circle, count the turns by the bearing to the centre,
        then, with the tangent exit (param4), leave when the course points at the next
        waypoint; the next leg starts where it left (from the centre without it).
        LOITER_TIME: the same, for param1 seconds from the capture, on ArduPlane's own loiter
        radius (it keeps only the sign of param3, the direction)."""
        s = self.state
        timed = item.command == Command.NAV_LOITER_TIME
        radius = self.airframe.loiter_radius_m if timed else (abs(item.params[2])
                                                             or self.airframe.loiter_radius_m)
        direction = -1 if item.params[2] < 0 else 1
        accel, on_circle = self._loiter_lateral_accel(item.x_m, item.y_m, radius, direction)
        self._fly(dt, accel, self._toward_alt(item.alt_m, dt))
        bearing = math.atan2(s.y_m - item.y_m, s.x_m - item.x_m)
        loiter = self._loiter
        if loiter is None:
            if not on_circle:
                return
            loiter = self._loiter = {"bearing": bearing, "turned": 0.0, "counted": False,
                                     "since_s": s.time_s}
        loiter["turned"] += -direction * math.remainder(bearing - loiter["bearing"], 2 * math.pi)
        loiter["bearing"] = bearing
        if timed and s.time_s - loiter["since_s"] < max(item.params[0], 0.0):
            return
        if not timed and loiter["turned"] < 2 * math.pi * max(item.params[0], 0.0):
            return
        following = self._following()
        if item.params[3] > 0 and following is not None:
            # ArduPlane's exit test: at once if the next waypoint lies inside the circle (the
            # course could never point at it), else the course within 10 deg of it (20 deg
            # if it lies within 5 % outside), 10 deg more for each circle flown.
            offset = math.hypot(following.x_m - item.x_m, following.y_m - item.y_m)
            if offset >= 0.99 * radius:
                base = 2.0 if offset < 1.05 * radius else 1.0
                tolerance = LOITER_EXIT_HEADING_RAD * (base + math.floor(loiter["turned"] / (2 * math.pi)))
                towards = math.atan2(following.y_m - s.y_m, following.x_m - s.x_m)
                if abs(math.remainder(towards - s.heading_rad, 2 * math.pi)) > tolerance:
                    return
            self._complete((s.x_m, s.y_m, item.alt_m))
            return
        self._complete()

    def _step_takeoff(self, item: LocalItem, dt: float) -> None:
        """NAV_TAKEOFF: straight ahead until the item's altitude; the leg after it starts
        where the climb ended, at the cruise airspeed."""
        s, frame = self.state, self.airframe
        if frame.takeoff_accel_m_s2 <= 0:
            pitch = math.radians(item.params[0] or TAKEOFF_PITCH_DEG)
            self._fly(dt, 0.0, s.airspeed_m_s * math.sin(pitch), math.cos(pitch))
        else:
            if self._loiter is None:                 # the take-off run starts from rest
                self._loiter = {"speed": 0.0}
            cruise = frame.airspeed_m_s
            run = self._loiter
            run["speed"] = min(run["speed"] + frame.takeoff_accel_m_s2 * dt, 1.16 * cruise)
            climb = frame.takeoff_climb_m_s if run["speed"] >= 0.85 * cruise else 0.0
            s.airspeed_m_s = max(run["speed"], 1e-3)
            self._fly(dt, 0.0, climb)
        if s.alt_m >= item.alt_m:
            s.alt_m = item.alt_m
            s.airspeed_m_s = frame.airspeed_m_s
            self._complete()

    def _navigation_tick(self) -> bool:
        """Whether the navigation runs in this step (always, unless ``navigation_hz`` is set)."""
        rate = self.airframe.navigation_hz
        if rate <= 0:
            return True
        if self.state.time_s + 1e-9 >= self._next_navigation_s:
            self._next_navigation_s = self.state.time_s + 1.0 / rate
            return True
        return False

    def step(self, dt: float) -> None:
        """Advance ``dt`` seconds; completed items go to :attr:`reached`."""
        if self.finished:
            return
        s, item = self.state, self.current
        if item.command == Command.NAV_TAKEOFF:
            self._step_takeoff(item, dt)
            return
        if item.command in (Command.NAV_LOITER_TURNS, Command.NAV_LOITER_TIME):
            self._step_loiter_turns(item, dt)
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
            sink = self.airframe.max_sink_m_s
            climb = (wanted_alt - s.alt_m) / dt if fraction < 1 else -sink
            climb = max(-sink, min(self.airframe.max_climb_m_s, climb))
        else:
            climb = self._toward_alt(wanted_alt, dt)
        tick = self._navigation_tick()
        if tick:
            self._demand = self._l1_lateral_accel(ax, ay, bx, by)
        self._fly(dt, self._demand, climb)
        if not tick:
            return
        distance = math.hypot(bx - s.x_m, by - s.y_m)
        past_finish_line = leg > 1e-9 and ((s.x_m - bx) * (bx - ax) + (s.y_m - by) * (by - ay)) > 0
        if item.command == Command.NAV_LAND:
            if s.alt_m <= 0.0:
                s.alt_m = 0.0
                self._complete()
            return
        acceptance = item.params[1] if item.command == Command.NAV_WAYPOINT else 0.0
        if acceptance <= 0:
            l1 = self.airframe.l1_distance_m(s.airspeed_m_s)
            acceptance = min(self.airframe.wp_radius_m, l1) * min(self._next_turn_deg(), 90.0) / 90.0
            if item.command == Command.NAV_RETURN_TO_LAUNCH:
                acceptance = self.airframe.wp_radius_m
        if distance <= acceptance or past_finish_line:
            self._complete()


def closest_approach_m(track_xy: np.ndarray, points_xy: np.ndarray) -> np.ndarray:
    """For each point, the smallest distance to the polyline ``track_xy`` (exact per segment).

    A point's nearest segment has an end within (distance to the nearest vertex + the longest
    segment) of it, so only the segments at the vertices in that ball are measured."""
    from scipy.spatial import cKDTree
    track = np.asarray(track_xy, dtype=float).reshape(-1, 2)
    points = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    if len(track) == 0:
        return np.full(len(points), np.inf)
    if len(track) == 1:
        return np.hypot(*(points - track[0]).T)
    a, d = track[:-1], np.diff(track, axis=0)
    length2 = np.maximum((d * d).sum(axis=1), 1e-18)
    longest = float(np.sqrt(length2.max()))
    tree = cKDTree(track)
    nearest, _ = tree.query(points)
    result = np.empty(len(points))
    for k, (p, radius) in enumerate(zip(points, nearest)):
        vertices = np.asarray(tree.query_ball_point(p, radius + longest + 1e-9), dtype=np.int64)
        segments = np.unique(np.clip(np.concatenate([vertices - 1, vertices]), 0, len(a) - 1))
        t = np.clip(((p - a[segments]) * d[segments]).sum(axis=1) / length2[segments], 0.0, 1.0)
        q = a[segments] + t[:, None] * d[segments]
        result[k] = float(np.sqrt(((q - p) ** 2).sum(axis=1).min()))
    return result
