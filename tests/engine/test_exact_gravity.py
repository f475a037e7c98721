"""The exact model under gravity (docs/models.md#exact-under-gravity), held to the closed forms: a
free fall at every frame, the bounce times of an elastic ball, a projectile's flight, the
stacked-ball drop, bounces on a static box and a static circle (a curved relative path), and the
energy of an elastic gas under gravity over 10,000 ticks; rest, slides and stops on the walls.
(Rest on static boxes, and the supports it does not follow: test_exact_rest_on_static.py.)"""

from __future__ import annotations

import math

import numpy as np
import pytest
from engine_refs import pile_bodies

from collide2d.engine.events import AXIS_Y, EV_PAIR, EV_WALL, SIDE_BOTTOM, TYPE_NAMES
from collide2d.engine.models import make
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, Bodies, Looks, WorldSpec

G = 980.0


def energy(model, bodies: Bodies, world: WorldSpec) -> float:
    """Kinetic plus potential energy (relative to the world's origin: -m·(g·p))."""
    m = bodies.mass
    p, v = model.positions(), model.velocities()
    return float(np.sum(0.5 * m * (v * v).sum(axis=1)) - np.sum(m * (p @ np.array(world.gravity))))


def test_a_free_fall_matches_the_closed_form_at_every_frame():
    world = WorldSpec(100, 4000, 60, gravity=(0.0, G))
    m = make("exact", world, Bodies.boxes([[40, 10]], 10, [[3, 0]]))
    for k in range(1, 120):
        m.advance(1)
        t = k / 60
        assert m.positions()[0, 1] == pytest.approx(10 + 0.5 * G * t * t, rel=1e-14, abs=1e-12)
        assert m.velocities()[0, 1] == pytest.approx(G * t, rel=1e-14)
        assert m.positions()[0, 0] == pytest.approx(40 + 3 * t, rel=1e-14)


@pytest.mark.parametrize("fps", [1, 10, 60])
def test_an_elastic_ball_bounces_at_the_closed_form_times_at_any_fps(fps):
    # dropped from rest h px above the floor: impacts at t1·(2n - 1), t1 = √(2h/g), for ever
    h = 300.0
    world = WorldSpec(50, 400, fps, gravity=(0.0, G))
    m = make("exact", world, Bodies.boxes([[20, 400 - 10 - h]], 10, [[0, 0]]))
    t1 = math.sqrt(2 * h / G)
    found = m.advance(int(math.ceil(12 * 2 * t1 * fps)) + 1)
    floor = found[(found["type"] == EV_WALL) & (found["code"] == SIDE_BOTTOM)]
    assert len(floor) >= 12 and len(found) == len(floor)  # it never reaches the ceiling
    for n, t in enumerate(floor["t"][:12], start=1):
        assert abs(t - t1 * (2 * n - 1)) <= 1e-9
        assert floor["tick"][n - 1] == math.ceil(t * fps - 1e-9)


def test_a_projectile_lands_after_the_closed_form_flight_and_range():
    v, theta = 300.0, math.radians(60)
    world = WorldSpec(2000, 500, 60, gravity=(0.0, G))
    vel = [[v * math.cos(theta), -v * math.sin(theta)]]
    m = make("exact", world, Bodies.boxes([[10, 490]], 10, vel))
    flight = 2 * v * math.sin(theta) / G
    found = m.advance(60)
    assert found["code"][0] == SIDE_BOTTOM
    assert abs(found["t"][0] - flight) <= 1e-9
    # one tick after landing it is in the air again, as far along as the range says and beyond
    assert m.positions()[0, 0] == pytest.approx(10 + v * math.cos(theta) * 1.0, rel=1e-13)
    assert v * v * math.sin(2 * theta) / G == pytest.approx(v * math.cos(theta) * flight)


