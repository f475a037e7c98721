"""The models: rule sets that move objects and resolve collisions (docs/models.md).

Every model is a class built as `Model(world, bodies, **options)` with the same surface:

    tick                  ticks run so far
    advance(ticks, log)   run that many ticks; returns the events (EVENT_DTYPE array, in order;
                          empty when `log` is False)
    positions()           (n, 2) float64 current top-left corners
    velocities()          (n, 2) float64 current velocities, px/s
    event_counts()        (wall events, pair events) so far, counted whether logged or not

`make` picks one by name. Each model's tick runs move -> walls -> pairs -> record. A model that
cannot carry a scene on (when built, or in `advance`) raises an `engine.errors.Runaway`.

Each model is a package of its own, `paper/`, `stepped/` and `exact/`, holding what only that
model uses and re-exporting its `Model`; what the models share stays at the top of the engine.
`make` imports only the package of the model it builds, so a run loads no other model. This
module may import the engine's shared modules; it imports a model's package only in `make`, and
a model's package may import this module's constants (MAX_EVENTS_PER_TICK).
"""

from __future__ import annotations

import importlib

from collide2d.engine.world import Bodies, WorldSpec

MODEL_NAMES = ("paper", "stepped", "exact")
# The exact model's default cap of wall and pair events in one tick (a runaway past it).
MAX_EVENTS_PER_TICK = 1_000_000
# The settings a scenario gives each model (docs/scenario-format.md#model): the paper model takes
# none.
SCENARIO_OPTIONS = {
    "paper": (),
    "stepped": ("substeps", "geometry", "iterations", "slop", "rest_speed", "sleep", "sleep_after"),
    "exact": ("geometry", "max_events_per_tick"),
}


def make(name: str, world: WorldSpec, bodies: Bodies, **options):
    """Build the model `name` over `world` and `bodies`; options go to its constructor."""
    if name not in MODEL_NAMES:
        raise ValueError(f"unknown model {name!r}; expected one of {', '.join(MODEL_NAMES)}")
    module = importlib.import_module(f"collide2d.engine.models.{name}")
    return module.Model(world, bodies, **options)


def scenario_options(name: str, **settings) -> dict:
    """Of a scenario's model settings (substeps, geometry, max_events_per_tick), those that
    model `name` takes."""
    return {k: v for k, v in settings.items() if k in SCENARIO_OPTIONS[name]}
