"""The kernel's inlined sine/cosine and atan2 against the C library."""

import math

import numba
import numpy as np
import pytest

from dtsp_mission.dubins.trig import atan2, sincos


@numba.njit
def _sincos_many(x):
    s, c = np.empty_like(x), np.empty_like(x)
    for i in range(x.shape[0]):
        s[i], c[i] = sincos(x[i])
    return s, c


@numba.njit
def _atan2_many(y, x):
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = atan2(y[i], x[i])
    return out


@pytest.mark.parametrize("limit", [1.0, 7.0, 1e3, 2.0 ** 20 - 1])
def test_sincos_within_a_few_ulp(rng, limit):
    x = np.concatenate([rng.uniform(-limit, limit, 1_000_000),
                        np.arange(-64, 65) * (math.pi / 4), [0.0, -0.0, 1e-300, -1e-300]])
    s, c = _sincos_many(x)
    assert np.max(np.abs(s - np.sin(x))) <= 4.5e-16 * max(1.0, limit / 1e3)
    assert np.max(np.abs(c - np.cos(x))) <= 4.5e-16 * max(1.0, limit / 1e3)


def test_atan2_within_a_few_ulp(rng):
    y = rng.normal(size=1_000_000) * np.exp(rng.uniform(-30, 30, 1_000_000))
    x = rng.normal(size=1_000_000) * np.exp(rng.uniform(-30, 30, 1_000_000))
    special = np.array([[0.0, 1.0], [1.0, 0.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 1.0],
                        [-1.0, -1.0], [1e-300, -1.0], [-1e-300, -1.0], [3.0, 4.0]])
    y = np.concatenate([y, special[:, 0]])
    x = np.concatenate([x, special[:, 1]])
    assert np.max(np.abs(_atan2_many(y, x) - np.arctan2(y, x))) <= 6.7e-16
    assert _atan2_many(np.zeros(1), np.zeros(1))[0] == 0.0
