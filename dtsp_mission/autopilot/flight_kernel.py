"""The compiled step loop of the flight model (:mod:`.navigation` is its Python face).

Everything here works on plain arrays so that numba compiles it:

* the aircraft and its mission progress are one ``float64`` state vector (indices ``S_*``);
  a checkpoint of a flight is a copy of it;
* the airframe, its tuning and the wind are one ``float64`` vector (indices ``A_*``);
* the mission is column arrays: ``command`` (int64), ``position`` (n, 3: x, y, altitude above
  home; NaN x/y for items without a position), ``params`` (n, 4) and ``following`` (int64: the
  index of the next navigation item with a position after each item, -1 if none).

:func:`run` advances a flight until an item is reached, a time or the mission's end, and on
the way records what its caller asks for: reach events, track rows, a checkpoint as chosen
items become current, the exact closest approach of the track to a set of points (an event
queue keyed by distance flown: a point is looked at again only when the aircraft could have
come closer to it than its best so far) and the ground distance flown.

The guidance is ArduPlane's L1 controller acting on the ground velocity (the aircraft flies
at its airspeed in an air mass moving with the wind; the L1 distance grows with ground
speed), its waypoint completion, loiters and take-off -- see :mod:`.navigation`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..vehicle import STANDARD_GRAVITY_M_S2
from .commands import Command

#: Only :func:`run` allocates (the closest approach's event queue); everything it calls is
#: compiled without numba's reference counting (``_nrt=False``): its atomic increments and
#: decrements of each array passed from function to function took half of a flight's time
#: (measured with perf on the bundled site's mission: 23.4 -> 15.4 ms, the same flight).
_JIT_ALLOCATING = dict(cache=True, error_model="numpy", nogil=True)
_JIT = dict(_JIT_ALLOCATING, _nrt=False)

G = STANDARD_GRAVITY_M_S2

# The MAV_CMD values the flight model acts on, as plain ints (compile-time constants).
(NAV_WAYPOINT, NAV_LOITER_TURNS, NAV_LOITER_TIME, NAV_RETURN_TO_LAUNCH, NAV_LAND, NAV_TAKEOFF,
 DO_CHANGE_SPEED) = (int(c) for c in (
    Command.NAV_WAYPOINT, Command.NAV_LOITER_TURNS, Command.NAV_LOITER_TIME,
    Command.NAV_RETURN_TO_LAUNCH, Command.NAV_LAND, Command.NAV_TAKEOFF, Command.DO_CHANGE_SPEED))

# -- the state vector --------------------------------------------------------------------------
S_X, S_Y, S_ALT, S_HEADING, S_AIRSPEED, S_BANK, S_BANK_RATE, S_TIME = range(8)
S_PREV_X, S_PREV_Y, S_PREV_ALT = 8, 9, 10          # the leg starts here
S_DEMAND, S_NEXT_NAV = 11, 12                      # lateral demand held between navigation ticks
S_INDEX, S_FINISHED = 13, 14                        # the current item; 1 once the mission ended
S_LOITER, S_LOITER_BEARING, S_LOITER_TURNED, S_LOITER_SINCE = 15, 16, 17, 18
S_RUN, S_RUN_SPEED = 19, 20                         # the take-off run
S_ODOMETER = 21                                     # ground distance flown (sum of step chords)
S_MEASURE_START = 22                                # the odometer when measuring began (NaN: not yet)
S_XTRACK_I, S_LAST_WAYPOINT_UPDATE, S_LAST_NU = 23, 24, 25   # L1 integrator, its clock, last Nu
S_SPEED_TARGET = 26                                 # the airspeed the autopilot holds
S_COS_HEADING, S_SIN_HEADING = 27, 28               # cos and sin of S_HEADING, kept with it
S_TKO_EXCESS, S_TKO_END = 29, 30                    # airspeed over the target left by the climb-out,
                                                    # and when the take-off ended
S_SPEED_HELD = 31                                   # the airspeed demand on its way to the target
S_DIRECT = 32                                       # 1: ArduPlane flies to the waypoint without
                                                    # cross-tracking (the leg after a take-off)
S_SPEED_FOLLOW, S_SPEED_FOLLOW_RATE = 33, 34        # the airspeed following the demand up, its rate
STATE_SIZE = 35

# -- the airframe vector -----------------------------------------------------------------------
(A_AIRSPEED, A_L1_PERIOD, A_WP_RADIUS, A_ROLL_W, A_ROLL_Z, A_L1_DAMPING,
 A_ROLL_LIMIT, A_LOITER_RADIUS, A_CLIMB, A_SINK, A_ALT_TC, A_TKO_ACCEL, A_TKO_CLIMB,
 A_TURN_EFFICIENCY, A_NAV_HZ, A_WIND_X, A_WIND_Y, A_WIND_FULL_ALT, A_TKO_PITCH,
 A_XTRACK_I_GAIN) = range(20)
# PX4's navigation instead of ArduPlane's (1.0), and its switch distance multiplier
# (NPFG_SW_DST_MLT); for PX4, A_L1_PERIOD and A_L1_DAMPING are NPFG_PERIOD and NPFG_DAMPING
# and A_WP_RADIUS is NAV_ACC_RAD.
A_PX4, A_SWITCH_MULT = 20, 21
# The airframe's true airspeed over the airspeed asked (DO_CHANGE_SPEED), the time constant its
# airspeed follows a change with (0: at once) and the airspeed it climbs out at after the
# take-off run (0: ArduPlane's rule, lift-off at 85 % of cruise).
A_SPEED_RATIO, A_SPEED_TC, A_TKO_SPEED = 22, 23, 24
A_MAX_SPEED = 25                                     # the most airspeed it flies (0: no limit)
# ArduPlane SITL's climb-out: the airspeed the take-off ends at over the cruise airspeed (0:
# the cruise airspeed at once), held this long (s), then bled off at this rate (m/s^2).
A_TKO_END_RATIO, A_TKO_END_HOLD, A_TKO_END_DECAY = 26, 27, 28
# ArduPlane SITL's airspeed in a bank: above the target by this much per unit of (1 / cos(bank)
# - 1), the load factor's excess (m/s; 0: none).
A_BANK_SPEED = 29
# ArduPlane's TECS: how fast its airspeed demand moves to a new target (m/s^2 up and down; 0:
# at once).  Only where the airspeed follows a change at once (A_SPEED_TC 0).
A_SPEED_UP, A_SPEED_DOWN = 30, 31
# The most roll rate the roll controller asks for (rad/s; ArduPlane's RLL2SRV_RMAX; 0: none).
A_ROLL_RATE_MAX = 32
# How the airspeed follows its demand when it rises (a second-order response: natural
# frequency rad/s and damping; 0: it is the demand): ArduPlane SITL's stock plane gains speed
# at once under the throttle and overshoots as TECS trades height back.  A fall follows the
# demand as it is.
A_SPEED_UP_W, A_SPEED_UP_Z = 33, 34
AIRFRAME_SIZE = 35

LOITER_EXIT_HEADING_RAD = math.radians(10.0)
TWO_PI = 2.0 * math.pi

# run() stops for these reasons.
STOP_FINISHED, STOP_REACHED, STOP_TIME, STOP_TRACK_FULL = 0, 1, 2, 3


@numba.njit(inline="always", **_JIT)
def _wrap(angle):
    """``math.remainder(angle, 2 pi)``: the angle in [-pi, pi]."""
    return angle - TWO_PI * math.floor(angle / TWO_PI + 0.5)


@numba.njit(inline="always", **_JIT)
def _clip(value, low, high):
    return max(low, min(high, value))


@numba.njit(inline="always", **_JIT)
def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


@numba.njit(inline="always", **_JIT)
def _wind_scale(af, alt):
    """The share of the wind at this altitude: SITL's profile, the square root of the height
    over the altitude of full strength below it (none on the ground)."""
    full = af[A_WIND_FULL_ALT]
    if alt >= full:
        return 1.0
    if alt <= 0.0:
        return 0.0
    return math.sqrt(alt / full)


@numba.njit(inline="always", **_JIT)
def _hypot(x, y):
    """``math.hypot`` without its overflow guard (lengths here are metres)."""
    return math.sqrt(x * x + y * y)


@numba.njit(inline="always", **_JIT)
def _ground_velocity(st, af):
    """(vx, vy, speed) over the ground."""
    speed = st[S_AIRSPEED]
    vx = speed * st[S_COS_HEADING]
    vy = speed * st[S_SIN_HEADING]
    scale = _wind_scale(af, st[S_ALT])
    wx, wy = af[A_WIND_X] * scale, af[A_WIND_Y] * scale
    if wx == 0.0 and wy == 0.0:
        return vx, vy, speed
    vx += wx
    vy += wy
    ground = _hypot(vx, vy)
    if ground < 0.1:                      # ArduPlane's floor, along the nose
        vx = 0.1 * st[S_COS_HEADING]
        vy = 0.1 * st[S_SIN_HEADING]
        ground = 0.1
    return vx, vy, ground


@numba.njit(inline="always", **_JIT)
def l1_distance(af, speed):
    return max(af[A_L1_DAMPING] * af[A_L1_PERIOD] * speed / math.pi, 1.0)


@numba.njit(inline="always", **_JIT)
def turn_rate_rad_s(airspeed, bank_rad, efficiency):
    """How fast the aircraft turns at ``bank_rad``: ``efficiency`` times the coordinated-turn
    rate ``g tan(bank) / airspeed`` (its radius through the air: airspeed over this)."""
    return efficiency * G * math.tan(bank_rad) / airspeed


@numba.njit(inline="always", **_JIT)
def _prevent_indecision(st, eta, tx, ty):
    """ArduPlane's guard against flip-flopping: pointing away from the target (``tx``, ``ty``
    from the aircraft), more than 120 deg off the nose, with the demand near +-180 deg and of
    the other sign than the last one, the last one is kept."""
    limit = 0.9 * math.pi
    last = st[S_LAST_NU]
    if abs(eta) > limit and abs(last) > limit and eta * last < 0.0:
        off = _wrap(math.atan2(ty, tx) - st[S_HEADING])
        if abs(off) > math.radians(120.0):
            eta = last
    st[S_LAST_NU] = eta
    return eta


@numba.njit(**_JIT)
def _l1_lateral_accel(st, af, ax, ay, bx, by):
    """ArduPlane's L1 law for the line from A to B: lateral acceleration, positive to the
    left.  Behind A and farther than L1 it flies to A; well past B, to B.  On the line, the
    cross-track integrator (``NAVL1_XTRACK_I``) pushes the track onto it; it restarts when the
    law was not used for more than a second (a loiter, the take-off)."""
    x, y = st[S_X], st[S_Y]
    dt = st[S_TIME] - st[S_LAST_WAYPOINT_UPDATE]
    if dt > 1.0:
        st[S_XTRACK_I] = 0.0
    dt = min(dt, 0.1)
    st[S_LAST_WAYPOINT_UPDATE] = st[S_TIME]
    vx, vy, speed = _ground_velocity(st, af)
    l1 = l1_distance(af, speed)
    tx, ty = bx - ax, by - ay
    length = _hypot(tx, ty)
    if length < 1e-6:
        tx, ty = bx - x, by - y
        length = _hypot(tx, ty)
        if length == 0.0:
            length = 1.0
    tx, ty = tx / length, ty / length
    rx, ry = x - ax, y - ay
    distance_a = _hypot(rx, ry)
    along = rx * tx + ry * ty
    if distance_a > l1 and along / distance_a < -0.7071:
        eta = math.atan2(_cross(vx, vy, -rx, -ry), vx * -rx + vy * -ry)      # fly to A first
    elif along > length + 3.0 * speed:
        px, py = bx - x, by - y                                              # past B: to B
        eta = math.atan2(_cross(vx, vy, px, py), vx * px + vy * py)
    else:
        nu2 = math.atan2(_cross(tx, ty, vx, vy), tx * vx + ty * vy)         # velocity vs track
        nu1 = math.asin(_clip(_cross(tx, ty, rx, ry) / l1, -0.7071, 0.7071))
        gain = af[A_XTRACK_I_GAIN]
        if gain <= 0:
            st[S_XTRACK_I] = 0.0
        elif abs(nu1) < math.radians(5.0):
            st[S_XTRACK_I] = _clip(st[S_XTRACK_I] + nu1 * gain * dt, -0.1, 0.1)
        eta = -(nu1 + st[S_XTRACK_I] + nu2)
    eta = _prevent_indecision(st, eta, bx - x, by - y)
    eta = _clip(eta, -math.pi / 2, math.pi / 2)
    damping = af[A_L1_DAMPING]
    return 4 * damping * damping * speed * speed / l1 * math.sin(eta)


@numba.njit(inline="always", **_JIT)
def npfg_track_error_bound(af, ground_speed):
    """PX4 NPFG's track error bound: the ground speed times its time constant (period times
    damping), held up below 1 m/s."""
    time_const = af[A_L1_PERIOD] * af[A_L1_DAMPING]
    if ground_speed > 1.0:
        return ground_speed * time_const
    return 0.5 * time_const * (ground_speed * ground_speed + 1.0)


@numba.njit(**_JIT)
def _npfg(st, af, tx, ty, error, curvature):
    """PX4's NPFG for a path through the point nearest the aircraft with unit tangent (tx,
    ty), the aircraft ``error`` metres to its left, ``curvature`` (1/m, positive turning left):
    lateral acceleration, positive to the left.  The bearing turns from the path's normal (far
    off it) to its tangent (on it) as the look-ahead angle pi/2 (1 - e)^2 of the track error e
    normalised by the track error bound; the heading that makes the ground velocity follow the
    bearing in the wind is tracked with the gain 4 pi damping / period on the airspeed (the
    most held beyond 90 deg off); a curved path adds the acceleration that keeps the aircraft
    on it, ramped in as it comes near."""
    vx, vy, ground = _ground_velocity(st, af)
    normalized = min(abs(error) / npfg_track_error_bound(af, ground), 1.0)
    look_ahead = 0.5 * math.pi * (normalized - 1.0) * (normalized - 1.0)
    side = -1.0 if error < 0.0 else 1.0
    towards_x, towards_y = side * ty, -side * tx          # the normal towards the path
    bearing_x = math.cos(look_ahead) * towards_x + math.sin(look_ahead) * tx
    bearing_y = math.cos(look_ahead) * towards_y + math.sin(look_ahead) * ty
    airspeed = st[S_AIRSPEED]
    scale = _wind_scale(af, st[S_ALT])
    wx, wy = af[A_WIND_X] * scale, af[A_WIND_Y] * scale
    across = _cross(bearing_x, bearing_y, wx, wy)          # wind to the bearing's left
    along = math.sqrt(max(airspeed * airspeed - across * across, 0.0))
    heading_x = along * bearing_x + across * bearing_y     # cancels the crosswind
    heading_y = along * bearing_y - across * bearing_x
    off = _wrap(math.atan2(heading_y, heading_x) - st[S_HEADING])
    gain = 4.0 * math.pi * af[A_L1_DAMPING] / af[A_L1_PERIOD]
    if math.cos(off) < 0.0:
        accel = gain * (airspeed if off > 0.0 else -airspeed)
    else:
        accel = gain * airspeed * math.sin(off)
    if curvature != 0.0:
        frame_curvature = curvature / max(1.0 - curvature * error, abs(curvature) * 0.1)
        tangent_speed = max(vx * tx + vy * ty, 0.0)
        wind_across = _cross(tx, ty, wx, wy)
        projected = math.sqrt(max(airspeed * airspeed - wind_across * wind_across, 1e-6))
        ratio = 1.0 + (wx * tx + wy * ty) / projected
        proximity = math.sin(look_ahead) ** 2
        accel += airspeed * ratio * frame_curvature * tangent_speed * proximity
    return accel


@numba.njit(**_JIT)
def _npfg_lateral_accel(st, af, ax, ay, bx, by):
    """PX4's NPFG (:func:`_npfg`) for the line through A and B, towards B."""
    x, y = st[S_X], st[S_Y]
    tx, ty = bx - ax, by - ay
    length = math.hypot(tx, ty)
    if length < 1e-6:                       # no line: towards B
        tx, ty = bx - x, by - y
        length = max(math.hypot(tx, ty), 1e-9)
    tx, ty = tx / length, ty / length
    return _npfg(st, af, tx, ty, _cross(tx, ty, x - ax, y - ay), 0.0)


