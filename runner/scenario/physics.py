"""The model a scenario names and the physics it asks of it: the `model` section, and the world's
gravity, restitution and friction (docs/scenario-format.md#model,
docs/scenario-format.md#gravity-restitution-and-friction).

`ModelReader` extends `runner.scenario.nodes.Nodes` for the scenario reader
(`runner.scenario.load`): `model` reads the `model` section with the command line's `--model`
and `--max-events-per-tick` and the project's defaults into a `ModelSettings` (kind, substeps,
geometry, the exact model's event cap, the stepped model's settings for contacts and rest:
`iterations`, `slop`, `rest_speed`, `sleep`, `sleep_after`, and the exact model's rest under
gravity: `rest_height` (docs/models.md#exact-under-gravity), each absent where the file gives none,
so that the model's own default holds); `world_physics` reads `world.gravity` (`[gx, gy]` px/s², or
one number g meaning `[0, g]`, y down), `world.restitution` and `world.friction` (the walls'), and
`check_world_physics` holds them against the model once both are known: the paper model takes
none of them (the paper has none), each refused at its line with a message naming `stepped`;
the stepped and exact models take them all. A setting given to a model that does not take it is
refused at its line. An object's restitution and friction follow the rules of objects
(`runner.scenario.rules`).

Bounds: a gravity component lies within MAX_GRAVITY px/s². With the world's side and the mass
bounded (runner.scenario.load, "Numbers"), a body falling across the whole world gains at most
m·|g|·(width + height) of kinetic energy and a speed of sqrt(2·|g|·(width + height)), both many
orders of magnitude inside float64 at every bound.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field

import yaml

from collide2d.engine.models import MAX_EVENTS_PER_TICK, names_for
from collide2d.engine.shapes import GEOMETRIES
from collide2d.runner.scenario.nodes import Nodes, _raise
from collide2d.runner.scenario.rules import MAX_FRICTION, MAX_SPEED, PAPER_REFUSES

MAX_SUBSTEPS = 10_000  # substeps per tick of the stepped model
MAX_ITERATIONS = 1_000  # velocity passes per step of the stepped model (peers use 4 to 10)
MAX_SLOP = 1e9  # px, the largest overlap the stepped model may be told to leave (a bound only)
MAX_SLEEP_AFTER = 1e9  # s, the longest a body must be slow before it sleeps (about 32 years)
MAX_REST_HEIGHT = 1e9  # px, the highest rise the exact model may be told to end a bounce below
MAX_GRAVITY = 1e12  # px/s², the largest gravity component
# The exact model's `max_events_per_tick`: the default, and the largest a scenario or
# --max-events-per-tick may ask for (counted exactly in the kernel's int64 and in float64).
DEFAULT_MAX_EVENTS_PER_TICK = MAX_EVENTS_PER_TICK
MAX_EVENT_CAP = 2**53
# The numeric model settings and their (lowest, highest), of a scenario's `model` and of a
# project's [tool.collide2d.model] alike (runner.command.settings): substeps, iterations and
# max_events_per_tick are whole numbers.
MODEL_BOUNDS = {
    "substeps": (1, MAX_SUBSTEPS),
    "max_events_per_tick": (1, MAX_EVENT_CAP),
    "iterations": (1, MAX_ITERATIONS),
    "slop": (0, MAX_SLOP),
    "rest_speed": (0, MAX_SPEED),
    "sleep_after": (0, MAX_SLEEP_AFTER),
    "rest_height": (0, MAX_REST_HEIGHT),
}
# The stepped model's settings for contacts and rest (SCENARIO_OPTIONS of engine.models), with
# their unit in messages; None for a true or false.
STEPPED_KEYS = {"iterations": "", "slop": " px", "rest_speed": " px/s", "sleep": None,
                "sleep_after": " s"}  # fmt: skip
# The exact model's settings besides its event cap (SCENARIO_OPTIONS of engine.models), with their
# unit in messages: `rest_height`, a bounce under gravity that would rise less comes to rest.
EXACT_KEYS = {"rest_height": " px"}
MODEL_KEYS = ("kind", "substeps", "geometry", "max_events_per_tick", *STEPPED_KEYS, *EXACT_KEYS)
# The world's physics keys and their defaults (the elastic, weightless world).
WORLD_PHYSICS = {"gravity": 0.0, "restitution": 1.0, "friction": 0.0}


@dataclass(frozen=True)
class ModelSettings:
    """The model a scenario runs and its settings (the geometry resolved: `box` or `exact`)."""

    kind: str
    substeps: int = 1
    geometry: str = "box"
    max_events_per_tick: int = DEFAULT_MAX_EVENTS_PER_TICK
    stepped: dict = field(default_factory=dict)  # the stepped settings the file gives
    exact: dict = field(default_factory=dict)  # the exact settings the file gives (EXACT_KEYS)


@dataclass(frozen=True)
class WorldPhysics:
    """The world's gravity (px/s², y down) and the walls' restitution and friction, with the
    node of each key the file gives (for `check_world_physics`)."""

    gravity: tuple[float, float] = (0.0, 0.0)
    restitution: float = 1.0
    friction: float = 0.0
    nodes: dict = field(default_factory=dict)


class ModelReader(Nodes):
    """Reads the `model` section and the world's physics; the scenario reader extends it and sets
    `overrides`, `defaults` and `model_from` (see runner.scenario.load)."""

    overrides: dict
    defaults: dict
    model_from: str | None = None

    def world_physics(self, m: dict) -> WorldPhysics:
        """Gravity, restitution and friction of the world mapping `m` ({key: (key, value node)})."""
        gravity, restitution, friction = (0.0, 0.0), 1.0, 0.0
        nodes = {key: m[key] for key in WORLD_PHYSICS if key in m}
        if "gravity" in m:
            node = m["gravity"][1]
            bound = {"lo": -MAX_GRAVITY, "hi": MAX_GRAVITY, "unit": " px/s²"}
            if isinstance(node, yaml.SequenceNode):
                items = self.seq(node, "world.gravity")
                if len(items) != 2:
                    raise self.error(
                        node,
                        f"world.gravity must be one number g (meaning [0, g]) or [gx, gy], not a "
                        f"list of {len(items)}",
                    )
                gx, gy = (
                    float(self.number(n, f"world.gravity {axis}", **bound)) + 0.0
                    for n, axis in zip(items, "xy", strict=True)
                )
                gravity = (gx, gy)
            else:
                gravity = (0.0, float(self.number(node, "world.gravity", **bound)) + 0.0)
        if "restitution" in m:
            restitution = float(self.number(m["restitution"][1], "world.restitution", lo=0, hi=1))
        if "friction" in m:
            friction = float(self.number(m["friction"][1], "world.friction", lo=0, hi=MAX_FRICTION))
        return WorldPhysics(gravity, restitution + 0.0, friction + 0.0, nodes)

    def check_world_physics(self, physics: WorldPhysics, kind: str) -> None:
        """The world's physics keys the model `kind` does not take, each refused at its value
        (all of them, when collecting errors): the paper model takes none."""
        if kind != "paper":
            return
        said = self.prefix(self.model_from)
        for key, (_, vnode) in physics.nodes.items():
            text = PAPER_REFUSES.format(key=key)
            self.attempt(_raise, self.error(vnode, f"{said}world.{key} {text}"))

    def model(self, top: dict) -> ModelSettings:
        """The ModelSettings of `model` and the overrides."""
        kind, substeps, geometry, cap = "paper", 1, None, DEFAULT_MAX_EVENTS_PER_TICK
        sub_node = cap_node = None
        stepped: dict = {}
        exact: dict = {}
        if "model" not in top:
            kind = self.defaults.get("kind", kind)
        if "model" in top:
            node = top["model"][1]
            if isinstance(node, yaml.MappingNode):
                m = self.mapping(node, "model", MODEL_KEYS)
                if "kind" not in m:
                    raise self.error(node, "model is missing 'kind' (paper | stepped | exact)")
                kind = self.choice(m["kind"][1], "model", names_for(m["kind"][1].value))
                if "substeps" in m:
                    sub_node = m["substeps"][1]
                    substeps = self._setting(m, "substeps", kind, "stepped")
                if "max_events_per_tick" in m:
                    cap_node = m["max_events_per_tick"][1]
                    cap = self._setting(m, "max_events_per_tick", kind, "exact")
                for key in STEPPED_KEYS:
                    if key in m:
                        stepped[key] = self._setting(m, key, kind, "stepped")
                for key in EXACT_KEYS:
                    if key in m:
                        exact[key] = self._setting(m, key, kind, "exact")
                if "geometry" in m:
                    geo_node = m["geometry"][1]
                    geometry = self.choice(geo_node, "geometry", GEOMETRIES)
                    if geometry == "exact" and kind == "paper":
                        raise self.error(
                            geo_node,
                            "geometry 'exact' is not available with the "
                            "paper model, where every shape collides as its box",
                        )
            else:
                kind = self.choice(node, "model", names_for(node.value))
        if "model" in self.overrides:
            v = self.overrides["model"]
            origin = f"--model {v}"
            if not isinstance(v, str) or v not in names_for(v):
                near = difflib.get_close_matches(str(v), names_for(v), n=1)
                hint = (
                    f"did you mean '{near[0]}'?" if near else "expected " + " | ".join(names_for(v))
                )
                raise self.error(None, f"{origin}: unknown model {v!r}; {hint}")
            if v != kind:
                self.model_from = origin
                kind, substeps, geometry, stepped, exact = v, 1, None, {}, {}
                cap = DEFAULT_MAX_EVENTS_PER_TICK
        if "max_events_per_tick" in self.overrides:  # any model: only the exact one uses it
            v = self.overrides["max_events_per_tick"]
            if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= MAX_EVENT_CAP:
                raise self.error(
                    None,
                    f"--max-events-per-tick {v}: must be a whole number from 1 to {MAX_EVENT_CAP}",
                )
            cap = v
        if self.model_from:  # the file's settings went with its model
            sub_node = cap_node = None
        substeps, geometry, cap = self.model_defaults(
            kind, sub_node, geometry, cap_node, substeps, cap
        )
        if geometry is None:
            geometry = "exact" if kind == "exact" else "box"
        return ModelSettings(kind, substeps, geometry, cap, stepped, exact)

    def _setting(self, m: dict, key: str, kind: str, model: str):
        """The value of the model setting `key` (of the `model` mapping `m`), which only `model`
        takes: refused at its line under another kind."""
        node = m[key][1]
        what = f"model.{key}"
        if key == "sleep":
            value = self.boolean(node, what)
        elif key in ("substeps", "iterations", "max_events_per_tick"):
            lo, hi = MODEL_BOUNDS[key]
            value = self.integer(node, what, lo=lo, hi=hi)
        else:
            lo, hi = MODEL_BOUNDS[key]
            unit = {**STEPPED_KEYS, **EXACT_KEYS}[key]
            value = float(self.number(node, what, lo=lo, hi=hi, unit=unit)) + 0.0
        if kind != model:
            raise self.error(node, f"{key} applies to the {model} model only, not to {kind}")
        return value

    def model_defaults(self, kind, sub_node, geometry, cap_node, substeps, cap):
        """The project's model defaults (runner.command.settings) where neither the file nor the
        command line set a value and the model takes it."""
        d = self.defaults
        if kind == "stepped" and sub_node is None and "substeps" in d:
            substeps = d["substeps"]
        if geometry is None and kind != "paper" and "geometry" in d:
            geometry = d["geometry"]
        if (
            kind == "exact"
            and cap_node is None
            and "max_events_per_tick" in d
            and "max_events_per_tick" not in self.overrides
        ):
            cap = d["max_events_per_tick"]
        return substeps, geometry, cap
