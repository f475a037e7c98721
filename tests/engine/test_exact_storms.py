"""Event storms in the exact model (docs/models.md#event-storms): bounces that die away at one
instant, a body pinched between a wall and another or three bodies collapsing into a cluster, that
floating point never ends, or bounces that shrink until each takes a rounding of the clock. Scenes
found among random small scenes under gravity, which ran to the event cap (a million events in one
tick, minutes interpreted), now stop within a few thousand events, naming the objects, the walls
and the tick; random small scenes under gravity all end within a bounded number of events; and
what meets many partners once at one instant, or an elastic world, is never taken for a storm."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import collide2d
from collide2d.engine.errors import NoRoom, NotYetExact, Runaway
from collide2d.engine.models import make
from collide2d.engine.models.exact.jam import STORM_EVENTS
from collide2d.engine.world import Bodies, WorldSpec


def scene(world, objects, ticks):
    return {"version": 1, "world": world, "model": "exact", "ticks": ticks, "objects": objects}


def box(position, size, velocity, e, mu, mass=1):
    return {
        "shape": "box",
        "position": position,
        "size": size,
        "velocity": velocity,
        "mass": mass,
        "restitution": e,
        "friction": mu,
    }


def circle(position, diameter, velocity, e, mu, mass=1, static=False):
    found = {
        "shape": "circle",
        "position": position,
        "diameter": diameter,
        "restitution": e,
        "friction": mu,
    }
    return found | ({"static": True} if static else {"velocity": velocity, "mass": mass})


def model_of(source):
    """The exact model of a scenario dict, and its ticks."""
    scenario = collide2d.load(source)
    return make("exact", scenario.world, scenario.bodies), scenario.ticks


# Storms found among random scenes of 5 to 8 objects, cut down to the objects of the storm (each
# ran to the cap of 1,000,000 events in one tick): what stops, in which tick, naming whom.
STORMS = {
    # a light box resting on the floor against the left wall, a falling ball landing and rolling
    # into it: both inelastic, the box bounces between the wall and the ball ever more slowly,
    # to a subnormal speed that rounds back to itself
    "pinched-on-the-floor": (
        scene(
            {"width": 240, "height": 160, "fps": 30, "gravity": 9.8},
            [
                box([0, 129], [31, 31], [14.30223522504103, 0], 0, 0, mass=0.1),
                circle([72, 104], 11, [-32.920428324810985, 218.5753158846435], 0, 0),
            ],
            150,
        ),
        40,
        (0, 1),
        "left",
    ),
    # two falling boxes, the second against the right wall, the first thrown into it
    "pinched-in-flight": (
        scene(
            {"width": 320, "height": 160, "fps": 30, "gravity": 980},
            [
                box([281, 79], [21, 28], [188.02687304945317, 251.98501349858407], 0, 1),
                box(
                    [308, 86.78358068776905],
                    [12, 28],
                    [25.820238753420256, 287.5792275743379],
                    0.04921617898990793,
                    1,
                ),
            ],
            150,
        ),
        1,
        (0, 1),
        "right",
    ),
    # two boxes thrown up against the ceiling, the one under the other pressing it there
    "pinched-on-the-ceiling": (
        scene(
            {"width": 160, "height": 240, "fps": 10, "gravity": [0, 500], "restitution": 1},
            [
                box(
                    [9, 17.98953146914137], [8, 21], [-35.21889708273227, -212.26408675380478], 0, 0
                ),
                box([0, 2.5581163124723902], [23, 14], [-24.146606299374994, 0], 0, 0),
            ],
            50,
        ),
        1,
        (0, 1),
        "top",
    ),
    # a light box resting on a floor of restitution 0, a heavy ball rolling it into a small
    # ball at the right wall
    "three-against-a-wall": (
        scene(
            {"width": 320, "height": 100, "fps": 10, "gravity": 980, "restitution": 0},
            [
                box([263.36355177497416, 68], [29, 32], [0, 0], 0.8714496291772394, 0, mass=0.1),
                circle(
                    [215.2669794869759, 67],
                    33,
                    [31.10699290549769, 0],
                    0.3121018873252279,
                    0,
                    mass=10,
                ),
                circle(
                    [314, 47], 6, [232.44542602483807, -293.58567922108904], 0.3270148183801277, 0
                ),
            ],
            50,
        ),
        12,
        (0, 1, 2),
        "right",
    ),
    # a ball and a light box squeezed together against a static ball, no wall at all
    "against-a-static-ball": (
        scene(
            {"width": 100, "height": 240, "fps": 10, "gravity": 9.8},
            [
                circle([64, 79], 29, None, 1, 0.5478052877137989, static=True),
                circle([26, 203], 37, [68.44270326571416, -138.94177462963825], 0, 1),
                box([77.77377613665884, 113], [15, 6], [-8.76931168419015, 0], 1, 0, mass=0.1),
            ],
            50,
        ),
        8,
        (0, 1, 2),
        None,
    ),
}


@pytest.mark.parametrize("name", STORMS)
def test_a_storm_found_in_a_random_scene_stops_within_thousands_of_events_naming_it(name):
    source, tick, objects, wall = STORMS[name]
    model, ticks = model_of(source)
    with pytest.raises(NotYetExact) as err:
        model.advance(ticks, log=False)
    said = str(err.value)
    assert err.value.objects == objects
    listed = ", ".join(map(str, objects[:-1])) + f" and {objects[-1]}"
    met = f" and the {wall} wall" if wall else ""
    assert said.startswith(f"objects {listed}{met} collide again and again in tick {tick} at t = ")
    assert "event storm (object " in said and f"more than {STORM_EVENTS} times" in said
    assert said.endswith("use model: stepped")
    # the whole run, up to the storm's instant included, took a few thousand events, not the cap
    assert sum(model.event_counts()) < 5 * STORM_EVENTS
    with pytest.raises(NotYetExact):  # and it stays stopped
        model.advance(1)


def test_a_ball_bouncing_on_with_no_rest_height_stops_once_its_bounces_take_no_time():
    # rest_height 0: no bounce is low enough to end in a rest, so the bounces of restitution 0.9
    # shrink until each moves the clock on by a rounding of it, a million of them in one tick
    world = WorldSpec(100, 400, 10, gravity=(0.0, 980.0))
    bodies = Bodies.boxes([[40, 100]], 10, [[0, 0]])
    bodies = Bodies(**{**bodies.__dict__, "restitution": np.array([0.9])})
    model = make("exact", world, bodies, rest_height=0.0)
    with pytest.raises(NotYetExact) as err:
        model.advance(300, log=False)
    assert str(err.value).startswith(
        "object 0 and the bottom wall collide again and again in tick 147 at t = 14.61"
    )
    assert err.value.objects == (0,) and sum(model.event_counts()) < 2 * STORM_EVENTS


def test_a_ball_pinched_under_a_heavy_box_stops_though_each_bounce_moves_the_clock_on():
    # a box 10^6 times heavier falls onto a ball, both onto the floor, under a strong gravity and
    # with rest_height 0: pinched with no gap, the ball bounces between the two with the clock
    # moving on by some 1e-12 s at each impact (the 1e-9 px contacts are decided to, over its
    # speed), a million times in the tick
    source = scene(
        {"width": 20, "height": 20, "fps": 1, "gravity": 1e6, "friction": 1000},
        [
            box([0, 9.442984795111954], [3, 2], [0, 0], 1, 0.380386171137187, mass=1e6),
            circle([0, 13], 3, [0, 0], 0.999, 0.9929287618154823, mass=3.8020252889838195),
        ],
        3,
    )
    scenario = collide2d.load(source)
    model = make("exact", scenario.world, scenario.bodies, rest_height=0.0)
    with pytest.raises(NotYetExact) as err:
        model.advance(3, log=False)
    assert str(err.value).startswith(
        "objects 0 and 1 and the bottom wall collide again and again in tick 1 at t = 0.00803"
    )
    assert sum(model.event_counts()) < 10 * STORM_EVENTS


def test_a_storm_of_a_body_held_from_wall_to_wall_is_named_as_having_no_room():
    # a box resting on the floor slides under a static ball whose box it overlaps: held between
    # the floor and the ball on y, it bounces between them at one instant
    source = scene(
        {"width": 100, "height": 160, "fps": 30, "gravity": 5000},
        [
            box([29, 134], [12, 26], [-38.757273182538796, 0], 0.658476707114129, 0),
            circle([0, 122.14094478881812], 12, None, 0, 0, static=True),
        ],
        150,
    )
    model, ticks = model_of(source)
    with pytest.raises(NoRoom) as err:
        model.advance(ticks, log=False)
    assert err.value.objects == (0,) and err.value.axis == "y"
    assert str(err.value).startswith("object 0 has no room to move on y: it collides with its ")
    assert str(err.value).endswith(
        f"(an event storm in tick 17: object 0 met the same partners more than {STORM_EVENTS} "
        "times at one instant)"
    )
    assert sum(model.event_counts()) < 5 * STORM_EVENTS


def test_a_storm_stops_a_run_naming_its_objects_by_name():
    source = copy.deepcopy(STORMS["pinched-on-the-floor"][0])
    source["objects"][0]["name"] = "crate"
    source["objects"][1]["name"] = "ball"
    with pytest.raises(collide2d.RunStopped) as err:
        collide2d.run(source, events=False)
    said = str(err.value)
    assert "the exact model stopped the run in tick" in said
    assert "objects 0 and 1 and the left wall collide again and again in tick 40 at t = " in said
    assert said.endswith("(object 0 is crate, object 1 is ball)")


def random_scene(seed: int) -> dict:
    """A small scene under gravity as a hostile user writes it: 5 to 8 boxes and balls of random
    sizes, some static, at random places (some on a wall, on whole pixels or not), with random
    velocities (some still), masses, restitutions and frictions in [0, 1], the walls' too."""
    rng = np.random.default_rng(seed)
    width, height = rng.choice([100, 160, 240, 320]), rng.choice([100, 160, 240])
    fps = int(rng.choice([10, 30, 60]))
    gravity = [[0, 980], [0, 500], [200, 980], [0, -980], [0, 9.8], [0, 5000]][rng.integers(6)]
    e_or_mu = lambda: float(rng.choice([0.0, 1.0, rng.random(), rng.random()]))  # noqa: E731
    objects, boxes = [], []
    for _ in range(2000):
        if len(objects) == 8 or (len(objects) >= 5 and rng.random() < 0.2):
            break
        w, h = (int(k) for k in rng.integers(2, 41, 2))
        shape = "box" if rng.random() < 0.5 else "circle"
        h = h if shape == "box" else w
        if w >= width or h >= height:
            continue
        x = float(rng.choice([rng.uniform(0, width - w), 0, width - w, rng.integers(width - w)]))
        y = float(rng.choice([rng.uniform(0, height - h), height - h, rng.integers(height - h)]))
        if any(
            x < bx + bw and bx < x + w and y < by + bh and by < y + h for bx, by, bw, bh in boxes
        ):
            continue
        boxes.append((x, y, w, h))
        size = {"size": [w, h]} if shape == "box" else {"diameter": w}
        found = {"shape": shape, "position": [x, y], **size}
        if rng.random() < 0.15:
            found["static"] = True
        else:
            speed = rng.uniform(-300, 300, 2).tolist()
            found["velocity"] = [[0, 0], speed, [speed[0] / 6, 0]][rng.integers(3)]
            found["mass"] = float(rng.choice([0.1, 1, 1, 1, 10, 1000]))
        objects.append(found | {"restitution": e_or_mu(), "friction": e_or_mu()})
    world = {
        "width": int(width),
        "height": int(height),
        "fps": fps,
        "gravity": gravity,
        "restitution": e_or_mu(),
        "friction": e_or_mu(),
    }
    return scene(world, objects, 3 * fps)


