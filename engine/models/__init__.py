"""The models: rule sets that move objects and resolve collisions (SPEC section 3).

Every model is a class built as `Model(world, bodies, **options)` with the same surface:

    tick                  ticks run so far
    advance(ticks, log)   run that many ticks; returns the events (EVENT_DTYPE array, in order;
                          empty when `log` is False)
    positions()           (n, 2) float64 current top-left corners
    velocities()          (n, 2) float64 current velocities, px/s
    event_counts()        (wall events, pair events) so far, counted whether logged or not

`make` picks one by name. Each model's tick runs move -> walls -> pairs -> record. A model that
cannot carry a scene on (when built, or in `advance`) raises an `engine.errors.Runaway`.
"""

from __future__ import annotations

import importlib

from collide2d.engine.world import Bodies, WorldSpec

MODEL_NAMES = ("paper", "stepped", "exact")


class ModelUnavailable(Exception):
    """The named model is not built into this version."""


def make(name: str, world: WorldSpec, bodies: Bodies, **options):
    """Build the model `name` over `world` and `bodies`; options go to its constructor."""
    if name not in MODEL_NAMES:
        raise ValueError(f"unknown model {name!r}; expected one of {', '.join(MODEL_NAMES)}")
    try:
        module = importlib.import_module(f"collide2d.engine.models.{name}")
    except ModuleNotFoundError as exc:
        if exc.name == f"collide2d.engine.models.{name}":
            raise ModelUnavailable(f"model {name!r} is not available yet") from exc
        raise
    return module.Model(world, bodies, **options)