@numba.njit(**_JIT)
def _npfg_loiter_lateral_accel(st, af, cx, cy, radius, direction):
    """PX4's NPFG (:func:`_npfg`) for the circle of ``radius`` around (cx, cy), ``direction``
    +1 clockwise; and whether the aircraft is on it (within a tenth of the track error bound,
    as PX4 counts a loiter from there)."""
    rx, ry = st[S_X] - cx, st[S_Y] - cy
    distance = math.hypot(rx, ry)
    if distance > 0.1:
        ux, uy = rx / distance, ry / distance
    else:
        ux, uy = math.cos(st[S_HEADING] - math.pi / 2), math.sin(st[S_HEADING] - math.pi / 2)
    if direction > 0:                       # clockwise: the centre to the right
        tx, ty, curvature = uy, -ux, -1.0 / radius
    else:
        tx, ty, curvature = -uy, ux, 1.0 / radius
    error = _cross(tx, ty, (distance - radius) * ux, (distance - radius) * uy)
    _, _, ground = _ground_velocity(st, af)
    on_circle = abs(distance - radius) < 0.1 * npfg_track_error_bound(af, ground)
    return _npfg(st, af, tx, ty, error, curvature), on_circle


@numba.njit(**_JIT)
def _loiter_lateral_accel(st, af, cx, cy, radius, direction):
    """ArduPlane's L1 loiter law around (cx, cy): lateral acceleration (positive to the left)
    and whether it is on the circle (not capturing it).  ``direction`` +1 clockwise."""
    vx, vy, speed = _ground_velocity(st, af)
    l1 = l1_distance(af, speed)
    damping = af[A_L1_DAMPING]
    omega = 2 * math.pi / af[A_L1_PERIOD]
    rx, ry = st[S_X] - cx, st[S_Y] - cy
    distance = math.hypot(rx, ry)
    if distance > 0.1:
        ux, uy = rx / distance, ry / distance
    else:
        ux, uy = vx / speed, vy / speed
    # In ArduPilot's sense: right-positive, cross products of north-east vectors.
    xtrack_velocity = -_cross(ux, uy, vx, vy)        # velocity across the radial line
    ltrack_velocity = -(vx * ux + vy * uy)           # velocity towards the centre
    nu = -_prevent_indecision(st, -math.atan2(xtrack_velocity, ltrack_velocity), -rx, -ry)
    nu = _clip(nu, -math.pi / 2, math.pi / 2)
    capture = 4 * damping * damping * speed * speed / l1 * math.sin(nu)
    error = distance - radius
    pd = error * omega * omega + -ltrack_velocity * 2 * damping * omega
    tangent = xtrack_velocity * direction
    if ltrack_velocity < 0 and tangent < 0:
        pd = max(pd, 0.0)
    circle = direction * (pd + tangent * tangent / max(0.5 * radius, radius + error))
    if error > 0 and direction * capture < direction * circle:
        return -capture, False
    return -circle, True


