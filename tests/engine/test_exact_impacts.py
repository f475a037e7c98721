"""The exact model's impacts with restitution and friction (docs/models.md#the-elastic-exchange):
a pair leaves at -e times its approach speed with momentum kept and the closed-form loss, friction
takes what Coulomb's law says at a wall and between two bodies, and three bodies collapse below
e = 7 - 4√3 and not above (where rounding keeps the collapse alive, the run stops as an event storm,
naming them)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collide2d.engine.errors import NotYetExact
from collide2d.engine.models import make
from collide2d.engine.models.exact.jam import STORM_EVENTS
from collide2d.engine.world import Bodies, WorldSpec


def with_(bodies: Bodies, **columns) -> Bodies:
    return Bodies(**{**bodies.__dict__, **columns})


@pytest.mark.parametrize("e", [0.0, 0.3, 0.9, 1.0])
def test_a_pair_leaves_at_minus_e_times_its_approach_speed(e):
    m1, m2, v1, v2 = 2.0, 5.0, 40.0, -10.0
    world = WorldSpec(1000, 100, 10)
    bodies = Bodies.boxes([[100, 40], [200, 40]], 10, [[v1, 0], [v2, 0]], mass=[m1, m2])
    m = make("exact", world, with_(bodies, restitution=np.array([1.0, e])))
    found = m.advance(20)
    assert len(found) == 1 and found["t"][0] == pytest.approx(90 / 50, rel=1e-15)
    (w1, _), (w2, _) = m.velocities()
    assert w2 - w1 == pytest.approx(-e * (v2 - v1), abs=1e-12)
    assert m1 * w1 + m2 * w2 == pytest.approx(m1 * v1 + m2 * v2, rel=1e-14)
    lost = 0.5 * (m1 * v1**2 + m2 * v2**2) - 0.5 * (m1 * w1**2 + m2 * w2**2)
    reduced = m1 * m2 / (m1 + m2)
    assert lost == pytest.approx(0.5 * reduced * (1 - e * e) * (v2 - v1) ** 2, rel=1e-12, abs=1e-9)


@pytest.mark.parametrize("mu, e", [(0.1, 1.0), (0.1, 0.5), (2.0, 0.5), (0.0, 0.5)])
def test_friction_at_a_wall_takes_mu_1_plus_e_times_the_normal_speed_at_most_all(mu, e):
    vn, vt = 30.0, 20.0
    world = WorldSpec(400, 100, 10, restitution=e, friction=mu)
    m = make("exact", world, Bodies.boxes([[100, 50], [300, 10]], 10, [[vt, vn], [0, 0]]))
    found = m.advance(20)
    assert found["type"][0] == 0 and found["t"][0] == pytest.approx(40 / 30, rel=1e-15)
    vx, vy = m.velocities()[0]
    assert vy == pytest.approx(-e * vn, abs=1e-12)
    assert vx == pytest.approx(vt - min(vt, mu * (1 + e) * vn), abs=1e-12)


def test_friction_between_two_bodies_is_coulombs_and_keeps_momentum():
    # b slides along a's face while closing on it; the larger mu of the two acts
    world = WorldSpec(1000, 1000, 10)
    bodies = Bodies.boxes([[100, 100], [30, 200]], 10, [[0, 0], [25, -30]], mass=[1.0, 3.0])
    bodies = with_(bodies, friction=np.array([0.1, 0.3]), restitution=np.array([0.5, 0.8]))
    m = make("exact", world, bodies)
    m.advance(40)
    (ax, ay), (bx, by) = m.velocities()
    e, mu, u = 0.5, 0.3, -30.0
    assert by - ay == pytest.approx(-e * u, rel=1e-12)  # normal: -e times the approach
    # tangential: the normal impulse (1 + e)|u| m_red, friction mu times it, at most all the slide
    reduced = 1.0 * 3.0 / 4.0
    jn = (1 + e) * abs(u) * reduced
    jt = min(25.0 * reduced, mu * jn)
    assert bx - ax == pytest.approx(25.0 - jt / reduced, rel=1e-12)
    assert 1.0 * ax + 3.0 * bx == pytest.approx(3.0 * 25.0, rel=1e-14)
    assert 1.0 * ay + 3.0 * by == pytest.approx(3.0 * -30.0, rel=1e-14)


def three(e, vel=(10, 0, -10), mass=(1, 1, 1), cap=20_000):
    """Three boxes in a row on x, the outer two closing in, restitution e."""
    world = WorldSpec(1000, 100, 1)
    bodies = Bodies.boxes([[400, 40], [420, 40], [440, 40]], 10, [[v, 0] for v in vel], mass=mass)
    return make("exact", world, with_(bodies, restitution=np.full(3, e)), max_events_per_tick=cap)


@pytest.mark.parametrize("e, collapses", [(0.05, True), (0.1, False)])
def test_three_bodies_collapse_below_7_minus_4_root_3_into_one_cluster(e, collapses):
    """Below e = 7 - 4√3 the impacts never end in exact arithmetic; in floats they run until the
    speeds apart round to nothing, and the three move on as one at their centre of mass's
    velocity (0 here), touching. Above it they part after a few impacts."""
    assert (e < 7 - 4 * math.sqrt(3)) == collapses
    m = three(e)
    found = m.advance(5)
    v = m.velocities()[:, 0]
    if collapses:
        assert 20 < len(found) < 1000
        assert v[0] == v[1] == v[2] and abs(v[0]) < 1e-14
        assert m.positions()[:, 0].tolist() == [410.0, 420.0, 430.0]  # touching
    else:
        assert 0 < len(found) < 20
        assert v[0] < v[1] < v[2]
        assert np.all(np.diff(m.positions()[:, 0]) >= 10 - 1e-9)  # apart, in order


def test_a_collapse_that_rounding_keeps_alive_stops_as_a_storm_naming_the_three():
    """With a heavy first body the collapse's last impacts round to no change at all: the same
    approach again and again at one instant, an event storm (docs/models.md#event-storms) that
    stops the run by name long before the event cap, and the model stays stopped."""
    m = three(0.05, mass=(3, 1, 1))
    with pytest.raises(NotYetExact, match="objects 0, 1 and 2 collide again and again in tick 1"):
        m.advance(5)
    assert sum(m.event_counts()) < 3 * STORM_EVENTS < 20_000
    with pytest.raises(NotYetExact):
        m.advance(1)
