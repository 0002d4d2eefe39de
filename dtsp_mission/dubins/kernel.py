"""The compiled core of the exact Dubins solver (Dubins 1957; words as in Shkel & Lumelsky 2001).

One function, :func:`solve_pair`, computes the shortest of the six candidate words for one pose
pair; the two batch loops around it are the only other code here.  It is branch-free (every
word is evaluated, the minimum is taken with selects) and calls no C library function, so the
batch loops compile to SIMD code.  Everything inside is in units of the turn radius: arcs as
angles in radians, the straight part in radii.

Robustness (the cases where public implementations fail):

* curve-straight-curve words are built from the actual turning-circle centres.  The outer
  tangent's length is the centre distance itself (never a square root of a rounded square);
  the inner tangent exists iff the centres are at least 2 apart, with a slack of
  ``FEASIBILITY_SLACK`` so that two opposite arcs with no straight part (distance exactly 2)
  are not lost to rounding; likewise the middle circle of the three-arc words;
* coincident centres (goal on a starting turning circle) give a pure arc, never a spurious loop;
* an arc within ``FULL_TURN_SLACK`` of a full turn is counted as no turn: such an arc is a
  rounding artefact of an arc that should be empty (e.g. headings within 1e-12 of 2*pi), and
  dropping it moves the end pose by at most that slack times the radius.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .trig import FASTMATH, atan2, sincos

TWO_PI = 2.0 * math.pi
HALF_PI = 0.5 * math.pi
#: Arcs closer than this (radians) to a full turn are treated as no turn at all.
FULL_TURN_SLACK = 1e-10
#: Slack (in radii) on the existence tests of inner tangents and of the middle circle.
FEASIBILITY_SLACK = 1e-10
#: Centres closer than this (in radii) are treated as coincident.
COINCIDENT_CENTRES = 1e-12

#: Word names, indexed by the word codes the kernel returns.
WORDS = ("LSL", "RSR", "LSR", "RSL", "RLR", "LRL")
#: Turn direction of each of the three segments of every word: +1 left, -1 right, 0 straight.
WORD_TURNS = np.array([[1, 0, 1], [-1, 0, -1], [1, 0, -1], [-1, 0, 1],
                       [-1, 1, -1], [1, -1, 1]], dtype=np.int8)

_JIT = dict(cache=True, error_model="numpy", fastmath=FASTMATH)


@numba.njit(inline="always", **_JIT)
def _turn(angle: float) -> float:
    """Angle folded into [0, 2 pi), with near-full turns counted as none."""
    r = angle - TWO_PI * math.floor(angle * (1.0 / TWO_PI))
    return 0.0 if r >= TWO_PI - FULL_TURN_SLACK else r


@numba.njit(inline="always", **_JIT)
def solve_pair(x0: float, y0: float, th0: float, x1: float, y1: float, th1: float,
               inv_rho: float):
    """Shortest Dubins path from (x0, y0, th0) to (x1, y1, th1) for turn radius 1/inv_rho.

    Headings must satisfy ``|th| < 2**20`` (the Python wrappers reduce larger ones).  Returns
    ``(word, t, p, q)``: the index into :data:`WORDS` and the three segment lengths in units of
    the radius (angles for arcs).  Among words of equal length the first in :data:`WORDS`
    order wins.
    """
    dx = (x1 - x0) * inv_rho
    dy = (y1 - y0) * inv_rho
    s0, c0 = sincos(th0)
    s1, c1 = sincos(th1)
    # Vectors between turning-circle centres (L = left circle, R = right circle; 0 start,
    # 1 goal): centre = position + (-sin, cos) for L, + (sin, -cos) for R.  The sine and
    # cosine differences are formed first, so equal headings cancel exactly (straight paths).
    llx, lly = dx + (s0 - s1), dy + (c1 - c0)
    rrx, rry = dx + (s1 - s0), dy + (c0 - c1)
    lrx, lry = dx + (s1 + s0), dy - (c1 + c0)
    rlx, rly = dx - (s1 + s0), dy + (c1 + c0)
    d_ll = math.sqrt(llx * llx + lly * lly)
    d_rr = math.sqrt(rrx * rrx + rry * rry)
    d_lr = math.sqrt(lrx * lrx + lry * lry)
    d_rl = math.sqrt(rlx * rlx + rly * rly)
    psi_ll = atan2(lly, llx)
    psi_rr = atan2(rry, rrx)

    # LSL: outer tangent along the centre line (any direction if the centres coincide).
    phi = psi_ll if d_ll > COINCIDENT_CENTRES else th0
    best_t, best_p, best_q = _turn(phi - th0), d_ll, _turn(th1 - phi)
    best = best_t + best_p + best_q
    word = 0

    # RSR.
    phi = psi_rr if d_rr > COINCIDENT_CENTRES else th0
    t, p, q = _turn(th0 - phi), d_rr, _turn(phi - th1)
    take = t + p + q < best
    word, best = (1 if take else word), (t + p + q if take else best)
    best_t, best_p, best_q = (t if take else best_t), (p if take else best_p), (q if take else best_q)

    # LSR: inner tangent, direction = centre line turned by atan2(2, s) to the left.
    p = math.sqrt(max((d_lr - 2.0) * (d_lr + 2.0), 0.0))
    phi = atan2(lry * p + 2.0 * lrx, lrx * p - 2.0 * lry)
    t, q = _turn(phi - th0), _turn(phi - th1)
    take = (d_lr >= 2.0 - FEASIBILITY_SLACK) and (t + p + q < best)
    word, best = (2 if take else word), (t + p + q if take else best)
    best_t, best_p, best_q = (t if take else best_t), (p if take else best_p), (q if take else best_q)

    # RSL: inner tangent turned to the right.
    p = math.sqrt(max((d_rl - 2.0) * (d_rl + 2.0), 0.0))
    phi = atan2(rly * p - 2.0 * rlx, rlx * p + 2.0 * rly)
    t, q = _turn(th0 - phi), _turn(th1 - phi)
    take = (d_rl >= 2.0 - FEASIBILITY_SLACK) and (t + p + q < best)
    word, best = (3 if take else word), (t + p + q if take else best)
    best_t, best_p, best_q = (t if take else best_t), (p if take else best_p), (q if take else best_q)

    # RLR: middle circle touching both right circles, middle arc pi + 2 acos(d / 4) > pi.
    half = min(d_rr * 0.25, 1.0)
    gamma = atan2(math.sqrt((1.0 - half) * (1.0 + half)), half)
    p = math.pi + 2.0 * gamma
    t, q = _turn(th0 - (psi_rr - gamma - HALF_PI)), _turn(psi_rr + gamma + HALF_PI - th1)
    take = (d_rr <= 4.0 + FEASIBILITY_SLACK) and (t + p + q < best)
    word, best = (4 if take else word), (t + p + q if take else best)
    best_t, best_p, best_q = (t if take else best_t), (p if take else best_p), (q if take else best_q)

    # LRL: mirror image.
    half = min(d_ll * 0.25, 1.0)
    gamma = atan2(math.sqrt((1.0 - half) * (1.0 + half)), half)
    p = math.pi + 2.0 * gamma
    t, q = _turn(psi_ll + gamma + HALF_PI - th0), _turn(th1 - (psi_ll - gamma - HALF_PI))
    take = (d_ll <= 4.0 + FEASIBILITY_SLACK) and (t + p + q < best)
    word = 5 if take else word
    best_t, best_p, best_q = (t if take else best_t), (p if take else best_p), (q if take else best_q)
    return word, best_t, best_p, best_q


@numba.njit(**_JIT)
def batch_lengths(x0, y0, th0, x1, y1, th1, rho, out) -> None:
    """``out[i]`` = shortest Dubins length (metres) from pose i of the start columns to pose i
    of the goal columns; all arguments but ``rho`` are 1-D float arrays of equal length."""
    inv_rho = 1.0 / rho
    for i in range(out.shape[0]):
        _, t, p, q = solve_pair(x0[i], y0[i], th0[i], x1[i], y1[i], th1[i], inv_rho)
        out[i] = (t + p + q) * rho


@numba.njit(**_JIT)
def batch_paths(x0, y0, th0, x1, y1, th1, rho, words, t_out, p_out, q_out) -> None:
    """Word codes and the three segment lengths (metres) of the shortest paths, pose by pose."""
    inv_rho = 1.0 / rho
    for i in range(words.shape[0]):
        w, t, p, q = solve_pair(x0[i], y0[i], th0[i], x1[i], y1[i], th1[i], inv_rho)
        words[i] = w
        t_out[i] = t * rho
        p_out[i] = p * rho
        q_out[i] = q * rho
