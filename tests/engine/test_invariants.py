"""engine.invariants: the deepest overlap against a plain reference, energy and momentum by hand."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.invariants import energy_momentum, kinetic_energy, max_penetration, momentum


def brute_penetration(pos, size) -> float:
    """The deepest overlap min(width, height) over all pairs, plainly."""
    lo = pos[:, None, :]
    hi = (pos + size)[:, None, :]
    over = np.minimum(hi, (pos + size)[None, :, :]) - np.maximum(lo, pos[None, :, :])
    depth = np.minimum(over[..., 0], over[..., 1])
    np.fill_diagonal(depth, 0.0)
    return float(max(depth.max(), 0.0))


boxes = st.integers(1, 12).flatmap(
    lambda n: st.tuples(
        st.lists(st.tuples(st.integers(0, 40), st.integers(0, 40)), min_size=n, max_size=n),
        st.lists(st.tuples(st.integers(1, 15), st.integers(1, 15)), min_size=n, max_size=n),
        st.sampled_from([1.0, 0.5, 0.25]),
    )
)


@settings(max_examples=60, deadline=None)
@given(boxes)
def test_max_penetration_is_the_deepest_overlap_of_any_pair(case):
    corners, sides, unit = case
    pos = np.array(corners, np.float64) * unit
    size = np.array(sides, np.float64)
    depth, a, b = max_penetration(pos, size)
    assert depth == brute_penetration(pos, size)
    if depth > 0:
        assert a < b
        one = brute_penetration(pos[[a, b]], size[[a, b]])
        assert one == depth
    else:
        assert (a, b) == (-1, -1)


def test_touching_boxes_have_no_penetration():
    pos = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
    assert max_penetration(pos, np.full((3, 2), 10.0))[0] == 0.0


def test_max_penetration_is_the_deepest_overlap():
    pos = np.array([[0.0, 0.0], [7.0, 2.0], [50.0, 50.0], [58.0, 50.0]])
    size = np.full((4, 2), 10.0)
    # pair (0, 1) overlaps 3 x 8 -> 3; pair (2, 3) overlaps 2 x 10 -> 2
    assert max_penetration(pos, size)[0] == 3.0
    assert max_penetration(pos[[0, 2]], size[:2])[0] == 0.0
    touching = np.array([[0.0, 0.0], [10.0, 0.0]])
    assert max_penetration(touching, size[:2])[0] == 0.0


def test_energy_and_momentum_count_movers_only():
    vel = np.array([[3.0, 4.0], [-1.0, 2.0], [0.0, 0.0]])
    mass = np.array([2.0, 0.5, np.inf])
    static = np.array([False, False, True])
    assert kinetic_energy(mass, static, vel) == pytest.approx(0.5 * 2 * 25 + 0.5 * 0.5 * 5)
    assert momentum(mass, static, vel) == pytest.approx((6.0 - 0.5, 8.0 + 1.0))
    assert energy_momentum(mass, static, vel)[0] == kinetic_energy(mass, static, vel)


def test_energy_and_momentum_are_never_negative_zero_nor_warn():
    vel = np.array([[-0.0, -0.0]])
    one, moving = np.ones(1), np.zeros(1, bool)
    assert str(kinetic_energy(one, moving, vel)) == "0.0"
    assert [str(p) for p in momentum(one, moving, vel)] == ["0.0", "0.0"]
    with np.errstate(all="raise"):
        assert kinetic_energy(one, moving, np.array([[1e200, 0.0]])) == np.inf
