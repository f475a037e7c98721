"""Collision response: the elastic exchange keeps momentum and energy, separation and walls."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from collide2d.engine.errors import Runaway
from collide2d.engine.events import AXIS_NORMAL, AXIS_X, AXIS_XY
from collide2d.engine.response import MAX_FOLDS_PER_STEP, exchange, exchange_along, fold, separate

speeds = st.floats(-1e3, 1e3)
masses = st.sampled_from([1e-5, 0.3, 1.0, 2.5, 7.0, 1e5, 1e10])


def energy(m1, m2, v1, v2):
    return 0.5 * (m1 * (v1 @ v1) + m2 * (v2 @ v2))


def test_equal_masses_head_on_swap_velocities():
    assert exchange_along(3.0, 0.0, -5.0, 0.0, 1.0, 1.0, 1.0, 0.0) == (-5.0, 0.0, 3.0, 0.0, True)


def test_one_dimensional_outcome_is_the_textbook_formula():
    m1, m2, v1, v2 = 9.0, 1.0, 20.0, -20.0
    a, _, b, _, changed = exchange_along(v1, 0.0, v2, 0.0, 1 / m1, 1 / m2, 1.0, 0.0)
    assert changed
    assert a == pytest.approx(((m1 - m2) * v1 + 2 * m2 * v2) / (m1 + m2), rel=1e-15)  # 12
    assert b == pytest.approx(((m2 - m1) * v2 + 2 * m1 * v1) / (m1 + m2), rel=1e-15)  # 52


def test_a_static_partner_is_a_mirror():
    a, c, b, d, changed = exchange_along(3.0, 4.0, 0.0, 0.0, 1.0, 0.0, 0.6, 0.8)
    assert changed and (b, d) == (0.0, 0.0)
    # Reflection of (3, 4) in the plane with normal (0.6, 0.8): v - 2 (v·n) n = (-3, -4).
    assert a == pytest.approx(-3.0, abs=1e-14) and c == pytest.approx(-4.0, abs=1e-14)


def test_separating_pairs_are_left_alone():
    assert exchange_along(-1.0, 0.0, 1.0, 0.0, 1.0, 1.0, 1.0, 0.0) == (-1.0, 0.0, 1.0, 0.0, False)
    # Resting relative to each other: nothing to exchange either.
    assert exchange_along(2.0, 2.0, 2.0, 2.0, 1.0, 1.0, 1.0, 0.0)[4] is False


@settings(max_examples=30, deadline=None)
@given(masses, masses, speeds, speeds, speeds, speeds, st.floats(0, 2 * math.pi))
def test_exchange_keeps_momentum_and_energy_and_reverses_the_normal_speed(
    m1, m2, v1x, v1y, v2x, v2y, angle
):
    n = np.array([math.cos(angle), math.sin(angle)])
    v1, v2 = np.array([v1x, v1y]), np.array([v2x, v2y])
    a, c, b, d, changed = exchange_along(v1x, v1y, v2x, v2y, 1 / m1, 1 / m2, n[0], n[1])
    w1, w2 = np.array([a, c]), np.array([b, d])
    assert np.isfinite([a, b, c, d]).all()
    if not changed:
        assert (v2 - v1) @ n >= 0
        return
    p0, p1 = m1 * v1 + m2 * v2, m1 * w1 + m2 * w2
    scale = m1 * np.abs(v1).max() + m2 * np.abs(v2).max()
    assert np.abs(p1 - p0).max() <= 1e-12 * scale
    e0, e1 = energy(m1, m2, v1, v2), energy(m1, m2, w1, w2)
    assert abs(e1 - e0) <= 1e-12 * e0
    # The normal part of the relative velocity is reversed, the tangential part kept.
    u0, u1 = v2 - v1, w2 - w1
    assert u1 @ n == pytest.approx(-(u0 @ n), abs=1e-9 * (np.abs(u0).max() + 1))
    t = np.array([-n[1], n[0]])
    assert u1 @ t == pytest.approx(u0 @ t, abs=1e-9 * (np.abs(u0).max() + 1))


def test_corner_contact_exchanges_each_approaching_axis():
    # Approaching on both axes: both swap (equal masses).
    assert exchange(1.0, 2.0, -3.0, -4.0, 1.0, 1.0, AXIS_XY, 1.0, 1.0)[:4] == (-3.0, -4.0, 1.0, 2.0)
    # Approaching on x only: y is left alone.
    assert exchange(1.0, -2.0, -3.0, 4.0, 1.0, 1.0, AXIS_XY, 1.0, 1.0)[:4] == (-3.0, -2.0, 1.0, 4.0)
    # AXIS_X and AXIS_NORMAL with an axis normal are the same 1-D exchange.
    x = exchange(1.0, 2.0, -3.0, -4.0, 0.5, 2.0, AXIS_X, 1.0, 0.0)
    assert x == exchange(1.0, 2.0, -3.0, -4.0, 0.5, 2.0, AXIS_NORMAL, 1.0, 0.0)


def test_extreme_mass_ratio_stays_finite_and_exact():
    # A 1e10 wall-like mass hits a light one at rest: it leaves at twice the speed.
    a, _, b, _, _ = exchange_along(10.0, 0.0, 0.0, 0.0, 1e-10, 1.0, 1.0, 0.0)
    assert a == pytest.approx(10.0 * (1e10 - 1) / (1e10 + 1), rel=1e-15)
    assert b == pytest.approx(20.0 * 1e10 / (1e10 + 1), rel=1e-15)


def test_separation_shares_the_push_by_inverse_mass():
    pos = np.array([[10.0, 0.0], [18.0, 0.0]])
    size = np.array([[10.0, 10.0], [10.0, 10.0]])
    # a has mass 1, b mass 3: a moves 3/4 of the 2 px, b 1/4.
    separate(pos, size, 0, 1, 1.0, 1 / 3, AXIS_X, 1.0, 0.0, 2.0, 0.0, 100.0, 100.0)
    assert pos[:, 0].tolist() == [8.5, 18.5]


def test_separation_never_pushes_out_of_the_world():
    pos = np.array([[0.5, 0.0], [8.0, 0.0]])
    size = np.array([[10.0, 10.0], [10.0, 10.0]])
    # a can only give 0.5 px before the left wall; b takes the rest.
    separate(pos, size, 0, 1, 1.0, 1.0, AXIS_X, 1.0, 0.0, 2.5, 0.0, 100.0, 100.0)
    assert pos[:, 0].tolist() == [0.0, 10.0]
    # A static partner never moves; the other takes the whole push.
    pos = np.array([[20.0, 20.0], [25.0, 28.0]])
    separate(pos, size, 0, 1, 0.0, 1.0, AXIS_XY, 1.0, 1.0, 5.0, 2.0, 100.0, 100.0)
    assert pos.tolist() == [[20.0, 20.0], [30.0, 30.0]]


def triangle_wave(x, span):
    """Where reflecting walls at 0 and span put a free coordinate x, and how many bounces."""
    y = x % (2 * span)
    if x > span:
        folds = math.ceil(x / span) - 1
    elif x < 0:
        folds = math.ceil(-x / span)
    else:
        folds = 0
    return (y if y <= span else 2 * span - y), folds


@settings(max_examples=30, deadline=None)
@given(st.floats(-2000, 2000), st.floats(2.5, 300.0))
def test_fold_is_the_reflecting_walls_triangle_wave(x, span):
    ratio = x / span
    assume(abs(ratio - round(ratio)) > 1e-9)  # not exactly on a wall, where rounding decides
    x_ref, folds = triangle_wave(x, span)
    x_new, v_new, low, high, first_low = fold(x, 1.0, span)
    assert x_new == pytest.approx(x_ref, abs=1e-9)
    assert 0.0 <= x_new <= span
    assert low + high == folds
    assert abs(low - high) <= 1  # the walls alternate
    assert v_new == (-1.0) ** folds
    assert first_low == (x < 0)


def test_fold_refuses_a_runaway():
    with pytest.raises(Runaway, match="substeps"):
        fold(10.0 * (MAX_FOLDS_PER_STEP + 2), 1.0, 10.0)


def test_fold_pins_an_object_as_wide_as_the_world():
    assert fold(3.0, 5.0, 0.0) == (0.0, 5.0, 0, 0, False)