@numba.njit(**_JIT)
def _fly(st, af, dt, lateral_accel, climb_rate, ground_factor):
    """One step of the point mass: the roll follows its command as a damped second-order
    response, the aircraft turns at its bank (exact arc of the step through the air) and
    drifts with the wind."""
    airspeed = st[S_AIRSPEED]
    limit = math.radians(af[A_ROLL_LIMIT])
    command = _clip(math.atan(lateral_accel / G), -limit, limit)
    w, z = af[A_ROLL_W], af[A_ROLL_Z]
    # The second-order roll response is the roll controller's: a roll rate asked for in
    # proportion to the bank error (w / 2z per second), followed with a lag of 1 / 2zw; the
    # rate asked for is limited (RLL2SRV_RMAX), which slows the large reversals.
    limit_rate = af[A_ROLL_RATE_MAX]
    asked = w / (2.0 * z) * (command - st[S_BANK]) if limit_rate > 0.0 else 0.0
    if abs(asked) > limit_rate > 0.0:
        st[S_BANK_RATE] += 2.0 * z * w * (math.copysign(limit_rate, asked) - st[S_BANK_RATE]) * dt
    else:
        st[S_BANK_RATE] += (w * w * (command - st[S_BANK]) - 2 * z * w * st[S_BANK_RATE]) * dt
    st[S_BANK] = _clip(st[S_BANK] + st[S_BANK_RATE] * dt, -limit, limit)
    air = airspeed * ground_factor
    turn_rate = turn_rate_rad_s(airspeed, st[S_BANK], af[A_TURN_EFFICIENCY])
    heading = st[S_HEADING] + turn_rate * dt
    cos_heading, sin_heading = math.cos(heading), math.sin(heading)
    if abs(turn_rate) > 1e-12:    # exact arc of the step
        radius = air / turn_rate
        dx = radius * (sin_heading - st[S_SIN_HEADING])
        dy = -radius * (cos_heading - st[S_COS_HEADING])
    else:
        dx = air * dt * cos_heading
        dy = air * dt * sin_heading
    scale = _wind_scale(af, st[S_ALT])
    dx += af[A_WIND_X] * scale * dt
    dy += af[A_WIND_Y] * scale * dt
    st[S_X] += dx
    st[S_Y] += dy
    st[S_ODOMETER] += _hypot(dx, dy)
    st[S_HEADING] = _wrap(heading)
    st[S_COS_HEADING], st[S_SIN_HEADING] = cos_heading, sin_heading
    st[S_ALT] += climb_rate * dt
    st[S_TIME] += dt


