"""runner.stress.checks: the per-tick kernel against numpy, and the exact rounding to pixels."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.picture.raster import round_positions
from collide2d.runner.stress.checks import exact_round, tick_figures


def figures(pos, vel, size, mass, static, pos0, speed0, world=(100.0, 80.0), room=None):
    out = np.zeros(8)
    room = np.array(room if room else (0.0, 0.0, -1.0, -1.0))
    tick_figures(pos, vel, size, mass, static, pos0, speed0, *world, room, out)
    return out


def test_tick_figures_against_numpy():
    rng = np.random.default_rng(3)
    n = 9
    pos = rng.uniform(-5, 95, (n, 2))
    vel = rng.uniform(-50, 50, (n, 2))
    size = rng.uniform(1, 10, (n, 2))
    static = np.arange(n) % 4 == 0
    mass = np.where(static, np.inf, rng.uniform(0.1, 5, n))
    pos0 = pos + rng.uniform(-1, 1, (n, 2))
    speed0 = np.abs(vel) + rng.uniform(0, 1, (n, 2))
    room = (10.0, 10.0, 70.0, 60.0)
    out = figures(pos, vel, size, mass, static, pos0, speed0, room=room)
    m = ~static
    assert out[0] == 1.0
    outside = max(0.0, (-pos).max(), (pos + size - [100.0, 80.0]).max())
    assert out[1] == pytest.approx(outside, abs=1e-12)
    assert out[2] == pytest.approx(0.5 * np.sum(mass[m] * np.sum(vel[m] ** 2, axis=1)))
    assert out[3:5] == pytest.approx(np.sum(mass[m, None] * vel[m], axis=0))
    assert out[5] == pytest.approx(np.abs(np.abs(vel) - speed0).max())
    assert out[6] == pytest.approx(np.abs(pos - pos0)[static].max())
    esc = np.concatenate([10 - pos[m], (pos + size)[m] - [70.0, 60.0]], axis=1).max()
    assert out[7] == pytest.approx(max(esc, 0.0))


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_tick_figures_flag_a_non_finite_value(bad):
    pos = np.array([[1.0, 1.0], [5.0, 5.0]])
    vel = np.array([[1.0, 0.0], [0.0, 1.0]])
    vel[1, 0] = bad
    one = np.ones(2)
    out = figures(pos, vel, np.ones((2, 2)), one, np.zeros(2, bool), pos, np.abs(vel))
    assert out[0] == 0.0


@settings(max_examples=200, deadline=None)
@given(st.floats(-1e6, 1e6, allow_nan=False))
def test_exact_round_is_floor_of_x_plus_a_half_in_exact_arithmetic(x):
    expected = math.floor(Fraction(x) + Fraction(1, 2))
    assert exact_round(np.array([[x, -x]]))[0].tolist() == [
        expected,
        math.floor(Fraction(-x) + Fraction(1, 2)),
    ]


def test_exact_round_at_the_float_half_trap():
    x = float(np.nextafter(0.5, 0.0))  # 0.49999999999999994: x + 0.5 rounds to 1.0 in floats
    assert x + 0.5 == 1.0
    assert exact_round(np.array([[x, 2.5]])).tolist() == [[0, 3]]


def test_raster_rounds_the_float_just_below_a_half_down():
    x = float(np.nextafter(0.5, 0.0))
    assert round_positions(np.array([[x, 0.0]])).tolist() == [[0, 0]]
