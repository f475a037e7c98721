"""The conformance kit of the model protocol: run it on your own model from your own tests.

    from collide2d.testing import check_model

    def test_my_model_meets_the_protocol():
        check_model(MyModel)          # a class, or the name it is registered under

`check_model` builds the model over a few small scenes (two boxes head on, a box bouncing in a
corner, a seeded gas of boxes; circles and polygons too when the model's `SHAPES` has them) and
checks, for each, what every model must do (`collide2d.engine.models.protocol`): answers of the
right shapes and types with no NaN, events in order and of real objects and ticks, the same bytes
from two runs and from any split of the ticks among `advance` calls, the event counts agreeing with
the events logged, the same motion with the log off, and every object kept inside the world or a
wall event for it in the tick it is outside. It raises AssertionError listing every problem found;
`problems` returns them instead.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

__all__ = ["SCENES", "check_model", "problems"]

# How far (px) an object's box may reach past a wall at a tick's end: rounding.
INSIDE_SLACK_PX = 1e-6


def _scene(name, size, fps, ticks, objects=(), generate=()) -> dict:
    return {
        "version": 1,
        "name": name,
        "world": {"width": size[0], "height": size[1], "fps": fps},
        "ticks": ticks,
        "objects": list(objects),
        **({"generate": list(generate)} if generate else {}),
    }


def _box(x, y, vx, vy, size=10, **more) -> dict:
    return {"shape": "box", "size": size, "position": [x, y], "velocity": [vx, vy], **more}


# The kit's scenes, by the shape they need: small enough to run in a second in pure Python.
SCENES: dict[str, list[dict]] = {
    "box": [
        _scene("head-on", (320, 240), 10, 60, [_box(100, 115, 10, 0), _box(210, 115, -10, 0)]),
        _scene("corner", (60, 40), 30, 90, [_box(5, 5, 40, 25)]),
        _scene(
            "gas",
            (120, 90),
            30,
            60,
            generate=[{"count": 12, "shape": "box", "size": 6, "speed": 30, "seed": 1}],
        ),
        _scene(
            "masses",
            (200, 60),
            20,
            80,
            [_box(20, 20, 30, 0, mass=1), _box(100, 20, -10, 0, mass=3), _box(170, 20, 0, 0)],
        ),
    ],
    "circle": [
        _scene(
            "circles",
            (100, 80),
            30,
            60,
            [
                {"shape": "circle", "diameter": 12, "position": [10, 30], "velocity": [30, 4]},
                {"shape": "circle", "diameter": 12, "position": [70, 34], "velocity": [-25, 0]},
            ],
        )
    ],
    "polygon": [
        _scene(
            "triangle",
            (100, 80),
            30,
            60,
            [
                {
                    "shape": "polygon",
                    "points": [[0, 0], [12, 0], [6, 10]],
                    "position": [20, 30],
                    "velocity": [30, 5],
                },
                _box(70, 30, -20, 0),
            ],
        )
    ],
}


def check_model(
    model: str | Callable[..., Any],
    *,
    scenes: Iterable[Mapping[str, Any]] | None = None,
    options: Mapping[str, Any] | None = None,
) -> None:
    """Run the conformance kit on `model`; AssertionError listing every problem found.

    Args:
        model: the model's class (any callable `model(world, bodies, **options)`), or the name
            a plugin is registered under (entry point group `collide2d.models`) or a built-in's.
        scenes: scenarios as dicts (what `collide2d.load` takes) instead of the kit's `SCENES`.
        options: keyword arguments for the model besides the world and the bodies.

    Raises:
        ValueError: `model` is a name no model is registered under (the message lists them).
    """
    found = problems(model, scenes=scenes, options=options)
    if found:
        raise AssertionError(
            f"{len(found)} problem(s) with the model protocol:\n" + "\n".join(found)
        )


def problems(
    model: str | Callable[..., Any],
    *,
    scenes: Iterable[Mapping[str, Any]] | None = None,
    options: Mapping[str, Any] | None = None,
) -> list[str]:
    """What `check_model` finds, as one text per problem ([] when the model conforms)."""
    from collide2d.api import load
    from collide2d.engine import models
    from collide2d.engine.models.protocol import ModelError

    if isinstance(model, str) and model not in models.names():
        raise ValueError(f"unknown model {model!r}; expected one of {', '.join(models.names())}")
    name, build = _builder(model, dict(options or {}))
    if scenes is None:
        try:
            takes = models.shapes_of(model) if isinstance(model, str) else _shapes(name, model)
        except ModelError as exc:  # its module or its SHAPES could not be read
            return [str(exc)]
        scenes = [s for shape in takes for s in SCENES.get(shape, ())]
    found: list[str] = []
    for scene in scenes:
        scenario = load(dict(scene), model="stepped")  # real-valued, the shapes as boxes
        where = f"{name} on scene {scenario.name!r}"
        try:
            found.extend(f"{where}: {p}" for p in _scene_problems(scenario, build))
        except Exception as exc:  # a ModelError, or the kit's own checks stopped short
            found.append(f"{where}: {type(exc).__name__}: {exc}")
    return found


def _shapes(name: str, model) -> tuple[str, ...]:
    from collide2d.engine.models import declared
    from collide2d.engine.world import KIND_NAMES

    return declared(name, model, "SHAPES", KIND_NAMES, KIND_NAMES)


def _builder(model, options: dict):
    """(the model's name, a function (world, bodies) -> the model, checked by protocol.Checked)."""
    from collide2d.engine import models
    from collide2d.engine.models.protocol import Checked

    if isinstance(model, str):
        return model, lambda world, bodies: Checked(
            model, lambda w, b, **k: models.make(model, w, b, **k), world, bodies, options
        )
    from collide2d.engine.models import guard

    name = guard.class_name(model) if isinstance(model, type) else guard.shown(model)
    return name, lambda world, bodies: Checked(name, model, world, bodies, options)


def _scene_problems(scenario, build) -> list[str]:
    import numpy as np

    world, bodies, ticks = scenario.world, scenario.bodies, scenario.ticks
    out = []
    # one tick at a time, the log on: order, shapes and NaN are checked by Checked
    one = build(world, bodies)
    chunks = []
    for _ in range(ticks):
        events = one.advance(1, True)
        chunks.append(events)
        out.extend(_outside(world, bodies, one.positions(), events, one.tick))
    events = np.concatenate(chunks) if chunks else np.zeros(0)
    counted = one.event_counts()
    logged = (int((events["type"] == 0).sum()), int((events["type"] == 1).sum()))
    if counted != logged:
        out.append(f"event_counts() says {counted} (wall, pair) but the events logged are {logged}")
    # all the ticks in one call, and again in uneven chunks: the same bytes
    whole = build(world, bodies)
    at_once = whole.advance(ticks, True)
    if at_once.tobytes() != events.tobytes():
        out.append("advance(ticks) logs other events than advance(1) repeated (chunking)")
    if whole.positions().tobytes() != one.positions().tobytes():
        out.append("advance(ticks) ends elsewhere than advance(1) repeated (chunking)")
    again = build(world, bodies)
    sizes = (3, 7, 1, 13)
    k = 0
    while again.tick < ticks:
        again.advance(min(sizes[k % len(sizes)], ticks - again.tick), True)
        k += 1
    if again.positions().tobytes() != one.positions().tobytes():
        out.append("uneven chunks of ticks end elsewhere than advance(1) repeated (chunking)")
    # a second run from the same scene: the same bytes (determinism)
    twin = build(world, bodies)
    if twin.advance(ticks, True).tobytes() != at_once.tobytes():
        out.append("two runs of one scene log different events (not deterministic)")
    if twin.velocities().tobytes() != whole.velocities().tobytes():
        out.append("two runs of one scene end with different velocities (not deterministic)")
    # the log off: the same motion, nothing logged, the same counts
    quiet = build(world, bodies)
    if len(quiet.advance(ticks, False)):
        out.append("advance(ticks, log=False) returned events")
    if quiet.positions().tobytes() != whole.positions().tobytes():
        out.append("the log off changes the motion")
    if quiet.event_counts() != counted:
        out.append("the log off changes event_counts()")
    if not np.array_equal(one.positions()[bodies.static], bodies.pos[bodies.static]):
        out.append("a static object moved")
    return out


def _outside(world, bodies, pos, events, tick: int) -> list[str]:
    """An object outside the world at the end of `tick` with no wall event for it then."""
    import numpy as np

    lo = pos < -INSIDE_SLACK_PX
    hi = pos + bodies.size > np.array([world.width, world.height]) + INSIDE_SLACK_PX
    out_ids = np.flatnonzero((lo | hi).any(axis=1))
    told = set(events["a"][events["type"] == 0].tolist()) if len(events) else set()
    left = [int(i) for i in out_ids if int(i) not in told]
    if not left:
        return []
    return [f"object {left[0]} is outside the world at tick {tick} with no wall event for it"]