@numba.njit(inline="always", **_JIT)
def _toward_alt(st, af, target_alt, dt):
    rate = (target_alt - st[S_ALT]) / max(dt, af[A_ALT_TC])
    return _clip(rate, -af[A_SINK], af[A_CLIMB])


@numba.njit(inline="always", **_JIT)
def _is_nav(command):
    return (command == NAV_WAYPOINT or command == NAV_TAKEOFF or command == NAV_LAND
            or command == NAV_RETURN_TO_LAUNCH or command == NAV_LOITER_TURNS
            or command == NAV_LOITER_TIME)


@numba.njit(**_JIT)
def _skip_instant_items(st, af, command, params, reached, counts):
    """Items that do not navigate are done as they become current (DO_CHANGE_SPEED sets the
    airspeed)."""
    n = len(command)
    i = int(st[S_INDEX])
    while i < n and not _is_nav(command[i]):
        if command[i] == DO_CHANGE_SPEED and params[i, 1] > 0:
            st[S_SPEED_TARGET] = params[i, 1] * af[A_SPEED_RATIO]
            if af[A_MAX_SPEED] > 0.0:
                st[S_SPEED_TARGET] = min(st[S_SPEED_TARGET], af[A_MAX_SPEED])
            if af[A_SPEED_TC] <= 0.0 and af[A_SPEED_UP] <= 0.0 and af[A_SPEED_DOWN] <= 0.0:
                st[S_AIRSPEED] = st[S_SPEED_TARGET]
                st[S_SPEED_HELD] = st[S_SPEED_TARGET]
                st[S_SPEED_FOLLOW] = st[S_SPEED_TARGET]
        _record_reached(reached, counts, i, st[S_TIME])
        i += 1
    st[S_INDEX] = i
    if i >= n:
        st[S_FINISHED] = 1.0


