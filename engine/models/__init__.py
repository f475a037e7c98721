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

The surface is the model protocol (`protocol`, docs/how-to/plugins.md): models of other packages,
registered under the entry point group `collide2d.models`, are named like the built-in ones
(`plugins`, `names_for`); `make` builds one wrapped in `protocol.Checked`, which holds it to the
protocol. A name is only ever looked up among the registered entry points, never imported as a
module path, and the entry points are read only when a name is not built in.

Each model is a package of its own, `paper/`, `stepped/` and `exact/`, holding what only that
model uses and re-exporting its `Model`; what the models share stays at the top of the engine.
`make` imports only the package of the model it builds, so a run loads no other model. This
module may import the engine's shared modules; it imports a model's package only in `make`, and
a model's package may import this module's constants (MAX_EVENTS_PER_TICK).
"""

from __future__ import annotations

import functools
import importlib
import itertools
import re

from collide2d.engine.world import KIND_NAMES, Bodies, WorldSpec

MODEL_NAMES = ("paper", "stepped", "exact")
# The exact model's default cap of wall and pair events in one tick (a runaway past it).
MAX_EVENTS_PER_TICK = 1_000_000
# The settings a scenario gives each model (docs/scenario-format.md#model): the paper model takes
# none; the stepped model's contacts and rest take iterations, slop, rest_speed, sleep and
# sleep_after (docs/scenario-format.md#gravity-restitution-and-friction); the exact model's rest
# under gravity takes rest_height (docs/models.md#exact-under-gravity).
SCENARIO_OPTIONS = {
    "paper": (),
    "stepped": (
        "substeps", "geometry", "iterations", "slop", "rest_speed", "sleep", "sleep_after",
    ),
    "exact": ("geometry", "max_events_per_tick", "rest_height"),
}  # fmt: skip


# The entry point group of model plugins, and the names a plugin may take (a scenario's word).
ENTRY_POINT_GROUP = "collide2d.models"
PLUGIN_NAME = re.compile(r"[a-z][a-z0-9_-]{0,63}\Z")
# The most words of a plugin's SHAPES or OPTIONS read (there are only a few it can mean).
MAX_DECLARED = 64


def make(name: str, world: WorldSpec, bodies: Bodies, **options):
    """Build the model `name` over `world` and `bodies`; options go to its constructor. A plugin
    comes wrapped in `protocol.Checked`."""
    if name not in MODEL_NAMES:
        if name not in plugins():
            raise ValueError(f"unknown model {name!r}; expected one of {', '.join(names())}")
        from collide2d.engine.models import protocol

        return protocol.Checked(name, lambda *a, **k: plugin_class(name)(*a, **k), world,
                                bodies, options)  # fmt: skip
    module = importlib.import_module(f"collide2d.engine.models.{name}")
    return module.Model(world, bodies, **options)


def scenario_options(name: str, **settings) -> dict:
    """Of a scenario's model settings (substeps, geometry, max_events_per_tick, ...), those that
    model `name` takes and the scenario sets (None: not set, the model's default holds)."""
    takes = SCENARIO_OPTIONS[name] if name in SCENARIO_OPTIONS else options_of(name)
    return {k: v for k, v in settings.items() if k in takes and v is not None}


@functools.lru_cache(maxsize=1)
def plugins() -> dict:
    """The registered model plugins: name -> its entry point (importlib.metadata), in name order.
    Names that are not PLUGIN_NAME, or that are a built-in model's, are left out; of two
    entry points of one name, the first found is kept. Nothing is imported but the metadata."""
    from importlib import metadata

    found = {}
    for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
        if PLUGIN_NAME.match(ep.name) and ep.name not in MODEL_NAMES:
            found.setdefault(ep.name, ep)
    return dict(sorted(found.items()))


def names() -> tuple[str, ...]:
    """Every model a scenario may name: the built-in ones, then the plugins."""
    return MODEL_NAMES + tuple(plugins())


def names_for(value) -> tuple[str, ...]:
    """The model names to choose `value` among: the built-in ones when it is one of them (the
    plugins are not looked up), else `names()`."""
    return MODEL_NAMES if value in MODEL_NAMES else names()


def plugin_class(name: str):
    """The class (or factory) of the registered plugin `name`, its module imported now;
    `protocol.ModelError` when it cannot be, whatever its import raised (`sys.exit` too; Ctrl-C's
    KeyboardInterrupt passes through)."""
    from collide2d.engine.models import guard
    from collide2d.engine.models.protocol import ModelError

    ep = plugins()[name]
    try:
        return ep.load()
    except KeyboardInterrupt:
        raise
    except BaseException as exc:
        raise ModelError(
            name, guard.did(exc, f"when its module was imported ({ep.value})")
        ) from exc


def declared(name: str, model, attribute: str, default, allowed) -> tuple[str, ...]:
    """Of what plugin class `model` (registered as `name`) says in `attribute` (SHAPES, OPTIONS),
    the words in `allowed`, in its order; `default` when it says nothing. What it holds is the
    plugin's: anything raised reading it is a `protocol.ModelError`."""
    from collide2d.engine.models import guard
    from collide2d.engine.models.protocol import ModelError

    try:
        said = getattr(model, attribute, default)
        words = [w for w in itertools.islice(iter(said), MAX_DECLARED) if type(w) is str]
    except KeyboardInterrupt:
        raise
    except BaseException as exc:
        raise ModelError(name, guard.did(exc, f"when its {attribute} was read")) from exc
    return tuple(w for w in words if w in allowed)


def options_of(name: str) -> tuple[str, ...]:
    """The scenario's model settings model `name` takes (a plugin's `OPTIONS`, within
    `protocol.PLUGIN_OPTIONS`)."""
    if name in SCENARIO_OPTIONS:
        return SCENARIO_OPTIONS[name]
    from collide2d.engine.models.protocol import PLUGIN_OPTIONS

    return declared(name, plugin_class(name), "OPTIONS", (), PLUGIN_OPTIONS)


def shapes_of(name: str) -> tuple[str, ...]:
    """The object shapes model `name` takes (a plugin's `SHAPES`; all for the built-in ones)."""
    if name in MODEL_NAMES:
        return KIND_NAMES
    return declared(name, plugin_class(name), "SHAPES", KIND_NAMES, KIND_NAMES)