@pytest.mark.parametrize("first", range(0, 120, 30))
def test_every_small_scene_under_gravity_ends_within_a_bounded_number_of_events(first):
    """Each of 120 random scenes runs its 3 seconds, or stops with a message, within 10,000
    events: none runs on to the cap (some of them ran a million events in one tick)."""
    for seed in range(first, first + 30):
        source = random_scene(seed)
        try:
            model, ticks = model_of(source)
        except collide2d.ScenarioError:
            continue  # refused before it runs (no room to move)
        try:
            model.advance(ticks, log=False)
        except Runaway as err:
            assert isinstance(err, (NotYetExact, NoRoom)), (seed, str(err))
        assert sum(model.event_counts()) <= 10_000, seed


def test_a_body_many_others_land_on_at_one_instant_is_no_storm():
    # a slab resting on the floor, and 1,200 small boxes of restitution 0 dropped onto it from
    # one height: 1,200 events of the slab at one instant, each with another partner
    n = 1200
    world = WorldSpec(3 * n + 20, 120, 10, gravity=(0.0, 980.0))
    pos = [[10, 100]] + [[12 + 3 * k, 40] for k in range(n)]
    size = [[3 * n, 20]] + [[2, 2]] * n
    bodies = Bodies.boxes(pos, size, [[0, 0]] * (n + 1), mass=[1000.0] + [1.0] * n)
    bodies = Bodies(**{**bodies.__dict__, "restitution": np.zeros(n + 1)})
    model = make("exact", world, bodies)
    found = model.advance(10)
    assert n > STORM_EVENTS and np.sum(found["b"] == 0) == n and len(set(found["t"][:n])) == 1
    assert len(model.rests()) == n + 1  # all of them resting, on the slab and the floor


def test_an_elastic_world_is_never_stopped_as_a_storm():
    # Galperin's billiard with no gap: a light block touching the left wall and a block 10^6
    # times heavier touching it, moving in: 3,141 collisions at one instant, each with the same
    # two partners; elastic, they end, and the heavy block leaves
    world = WorldSpec(4000, 100, 1)
    bodies = Bodies.boxes([[0, 45], [10, 45]], 10, [[0, 0], [-10, 0]], mass=[1.0, 1e6])
    model = make("exact", world, bodies)
    found = model.advance(2)
    assert len(found) == 3141 > 3 * STORM_EVENTS and len(set(found["t"])) == 1
    assert 0 <= model.velocities()[0, 0] <= model.velocities()[1, 0]