@numba.njit(inline="always", **_JIT)
def _record_reached(reached, counts, index, time):
    k = counts[0]
    if k < reached.shape[0]:
        reached[k, 0] = index
        reached[k, 1] = time
    counts[0] = k + 1


@numba.njit(**_JIT)
def _complete(st, af, command, position, params, reached, counts, leg_x, leg_y, leg_alt, has_leg):
    """The current item is done; the next leg starts at (leg_x, leg_y, leg_alt) if
    ``has_leg``, after a take-off where the climb ended, else at the item."""
    i = int(st[S_INDEX])
    _record_reached(reached, counts, i, st[S_TIME])
    c = command[i]
    if has_leg:
        st[S_PREV_X], st[S_PREV_Y], st[S_PREV_ALT] = leg_x, leg_y, leg_alt
    elif c == NAV_TAKEOFF:          # ArduPlane: no cross-track after a take-off
        st[S_PREV_X], st[S_PREV_Y], st[S_PREV_ALT] = st[S_X], st[S_Y], position[i, 2]
    elif _is_nav(c) and not math.isnan(position[i, 0]):
        st[S_PREV_X], st[S_PREV_Y], st[S_PREV_ALT] = position[i, 0], position[i, 1], position[i, 2]
    st[S_INDEX] = i + 1
    st[S_LOITER] = 0.0
    st[S_RUN] = 0.0
    ardupilot = af[A_PX4] <= 0.0
    # ArduPlane does not cross-track on the leg after a take-off: its L1 law flies from where
    # the aircraft is, every navigation tick, straight to the waypoint
    st[S_DIRECT] = 1.0 if c == NAV_TAKEOFF and ardupilot else 0.0
    _skip_instant_items(st, af, command, params, reached, counts)
    k = int(st[S_INDEX])
    if (ardupilot and k < len(command) and command[k] == NAV_WAYPOINT
            and not math.isnan(position[k, 0])):
        # ArduPlane's set_next_WP: already past the new waypoint's finish line where the leg
        # starts, the leg starts here instead (else the waypoint would count as passed at once)
        ax, ay = st[S_PREV_X], st[S_PREV_Y]
        bx, by = position[k, 0], position[k, 1]
        if (st[S_X] - bx) * (bx - ax) + (st[S_Y] - by) * (by - ay) > 0.0:
            st[S_PREV_X], st[S_PREV_Y], st[S_PREV_ALT] = st[S_X], st[S_Y], st[S_ALT]


@numba.njit(**_JIT)
def _next_turn_deg(st, command, position, following, i):
    """Turn angle at waypoint ``i`` towards the next navigation item with a position, a
    loiter's centre included (ArduPlane's ``get_next_ground_course_cd``; it scales the
    acceptance radius with it); 90 when there is none."""
    k = following[i]
    if k < 0:
        return 90.0
    a = math.atan2(position[i, 1] - st[S_PREV_Y], position[i, 0] - st[S_PREV_X])
    b = math.atan2(position[k, 1] - position[i, 1], position[k, 0] - position[i, 0])
    return abs(math.degrees(_wrap(b - a)))


@numba.njit(**_JIT)
def _step_loiter(st, af, command, position, params, following, reached, counts, dt):
    """LOITER_TURNS: capture the circle, count the turns by the bearing to the centre, then,
    with the tangent exit (param4), leave when the ground course points at the next waypoint;
    the next leg starts where it left (from the centre without it).  LOITER_TIME: the same,
    for param1 seconds from the capture, on ArduPlane's own loiter radius (it keeps only the
    sign of param3, the direction).  PX4 (``A_PX4``) follows the circle with NPFG, and its
    LOITER_TIME's radius is param3's (NAV_LOITER_RAD if 0)."""
    i = int(st[S_INDEX])
    cx, cy, calt = position[i, 0], position[i, 1], position[i, 2]
    timed = command[i] == NAV_LOITER_TIME
    if timed or params[i, 2] == 0.0:
        radius = af[A_LOITER_RADIUS]
    else:
        radius = abs(params[i, 2])
    direction = -1 if params[i, 2] < 0 else 1
    if af[A_PX4] > 0.0:                     # PX4: NAV_LOITER_TIME's radius is param3's
        if timed and params[i, 2] != 0.0:
            radius = abs(params[i, 2])
        accel, on_circle = _npfg_loiter_lateral_accel(st, af, cx, cy, radius, direction)
    else:
        accel, on_circle = _loiter_lateral_accel(st, af, cx, cy, radius, direction)
    _fly(st, af, dt, accel, _toward_alt(st, af, calt, dt), 1.0)
    bearing = math.atan2(st[S_Y] - cy, st[S_X] - cx)
    if st[S_LOITER] == 0.0:
        if not on_circle:
            return
        st[S_LOITER] = 1.0
        st[S_LOITER_BEARING] = bearing
        st[S_LOITER_TURNED] = 0.0
        st[S_LOITER_SINCE] = st[S_TIME]
    st[S_LOITER_TURNED] += -direction * _wrap(bearing - st[S_LOITER_BEARING])
    st[S_LOITER_BEARING] = bearing
    if timed and st[S_TIME] - st[S_LOITER_SINCE] < max(params[i, 0], 0.0):
        return
    if not timed and st[S_LOITER_TURNED] < TWO_PI * max(params[i, 0], 0.0):
        return
    k = following[i]
    if params[i, 3] > 0 and k >= 0:
        # ArduPlane's exit test: at once if the next waypoint lies inside the circle (the
        # course could never point at it), else the course within 10 deg of it (20 deg if it
        # lies within 5 % outside), 10 deg more for each circle flown.
        offset = math.hypot(position[k, 0] - cx, position[k, 1] - cy)
        if offset >= 0.99 * radius:
            base = 2.0 if offset < 1.05 * radius else 1.0
            tolerance = LOITER_EXIT_HEADING_RAD * (base + math.floor(st[S_LOITER_TURNED] / TWO_PI))
            towards = math.atan2(position[k, 1] - st[S_Y], position[k, 0] - st[S_X])
            vx, vy, _ = _ground_velocity(st, af)
            course = math.atan2(vy, vx)
            if abs(_wrap(towards - course)) > tolerance:
                return
        _complete(st, af, command, position, params, reached, counts, st[S_X], st[S_Y], calt, True)
        return
    _complete(st, af, command, position, params, reached, counts, 0.0, 0.0, 0.0, False)