@pytest.mark.parametrize("ratio", [0.1, 0.25, 1 / 3, 0.5, 1.0])
def test_the_stacked_ball_drop_sends_the_light_one_up_by_the_closed_form(ratio):
    # a light box (m) resting on a heavy one (M), dropped together from h: the heavy one bounces
    # off the floor and meets the light one at once; the light one rises ((3M - m)/(M + m))²·h
    h, big, small = 200.0, 1.0, ratio
    world = WorldSpec(60, 2000, 100, gravity=(0.0, G))
    floor_y = 2000 - 20
    pos = [[20, floor_y - h], [20, floor_y - h - 10]]
    bodies = Bodies.boxes(pos, [[20, 20], [20, 10]], [[0, 0], [0, 0]], mass=[big, small])
    m = make("exact", world, bodies)
    t1 = math.sqrt(2 * h / G)
    found = m.advance(int(t1 * 100) + 2)
    # the floor, then the pair, at one instant (then, for m = M, the floor again)
    assert [int(t) for t in found["type"][:2]] == [0, 1] and found["t"][1] == found["t"][0]
    v = (3 * big - small) / (big + small) * math.sqrt(2 * G * h)
    t_apex = found["t"][1] + v / G
    m.advance(int(math.ceil(t_apex * 100)) - m.tick)
    # from the pair's instant on the light box flies freely from where they met: the speed it
    # left with, read off its place now, rises ((3M - m)/(M + m))²·h
    y_meet = floor_y - 10
    t = m.tick / 100 - found["t"][1]
    assert m.positions()[1, 1] == pytest.approx(y_meet - v * t + 0.5 * G * t * t, rel=1e-12)
    v_left = (y_meet - m.positions()[1, 1] + 0.5 * G * t * t) / t
    rise = v_left * v_left / (2 * G)
    assert abs(rise / h - ((3 * big - small) / (big + small)) ** 2) <= 1e-9


def test_an_elastic_gas_under_gravity_keeps_its_energy_to_1e_12_over_10000_ticks():
    world = WorldSpec(300, 200, 100, gravity=(0.0, G))
    bodies = pile_bodies(40, 5, 300, size=8.0, pitch=20.0, e=1.0, mu=0.0, speed=150.0)
    m = make("exact", world, bodies)
    e0 = energy(m, bodies, world)
    worst = 0.0
    pairs = 0
    for _ in range(100):
        found = m.advance(100)
        pairs += int(np.sum(found["type"] == 1))
        worst = max(worst, abs(energy(m, bodies, world) - e0) / abs(e0))
    assert m.tick == 10_000 and pairs > 10_000  # a gas, not bodies flying apart
    assert worst <= 1e-12
    pos = m.positions()
    assert np.all(pos >= 0) and np.all(pos + bodies.size <= [300, 200])


def test_gravity_along_x_or_up_falls_that_way():
    for g in [(G, 0.0), (0.0, -G), (-300.0, 400.0)]:
        world = WorldSpec(3000, 3000, 10, gravity=g)
        m = make("exact", world, Bodies.boxes([[1400, 1400]], 10, [[5, -7]]))
        m.advance(5)
        t = 0.5
        want = np.array([1400 + 5 * t, 1400 - 7 * t]) + 0.5 * np.array(g) * t * t
        assert np.allclose(m.positions()[0], want, rtol=1e-14)


def _circles(pos, diameters, static) -> Bodies:
    n = len(pos)
    d = np.asarray(diameters, float)
    return Bodies(
        kind=np.full(n, KIND_CIRCLE, np.int8),
        pos=np.asarray(pos, float),
        size=np.stack([d, d], axis=1),
        vel=np.zeros((n, 2)),
        mass=np.ones(n),
        static=np.asarray(static, bool),
        vert_start=np.zeros(n + 1, np.int64),
        verts=np.zeros((0, 2), np.int64),
        looks=Looks(color=np.ones(n, np.uint8), fill=np.zeros(n, bool)),
    )


