"""The exact model's rest on a static box's face (docs/models.md#exact-under-gravity), held to the
closed forms: bounces on a platform at their times, then lying exactly on it; a slide with
friction stopping where the formulas say; sliding off the edge (`leave`) and landing as a
projectile from there; a circle that flies clear of the corner or would slide round it; across
the seam of two platforms; stacks, each box resting on one resting still; and the supports it
does not follow (curved, knocked into motion), stopped by name."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collide2d.engine.errors import NotYetExact
from collide2d.engine.events import EV_PAIR, SIDE_BOTTOM, SIDE_RIGHT, TYPE_NAMES
from collide2d.engine.models import make
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, Bodies, WorldSpec

G = 980.0
WORLD = WorldSpec(200, 1000, 60, gravity=(0.0, G))
# a static platform 40 px wide, its top at y = 710; the floor at y = 1000
PLATFORM = ([40, 710], [40, 20])


def with_(bodies: Bodies, **columns) -> Bodies:
    return Bodies(**{**bodies.__dict__, **columns})


def on_platform(x, y, vx, size=10, kind=KIND_BOX, e=1.0, mu=0.0, world=WORLD):
    """The model of a body at (x, y) moving at vx above or on PLATFORM (object 1)."""
    bodies = Bodies.boxes([[x, y], PLATFORM[0]], [[size, size], PLATFORM[1]], [[vx, 0], [0, 0]],
                          static=[False, True])  # fmt: skip
    bodies = with_(bodies, kind=np.array([kind, KIND_BOX], np.int8),
                   restitution=np.array([e, 1.0]), friction=np.array([mu, 0.0]))  # fmt: skip
    return make("exact", world, bodies)


def names(found) -> list[str]:
    return [TYPE_NAMES[k] for k in found["type"]]


@pytest.mark.parametrize("e", [0.5, 0.8])
def test_a_box_bounces_on_a_platform_at_the_closed_form_times_then_rests_exactly_on_it(e):
    # dropped from rest h px above the top: t_n = t1·(1 + 2e(1 - e^(n-1))/(1 - e)), at rest
    # before t_inf = t1·(1 + e)/(1 - e), lying on the top for good
    h = 300.0
    m = on_platform(50, 710 - 10 - h, 0, e=e)
    t1 = math.sqrt(2 * h / G)
    t_inf = t1 * (1 + e) / (1 - e)
    found = m.advance(int(t_inf * 60) + 2)
    impacts = found[found["type"] == EV_PAIR]
    assert len(impacts) == math.ceil(math.log(0.01 / h) / math.log(e * e)) - 1
    for n, t in enumerate(impacts["t"], start=1):
        assert abs(t - t1 * (1 + 2 * e * (1 - e ** (n - 1)) / (1 - e))) <= 1e-9
    assert names(found)[-1] == "rest" and found["t"][-1] < t_inf
    assert (found["a"][-1], found["b"][-1], found["code"][-1]) == (0, 1, SIDE_BOTTOM)
    assert m.positions()[0].tolist() == [50.0, 700.0] and m.velocities()[0].tolist() == [0.0, 0.0]
    assert len(m.advance(120)) == 0 and m.positions()[0].tolist() == [50.0, 700.0]


@pytest.mark.parametrize("v0, mu, rough", [(100.0, 0.5, 0), (60.0, 2.0, 0), (100.0, 0.5, 1)])
def test_a_block_slides_to_a_stop_on_a_platform_at_the_closed_form_time_and_distance(v0, mu, rough):
    # friction mu on the block (rough = 0) or on the platform (1): the contact takes the larger
    world = WorldSpec(4000, 1000, 60, gravity=(0.0, G))
    bodies = Bodies.boxes([[10, 490], [0, 500]], [[10, 10], [3000, 20]], [[v0, 0], [0, 0]],
                          static=[False, True])  # fmt: skip
    friction = np.zeros(2)
    friction[rough] = mu
    m = make("exact", world, with_(bodies, friction=friction))
    found = m.advance(int(v0 / (mu * G) * 60) + 30)
    assert names(found) == ["rest", "stop"] and found["t"][0] == 0.0
    assert abs(found["t"][1] - v0 / (mu * G)) <= 1e-9
    assert abs((m.positions()[0, 0] - 10) - v0 * v0 / (2 * mu * G)) <= 1e-9
    assert m.velocities()[0].tolist() == [0.0, 0.0] and m.positions()[0, 1] == 490.0


def test_a_block_slides_off_the_edge_and_lands_as_a_projectile_from_there():
    # on the top from the start at 20 px/s, it leaves when its box no longer overlaps the top
    # (x = 80), then falls 290 px to the floor: t = 30/20 + √(2·290/g), x = 80 + 20·√(2·290/g)
    m = on_platform(50, 700, 20)
    found = m.advance(180)
    assert names(found) == ["rest", "leave", "wall"]
    assert found["t"][1] == pytest.approx(1.5, abs=1e-12) and found["b"][1] == 1
    fall = math.sqrt(2 * 290 / G)
    assert abs(found["t"][2] - (1.5 + fall)) <= 1e-9 and found["code"][2] == SIDE_BOTTOM


def test_a_fast_circle_flies_clear_of_the_corner_and_a_slow_one_stops_the_run_by_name():
    # a circle of radius r leaves when its centre passes the edge; at speed v it clears the
    # corner if v² >= r·g (r = 5: 70 px/s), else it would slide round it
    fast = on_platform(50, 700, 100, kind=KIND_CIRCLE)
    found = fast.advance(120)
    assert names(found)[:3] == ["rest", "leave", "wall"]
    assert found["t"][1] == pytest.approx(0.25, abs=1e-12)
    assert abs(found["t"][2] - (0.25 + math.sqrt(2 * 290 / G))) <= 1e-9
    slow = on_platform(50, 700, 60, kind=KIND_CIRCLE)
    with pytest.raises(NotYetExact, match=r"objects 0 and 1 .* slide round it.* model: stepped"):
        slow.advance(60)


def test_a_box_crosses_the_seam_of_two_platforms_at_the_same_height_without_dropping():
    bodies = Bodies.boxes([[10, 490], [0, 500], [50, 500]], [[10, 10], [50, 20], [100, 20]],
                          [[40, 0], [0, 0], [0, 0]], static=[False, True, True])  # fmt: skip
    m = make("exact", WorldSpec(200, 1000, 60, gravity=(0.0, G)), bodies)
    found = m.advance(120)
    assert names(found) == ["rest", "leave", "rest"]
    assert found["t"][1] == found["t"][2] == pytest.approx(1.0, abs=1e-12)
    assert found["b"].tolist() == [1, 1, 2]
    assert m.positions()[0].tolist() == pytest.approx([10 + 40 * 2.0, 490.0], abs=1e-12)
    assert m.positions()[0, 1] == 490.0


def test_gravity_along_x_rests_a_box_on_a_static_box_s_side():
    world = WorldSpec(1000, 200, 60, gravity=(G, 0.0))
    bodies = Bodies.boxes([[400, 50], [700, 40]], [[10, 10], [20, 40]], [[0, 0], [0, 0]],
                          static=[False, True])  # fmt: skip
    m = make("exact", world, with_(bodies, restitution=np.array([0.5, 1.0])))
    found = m.advance(240)
    assert names(found)[-1] == "rest" and found["code"][-1] == SIDE_RIGHT
    assert m.positions()[0].tolist() == [690.0, 50.0]


def test_energy_never_rises_as_bodies_settle_on_platforms():
    world = WorldSpec(400, 600, 60, gravity=(0.0, G))
    # on a platform, one slides to a stop by friction and one off its edge, frictionless, onto the
    # floor; one bounces on the other platform until it rests there
    pos = [[60, 390], [120, 392], [250, 50], [50, 400], [200, 450]]
    size = [[10, 10], [8, 8], [12, 12], [100, 20], [150, 20]]
    vel = [[30, 0], [100, 0], [-40, -100], [0, 0], [0, 0]]
    bodies = Bodies.boxes(pos, size, vel, static=[False, False, False, True, True])
    bodies = with_(bodies, restitution=np.full(5, 0.6), friction=np.array([0.3, 0, 0.3, 0, 0]))
    m = make("exact", world, bodies)
    mass, gravity = bodies.mass[:3], np.array(world.gravity)

    def energy() -> float:
        p, v = m.positions()[:3], m.velocities()[:3]
        return float(np.sum(0.5 * mass * (v * v).sum(axis=1)) - np.sum(mass * (p @ gravity)))

    before, kinds = energy(), []
    for _ in range(240):
        kinds += names(m.advance(1))
        now = energy()
        assert now <= before + 1e-9 * abs(before)
        before = now
    assert {"rest", "leave", "stop"} <= set(kinds)


def test_a_box_on_a_static_circle_s_crown_stops_the_run_by_name():
    bodies = Bodies.boxes([[45, 690], [40, 700]], [[10, 10], [20, 20]], [[0, 0], [0, 0]],
                          static=[False, True])  # fmt: skip
    m = make("exact", WORLD, with_(bodies, kind=np.array([KIND_BOX, KIND_CIRCLE], np.int8)))
    with pytest.raises(NotYetExact, match="objects 0 and 1 .* tick 1 .* model: stepped") as info:
        m.advance(10)
    assert info.value.objects == (0, 1)
    with pytest.raises(NotYetExact):  # and stays stopped
        m.advance(1)


# --- stacks: bodies resting still are supports too ------------------------------------------


def column(n: int, gap: float, e: float = 0.0, top_down: bool = False) -> Bodies:
    """n boxes 10 px a side in a column over the floor of WORLD, `gap` px between each and the one
    below (the lowest `gap` over the floor), restitution e; ids from the bottom up (or top down)."""
    ys = [1000 - (k + 1) * (10 + gap) for k in range(n)]
    if top_down:
        ys = ys[::-1]
    bodies = Bodies.boxes([[50, y] for y in ys], 10, [[0, 0]] * n)
    return with_(bodies, restitution=np.full(n, e))


def test_a_column_of_ten_boxes_lands_into_a_stack_at_the_closed_form_times_and_stays():
    # at e = 0 each box rests where it lands; box k (from the bottom) falls (k + 1)·gap in all,
    # the ones below having stopped under it: it lands at √(2(k + 1)·gap/g)
    gap = 5.0
    m = make("exact", WORLD, column(10, gap))
    found = m.advance(60)
    rests = found[found["type"] == TYPE_NAMES.index("rest")]
    assert len(rests) == 10 and rests["a"].tolist() == list(range(10))
    assert rests["b"].tolist() == [-1, *range(9)]  # the floor, then each on the one below
    for k, t in enumerate(rests["t"]):
        assert abs(t - math.sqrt(2 * (k + 1) * gap / G)) <= 1e-9
    still = m.positions().copy()
    assert still[:, 1].tolist() == [1000 - 10 * (k + 1) for k in range(10)]
    assert len(m.advance(120)) == 0 and (m.positions() == still).all()
    assert (m.velocities() == 0).all()


@pytest.mark.parametrize("top_down", [False, True])
def test_a_stack_placed_still_rests_from_the_start_in_any_id_order(top_down):
    m = make("exact", WORLD, column(5, 0.0, top_down=top_down))
    found = m.advance(60)
    assert names(found) == ["rest"] * 4 and (found["t"] == 0.0).all()
    assert (m.velocities() == 0).all() and sorted(m.positions()[:, 1].tolist()) == [
        950.0, 960.0, 970.0, 980.0, 990.0]  # fmt: skip


def test_a_box_dropped_on_a_stack_bounces_off_it_as_off_the_floor_then_rests_on_it():
    # the stack is held by the floor: a box of e = 0.5 dropped h onto it bounces at the floor's
    # closed-form times, the stack unmoved, and comes to rest on its top
    h, e = 200.0, 0.5
    stack = column(3, 0.0)
    drop = Bodies.boxes([[50, 970 - 10 - h]], 10, [[0, 0]])
    bodies = Bodies.boxes(np.vstack([stack.pos, drop.pos]), 10, [[0, 0]] * 4)
    m = make("exact", WORLD, with_(bodies, restitution=np.array([1.0, 1.0, 1.0, e])))
    t1 = math.sqrt(2 * h / G)
    found = m.advance(int(t1 * (1 + e) / (1 - e) * 60) + 2)
    impacts = found[found["type"] == EV_PAIR]
    for n, t in enumerate(impacts["t"], start=1):
        assert abs(t - t1 * (1 + 2 * e * (1 - e ** (n - 1)) / (1 - e))) <= 1e-9
    assert (found["type"][-1], found["a"][-1], found["b"][-1]) == (
        TYPE_NAMES.index("rest"), 3, 2)
    assert m.positions()[:, 1].tolist() == [990.0, 980.0, 970.0, 960.0]
    assert (m.velocities() == 0).all()


@pytest.mark.parametrize("crowd", [0, 30])
def test_knocking_a_box_that_another_rests_on_stops_the_run_by_name(crowd):
    # (with a crowd resting further along the floor the model files its objects in a grid)
    pos = [[50, 990], [50, 980], [150, 990]] + [[600 + 40 * k, 990] for k in range(crowd)]
    vel = [[0, 0], [0, 0], [-100, 0]] + [[0, 0]] * crowd
    m = make("exact", WorldSpec(2000, 1000, 60, gravity=(0.0, G)), Bodies.boxes(pos, 10, vel))
    with pytest.raises(NotYetExact, match=r"object 0, which object 1 rests on, is knocked"):
        m.advance(120)