@numba.njit(**_JIT)
def _step_takeoff(st, af, command, position, params, reached, counts, dt):
    """NAV_TAKEOFF: straight ahead until the item's altitude; the leg after it starts where
    the climb ended, at the cruise airspeed."""
    i = int(st[S_INDEX])
    if af[A_TKO_ACCEL] <= 0:
        pitch = math.radians(params[i, 0] if params[i, 0] != 0.0 else af[A_TKO_PITCH])
        _fly(st, af, dt, 0.0, st[S_AIRSPEED] * math.sin(pitch), math.cos(pitch))
    else:
        if st[S_RUN] == 0.0:                 # the take-off run starts from rest
            st[S_RUN] = 1.0
            st[S_RUN_SPEED] = 0.0
        cruise = af[A_AIRSPEED]
        if af[A_TKO_SPEED] > 0.0:            # up to the climb-out airspeed, lift-off there
            top, lift_off = af[A_TKO_SPEED], af[A_TKO_SPEED]
        else:
            top, lift_off = 1.16 * cruise, 0.85 * cruise
        st[S_RUN_SPEED] = min(st[S_RUN_SPEED] + af[A_TKO_ACCEL] * dt, top)
        climb = af[A_TKO_CLIMB] if st[S_RUN_SPEED] >= lift_off else 0.0
        st[S_AIRSPEED] = max(st[S_RUN_SPEED], 1e-3)
        _fly(st, af, dt, 0.0, climb, 1.0)
    if st[S_ALT] >= position[i, 2]:
        st[S_ALT] = position[i, 2]
        if af[A_SPEED_TC] <= 0.0:
            st[S_AIRSPEED] = af[A_AIRSPEED]
            if af[A_TKO_END_RATIO] > 0.0:
                st[S_TKO_EXCESS] = (af[A_TKO_END_RATIO] - 1.0) * af[A_AIRSPEED]
                st[S_TKO_END] = st[S_TIME]
        st[S_SPEED_TARGET] = af[A_AIRSPEED]
        st[S_SPEED_HELD] = af[A_AIRSPEED]
        st[S_SPEED_FOLLOW], st[S_SPEED_FOLLOW_RATE] = af[A_AIRSPEED], 0.0
        _complete(st, af, command, position, params, reached, counts, 0.0, 0.0, 0.0, False)


@numba.njit(inline="always", **_JIT)
def _navigation_tick(st, af):
    """Whether the navigation runs in this step (always, unless a navigation rate is set)."""
    rate = af[A_NAV_HZ]
    if rate <= 0:
        return True
    if st[S_TIME] + 1e-9 >= st[S_NEXT_NAV]:
        st[S_NEXT_NAV] = st[S_TIME] + 1.0 / rate
        return True
    return False