@pytest.mark.parametrize("shape", ["box", "circle"])
def test_an_elastic_body_bounces_on_a_static_one_at_the_closed_form_times(shape):
    # dropped from rest h px above a static object's top (a box's flat top; a circle's crown, met
    # centre over centre): impacts at t1·(2n - 1), found on the curved relative path
    world = WorldSpec(200, 1000, 60, gravity=(0.0, G))
    if shape == "box":
        bodies = Bodies.boxes([[50, 400], [40, 710]], [[10, 10], [40, 20]], [[0, 0], [0, 0]],
                              static=[False, True])  # fmt: skip
        h = 710 - 410
    else:
        bodies = _circles([[45, 400], [40, 700]], [10, 20], [False, True])
        h = 700 - 410
    m = make("exact", world, bodies)
    t1 = math.sqrt(2 * h / G)
    found = m.advance(int(60 * 12 * 2 * t1) + 1)
    assert len(found) == 12 and set(found["type"].tolist()) == {EV_PAIR}
    for n, t in enumerate(found["t"], start=1):
        assert abs(t - t1 * (2 * n - 1)) <= 1e-9
    assert m.positions()[0, 1] < 700 - 10 + 1e-9  # never inside


def test_a_projectile_meets_a_static_wall_where_its_parabola_does():
    # thrown at a static box standing on the right: it meets its left face at the instant
    # x(t) = 300 - 10, having fallen 1/2 g t² meanwhile
    world = WorldSpec(1000, 1000, 30, gravity=(0.0, G))
    bodies = Bodies.boxes([[10, 100], [300, 0]], [[10, 10], [50, 1000]], [[250, -200], [0, 0]],
                          static=[False, True])  # fmt: skip
    m = make("exact", world, bodies)
    found = m.advance(60)
    t = (300 - 10 - 10) / 250
    assert found["type"][0] == EV_PAIR and abs(found["t"][0] - t) <= 1e-12
    m2 = make("exact", world, bodies)
    m2.advance(int(t * 30))
    y = 100 - 200 * (m2.tick / 30) + 0.5 * G * (m2.tick / 30) ** 2
    assert m2.positions()[0, 1] == pytest.approx(y, rel=1e-13)


def with_(bodies: Bodies, **columns) -> Bodies:
    return Bodies(**{**bodies.__dict__, **columns})


@pytest.mark.parametrize("e", [0.5, 0.8, 0.9])
def test_a_ball_bounces_at_the_closed_form_times_then_rests_exactly_on_the_floor(e):
    # t_n = t1·(1 + 2e(1 - e^(n-1))/(1 - e)); at rest before t_inf = t1·(1 + e)/(1 - e)
    h = 300.0
    world = WorldSpec(50, 400, 60, gravity=(0.0, G))
    m = make("exact", world, with_(Bodies.boxes([[20, 90]], 10, [[0, 0]]), restitution=[e]))
    t1 = math.sqrt(2 * h / G)
    t_inf = t1 * (1 + e) / (1 - e)
    found = m.advance(int(t_inf * 60) + 2)
    walls = found[found["type"] == EV_WALL]
    # impact n leaves the ball to rise h·e^(2n): the first one under rest_height (0.01 px) ends it
    impacts = math.ceil(math.log(0.01 / h) / math.log(e * e))
    assert len(walls) == impacts and (e < 0.8 or impacts >= 12)
    for n in range(1, len(walls) + 1):
        want = t1 * (1 + 2 * e * (1 - e ** (n - 1)) / (1 - e))
        assert abs(walls["t"][n - 1] - want) <= 1e-9
    assert [TYPE_NAMES[k] for k in found["type"][-2:]] == ["wall", "rest"]
    assert found["t"][-1] < t_inf and found["code"][-1] == SIDE_BOTTOM
    assert m.positions()[0].tolist() == [20.0, 390.0] and m.velocities()[0].tolist() == [0.0, 0.0]
    assert len(m.advance(120)) == 0 and m.positions()[0].tolist() == [20.0, 390.0]  # for good