@numba.njit(**_JIT)
def step(st, af, command, position, params, following, reached, counts, dt):
    """Advance one step of ``dt`` seconds; completed items go to ``reached`` (rows index,
    time; ``counts[0]`` of them)."""
    if st[S_FINISHED] != 0.0:
        return
    i = int(st[S_INDEX])
    c = command[i]
    if c == NAV_TAKEOFF:
        _step_takeoff(st, af, command, position, params, reached, counts, dt)
        return
    if af[A_SPEED_TC] > 0.0:
        st[S_AIRSPEED] += (st[S_SPEED_TARGET] - st[S_AIRSPEED]) * min(dt / af[A_SPEED_TC], 1.0)
    elif (st[S_TKO_EXCESS] > 0.0 or af[A_BANK_SPEED] > 0.0
          or st[S_SPEED_HELD] != st[S_SPEED_TARGET]
          or st[S_SPEED_FOLLOW_RATE] != 0.0 or st[S_SPEED_FOLLOW] != st[S_SPEED_HELD]):
        held, target = st[S_SPEED_HELD], st[S_SPEED_TARGET]
        if target > held:
            held = min(target, held + af[A_SPEED_UP] * dt) if af[A_SPEED_UP] > 0.0 else target
        elif target < held:
            held = max(target, held - af[A_SPEED_DOWN] * dt) if af[A_SPEED_DOWN] > 0.0 else target
        st[S_SPEED_HELD] = held
        if af[A_SPEED_UP_W] > 0.0 and target >= held:
            # rising (or settled after rising): the airspeed's second-order response to the demand
            w = af[A_SPEED_UP_W]
            rate = st[S_SPEED_FOLLOW_RATE]
            rate += (w * w * (held - st[S_SPEED_FOLLOW]) - 2.0 * af[A_SPEED_UP_Z] * w * rate) * dt
            st[S_SPEED_FOLLOW_RATE] = rate
            st[S_SPEED_FOLLOW] += rate * dt
        else:
            st[S_SPEED_FOLLOW], st[S_SPEED_FOLLOW_RATE] = held, 0.0
        excess = 0.0
        if st[S_TKO_EXCESS] > 0.0:        # the climb-out's airspeed bled off to the target
            bled = af[A_TKO_END_DECAY] * max(st[S_TIME] - st[S_TKO_END] - af[A_TKO_END_HOLD], 0.0)
            excess = st[S_TKO_EXCESS] - bled
            if excess <= 0.0:
                st[S_TKO_EXCESS] = 0.0
                excess = 0.0
        # faster in a bank (the load factor's excess), slower again as it levels
        excess += af[A_BANK_SPEED] * (1.0 / math.cos(st[S_BANK]) - 1.0)
        st[S_AIRSPEED] = st[S_SPEED_FOLLOW] + excess
    if c == NAV_LOITER_TURNS or c == NAV_LOITER_TIME:
        _step_loiter(st, af, command, position, params, following, reached, counts, dt)
        return
    if c == NAV_RETURN_TO_LAUNCH:
        bx, by, b_alt = 0.0, 0.0, st[S_PREV_ALT]
    else:
        bx, by, b_alt = position[i, 0], position[i, 1], position[i, 2]
    ax, ay, a_alt = st[S_PREV_X], st[S_PREV_Y], st[S_PREV_ALT]
    leg = _hypot(bx - ax, by - ay)
    if leg > 1e-9:
        along = ((st[S_X] - ax) * (bx - ax) + (st[S_Y] - ay) * (by - ay)) / leg
        fraction = min(max(along / leg, 0.0), 1.0)
    else:
        fraction = 1.0
    wanted_alt = a_alt + (b_alt - a_alt) * fraction       # altitude by leg progress
    if c == NAV_LAND:
        sink = af[A_SINK]
        climb = (wanted_alt - st[S_ALT]) / dt if fraction < 1 else -sink
        climb = _clip(climb, -sink, af[A_CLIMB])
    else:
        climb = _toward_alt(st, af, wanted_alt, dt)
    tick = _navigation_tick(st, af)
    px4 = af[A_PX4] > 0.0
    if tick:
        if px4:
            st[S_DEMAND] = _npfg_lateral_accel(st, af, ax, ay, bx, by)
        elif st[S_DIRECT] != 0.0:         # from where the aircraft is (no cross-track)
            st[S_DEMAND] = _l1_lateral_accel(st, af, st[S_X], st[S_Y], bx, by)
        else:
            st[S_DEMAND] = _l1_lateral_accel(st, af, ax, ay, bx, by)
    _fly(st, af, dt, st[S_DEMAND], climb, 1.0)
    if not tick:
        return
    x, y = st[S_X], st[S_Y]
    distance = _hypot(bx - x, by - y)
    past_finish_line = leg > 1e-9 and ((x - bx) * (bx - ax) + (y - by) * (by - ay)) > 0
    if c == NAV_LAND:
        if st[S_ALT] <= 0.0:
            st[S_ALT] = 0.0
            _complete(st, af, command, position, params, reached, counts, 0.0, 0.0, 0.0, False)
        return
    acceptance = params[i, 1] if c == NAV_WAYPOINT else 0.0
    if px4:
        # PX4: within the item's acceptance radius (NAV_ACC_RAD without one) or the position
        # controller's switch distance (NPFG_SW_DST_MLT of the track error bound), whichever
        # is larger; no finish line.
        _, _, speed = _ground_velocity(st, af)
        acceptance = max(acceptance if acceptance > 0 else af[A_WP_RADIUS],
                         af[A_SWITCH_MULT] * npfg_track_error_bound(af, speed))
        if distance <= acceptance:
            _complete(st, af, command, position, params, reached, counts, 0.0, 0.0, 0.0, False)
        return
    if acceptance <= 0:
        _, _, speed = _ground_velocity(st, af)
        l1 = l1_distance(af, speed)
        acceptance = min(af[A_WP_RADIUS], l1) * min(
            _next_turn_deg(st, command, position, following, i), 90.0) / 90.0
        if c == NAV_RETURN_TO_LAUNCH:
            acceptance = af[A_WP_RADIUS]
    if distance <= acceptance or past_finish_line:
        _complete(st, af, command, position, params, reached, counts, 0.0, 0.0, 0.0, False)


# -- closest approach: an event queue keyed by distance flown -----------------------------------

@numba.njit(inline="always", **_JIT)
def _heap_push(keys, ids, size, key, ident):
    k = size
    keys[k] = key
    ids[k] = ident
    while k > 0:
        parent = (k - 1) >> 1
        if keys[parent] <= keys[k]:
            break
        keys[parent], keys[k] = keys[k], keys[parent]
        ids[parent], ids[k] = ids[k], ids[parent]
        k = parent
    return size + 1


@numba.njit(inline="always", **_JIT)
def _heap_pop(keys, ids, size):
    """Removes the top; returns the new size."""
    size -= 1
    keys[0] = keys[size]
    ids[0] = ids[size]
    k = 0
    while True:
        left = 2 * k + 1
        if left >= size:
            break
        child = left
        if left + 1 < size and keys[left + 1] < keys[left]:
            child = left + 1
        if keys[k] <= keys[child]:
            break
        keys[k], keys[child] = keys[child], keys[k]
        ids[k], ids[child] = ids[child], ids[k]
        k = child
    return size


@numba.njit(inline="always", **_JIT)
def _segment_distance(px, py, ax, ay, bx, by):
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    t = 0.0
    if length2 > 1e-18:
        t = min(max(((px - ax) * dx + (py - ay) * dy) / length2, 0.0), 1.0)
    return _hypot(ax + t * dx - px, ay + t * dy - py)


@numba.njit(**_JIT)
def _approach_update(points, best, keys, ids, size, x0, y0, x1, y1, odometer, cap):
    """Every point due by ``odometer``: its best distance to the step's chord (x0, y0) ->
    (x1, y1), and looked at again once the aircraft could have come closer than its best or
    ``cap``, whichever is less (a point never passed within ``cap`` keeps a best that is only
    an upper bound of its least distance, at least ``cap``)."""
    while size > 0 and keys[0] <= odometer:
        j = ids[0]
        size = _heap_pop(keys, ids, size)
        d = _segment_distance(points[j, 0], points[j, 1], x0, y0, x1, y1)
        if d < best[j]:
            best[j] = d
        here = _hypot(points[j, 0] - x1, points[j, 1] - y1)
        size = _heap_push(keys, ids, size, odometer + max(here - min(best[j], cap), 1e-9), j)
    return size


@numba.njit(**_JIT_ALLOCATING)
def run(st, af, command, position, params, following, dt, stop_index, stop_time,
        reached, counts, track, marks, checkpoints, points, best, measure_from, cap):
    """Steps the flight ``st`` until the mission ends (:data:`STOP_FINISHED`), item
    ``stop_index`` (or a later one) is reached (:data:`STOP_REACHED`; -1: never), the time
    reaches ``stop_time`` (:data:`STOP_TIME`) or the track buffer is full
    (:data:`STOP_TRACK_FULL`: call again to go on).

    * ``reached``/``counts[0]``: reach events (index, time) appended;
    * ``track``/``counts[1]``: a row (time, x, y, altitude) appended per step (a buffer of
      zero rows records nothing);
    * ``marks``/``checkpoints``: as item k with ``marks[k]`` becomes current, a copy of the
      state and of ``best`` goes to ``checkpoints[k]``;
    * ``points``/``best``: the least distance of the track to each point, flown from the
      moment item ``measure_from`` is current or later (``best`` holds the starting values;
      exact where below ``cap``, see :func:`_approach_update`);
      ``st[S_MEASURE_START]``, if NaN, gets the odometer (ground distance flown) then.
    """
    n_points = points.shape[0]
    keys = np.empty(max(n_points, 1))
    ids = np.empty(max(n_points, 1), dtype=np.int64)
    return _run(st, af, command, position, params, following, dt, stop_index, stop_time,
                reached, counts, track, marks, checkpoints, points, best, measure_from, cap,
                keys, ids)


@numba.njit(**_JIT)
def _run(st, af, command, position, params, following, dt, stop_index, stop_time,
         reached, counts, track, marks, checkpoints, points, best, measure_from, cap, keys, ids):
    """:func:`run`, with the closest approach's event queue in ``keys`` and ``ids``."""
    n_points = points.shape[0]
    size = 0
    measuring = False
    record = track.shape[0] > 0
    seen = -1
    while True:
        if st[S_FINISHED] != 0.0:
            return STOP_FINISHED
        if st[S_TIME] >= stop_time:
            return STOP_TIME
        if record and counts[1] >= track.shape[0]:
            return STOP_TRACK_FULL
        i = int(st[S_INDEX])
        if i != seen:
            seen = i
            if marks.shape[0] > i and marks[i]:
                for j in range(STATE_SIZE):
                    checkpoints[i, j] = st[j]
                for j in range(n_points):
                    checkpoints[i, STATE_SIZE + j] = best[j]
        if not measuring and i >= measure_from:
            measuring = True
            if math.isnan(st[S_MEASURE_START]):
                st[S_MEASURE_START] = st[S_ODOMETER]
            for j in range(n_points):
                size = _heap_push(keys, ids, size, st[S_ODOMETER], j)
        x0, y0 = st[S_X], st[S_Y]
        before = counts[0]
        step(st, af, command, position, params, following, reached, counts, dt)
        if measuring:
            size = _approach_update(points, best, keys, ids, size, x0, y0, st[S_X], st[S_Y],
                                    st[S_ODOMETER], cap)
        if record:
            k = counts[1]
            track[k, 0] = st[S_TIME]
            track[k, 1] = st[S_X]
            track[k, 2] = st[S_Y]
            track[k, 3] = st[S_ALT]
            counts[1] = k + 1
        if stop_index >= 0 and counts[0] > before:
            last = min(counts[0], reached.shape[0]) - 1
            if reached[last, 0] >= stop_index:
                return STOP_REACHED


def new_state(heading_rad: float, airspeed_m_s: float, first_index: int) -> np.ndarray:
    """A flight at rest at home (0, 0, 0) facing ``heading_rad``, item ``first_index`` current
    (instant items not yet skipped: :func:`start`)."""
    st = np.zeros(STATE_SIZE)
    st[S_HEADING] = heading_rad
    st[S_COS_HEADING], st[S_SIN_HEADING] = math.cos(heading_rad), math.sin(heading_rad)
    st[S_AIRSPEED] = airspeed_m_s
    st[S_SPEED_TARGET] = airspeed_m_s
    st[S_SPEED_HELD] = airspeed_m_s
    st[S_SPEED_FOLLOW] = airspeed_m_s
    st[S_INDEX] = first_index
    st[S_MEASURE_START] = math.nan
    st[S_LAST_WAYPOINT_UPDATE] = -math.inf
    return st


@numba.njit(**_JIT)
def start(st, af, command, params, reached, counts):
    """Skips the instant items at the start of the mission."""
    _skip_instant_items(st, af, command, params, reached, counts)