@pytest.mark.parametrize("v0, mu", [(200.0, 0.5), (90.0, 0.1), (300.0, 2.0)])
def test_a_block_slides_to_a_stop_at_the_closed_form_time_and_distance(v0, mu):
    world = WorldSpec(4000, 100, 60, gravity=(0.0, G))
    bodies = with_(Bodies.boxes([[10, 90]], 10, [[v0, 0]]), friction=[mu])
    m = make("exact", world, bodies)
    found = m.advance(int(v0 / (mu * G) * 60) + 30)
    assert [TYPE_NAMES[k] for k in found["type"]] == ["stop"]
    assert abs(found["t"][0] - v0 / (mu * G)) <= 1e-9
    assert abs((m.positions()[0, 0] - 10) - v0 * v0 / (2 * mu * G)) <= 1e-9
    assert m.velocities()[0].tolist() == [0.0, 0.0] and m.positions()[0, 1] == 90.0


@pytest.mark.parametrize("gx, moves", [(300.0, False), (600.0, True)])
def test_a_block_on_the_floor_holds_while_friction_can_hold_it(gx, moves):
    # gravity down 980 and sideways gx; mu 0.5 holds up to 490 px/s² along the floor
    world = WorldSpec(4000, 100, 10, gravity=(gx, G))
    m = make("exact", world, with_(Bodies.boxes([[10, 90]], 10, [[0, 0]]), friction=[0.5]))
    assert len(m.advance(10)) == 0
    t = 1.0
    want = 10 + 0.5 * (gx - 0.5 * G) * t * t if moves else 10.0
    assert m.positions()[0, 0] == pytest.approx(want, rel=1e-13)
    assert m.positions()[0, 1] == 90.0


@pytest.mark.parametrize("x0, held", [(60, True), (46, False)])
def test_a_resting_box_is_held_by_the_floor_or_knocked_off_it_and_energy_never_rises(x0, held):
    # a ball thrown sideways lands on the resting box's top (x0 = 60): pressed straight into the
    # floor, the box is held by it and the ball bounces off as off the floor; on its corner
    # (x0 = 46), the oblique impact knocks the box off the floor: it wakes and bounces
    world = WorldSpec(200, 400, 60, gravity=(0.0, G))
    bodies = Bodies.boxes([[x0, 100], [90, 380]], [[10, 10], [20, 20]], [[50, 0], [0, 0]],
                          mass=[1.0, 2.0])  # fmt: skip
    bodies = with_(bodies, restitution=np.array([0.9, 0.5]),
                   kind=np.array([KIND_CIRCLE, KIND_BOX], np.int8))  # fmt: skip
    m = make("exact", world, bodies)
    before = energy(m, bodies, world)
    found = []
    for _ in range(120):
        found.append(m.advance(1))
        now = energy(m, bodies, world)
        assert now <= before + 1e-9 * abs(before)
        before = now
    found = np.concatenate(found)
    kinds = [TYPE_NAMES[k] for k in found["type"]]
    box = found["a"] == 1
    if held:
        assert kinds[0] == "pair" and found["code"][0] == AXIS_Y
        assert not box.any() and m.positions()[1].tolist() == [90.0, 380.0]
    else:
        assert kinds[:3] == ["pair", "wake", "wall"] and "rest" in kinds


def test_a_cradle_resting_on_a_frictionless_floor_is_the_zero_g_cradle():
    pos = [[20 + 12 * k, 90] for k in range(5)]
    vel = [[80.0, 0.0]] + [[0.0, 0.0]] * 4
    runs = []
    for g in (0.0, G):
        m = make("exact", WorldSpec(200, 100, 30, gravity=(0.0, g)), Bodies.boxes(pos, 10, vel))
        runs.append((m.advance(300), m.positions(), m.velocities()))
    (ev0, p0, v0), (ev1, p1, v1) = runs
    assert len(ev0) > 10 and ev0.tobytes() == ev1.tobytes()
    assert np.array_equal(p0, p1) and np.array_equal(v0, v1)
