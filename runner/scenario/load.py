"""Scenario files: YAML text in, a validated `Scenario` out (docs/scenario-format.md,
docs/limits.md), and its schema.

`load(path)` and `loads(text)` read a scenario, apply the command line's overrides (`model`, `fps`,
`ticks`, `max_events_per_tick`), check everything, and return a frozen `Scenario`: the world, the
model settings, every object as `engine.world.Bodies` arrays (listed objects first, then each
`generate` block, in id order), the palette, the output and golden settings. Any problem raises
`ScenarioError`, whose text is `FILE:LINE:COL: error: MESSAGE` (1-based) and points at the
offending YAML node. Nothing large is allocated before every count has been checked against
`Limits`.

Reading goes in two steps: `runner.scenario.parse` turns the text into a node tree within the bounds
of `Limits` (`runner.scenario.limits`: safe tags only, depth, aliases, size, value count); then the
tree is walked by hand, so every value is checked where it stands and every error carries its node's
place. `runner.scenario.nodes` reads single nodes (typed, located); this module reads the top level,
the world, the tick count and the overrides; `runner.scenario.physics` the model and the world's
gravity, restitution and friction; `runner.scenario.objects` reads the objects
and generate blocks, and once the world and the model are good checks them under the model's
`ModelRules` (`runner.scenario.rules`, the rules of every object however it is written);
`runner.scenario.sections` reads `output` and `golden`; `runner.scenario.assemble` builds the
`Bodies` and the palette and checks that no two objects overlap at the start.
Every name the format defines is importable from here (`__all__`), wherever it is defined.

Values follow YAML 1.1 as PyYAML reads it (`yes` is a boolean, `0x1f` an integer), with one
addition: an unquoted number in exponent form such as `1e3` or `1.5E-7`, a string to YAML 1.1, is
read as the number YAML 1.2 and JSON make of it. `<<` merge keys work as in YAML 1.1. A whole number
may be written as a float (`10.0`) wherever an integer is asked for, as in JSON Schema.

Time is counted in ticks: `world.fps` is a whole number of ticks per simulated second (1 to
`MAX_FPS`), `ticks` is given outright, or `duration` (seconds) becomes `duration * fps` ticks,
rounded to the nearest whole tick with halves up and computed exactly from the decimal as written
(`0.05` s at 10 fps is 1 tick); with neither, `DEFAULT_DURATION` seconds. A scenario without a
`name` takes its file's stem (text read by `loads` without a path is named `NAME_FOR_TEXT`).

Numbers: a number is at most `runner.scenario.parse.MAX_NUMBER_CHARS` characters as written, so it
is read at a cost linear in its text whatever its form (decimal, `0x`, `0b`, octal, sexagesimal
`1:30`, underscores); a whole number is at most MAX_INTEGER unless its field says less (a generate
seed at most MAX_SEED), and a number in a float field must be finite (`.inf`, `.nan` and `1e999` are
refused). `-0.0` is read as `0.0`. Masses lie in [MIN_MASS, MAX_MASS] and velocity components in
[-MAX_SPEED, MAX_SPEED], so every object starts with |m v| <= sqrt(2) * 1e24, m |v|^2 / 2 <= 1e33
and 1/m <= 1e15, and n objects with a kinetic energy E <= n * 1e33. Without gravity the models keep
kinetic energy (up to rounding) or lose it, never gain it, so no object ever moves faster than
sqrt(2 E / MIN_MASS) <= sqrt(n) * 1.5e24 px/s; gravity (runner.scenario.physics, MAX_GRAVITY) adds
at most the fall across the world to that. For any n a machine can hold, every velocity, energy,
momentum and inverse mass of a run stays many orders of magnitude inside float64's range (about
1.8e308). Denormal masses
such as `5e-324` are refused by the same bound; `static: true` is the way to an immovable object.

Every value in the file must be valid on its own. The overrides then replace values (`model`
replaces the file's whole `model` entry unless it names the same kind, whose settings are kept;
`fps` replaces `world.fps`, so a `duration` is counted again in ticks; `ticks` replaces `ticks` and
`duration`; `max_events_per_tick`, the exact model's cap, replaces the model option of that name
under any model, though only the exact model uses it), and everything that depends on them (paper
velocities and positions, the tick limit, frame numbers, room to move under the exact model) is
checked with the values in force; such an error starts with the override, e.g. `--fps 3: ...`.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import numpy as np
import yaml

from collide2d.engine.shapes import GEOMETRIES
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner.scenario import assemble, fastlane, parse
from collide2d.runner.scenario.assemble import PALETTE_SIZE
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.nodes import FAILED, MAX_INTEGER, Errors, fmt, is_number
from collide2d.runner.scenario.objects import (
    BLOCK_KEYS,
    BLOCK_SHAPES,
    DEFAULT_COLOR,
    MAX_POINT_OFFSET,
    MAX_SEED,
    OBJECT_KEYS,
    RANGE_KEYS,
    SHAPES,
    ModelRules,
    ObjectReader,
    polygon_problem,
)
from collide2d.runner.scenario.parse import ScenarioError
from collide2d.runner.scenario.physics import (
    DEFAULT_MAX_EVENTS_PER_TICK,
    MAX_EVENT_CAP,
    MAX_GRAVITY,
    MAX_ITERATIONS,
    MAX_SUBSTEPS,
    MODEL_BOUNDS,
    MODEL_KEYS,
    WORLD_PHYSICS,
    ModelReader,
)
from collide2d.runner.scenario.rules import (
    DEFAULT_FRICTION,
    DEFAULT_MASS,
    DEFAULT_RESTITUTION,
    MAX_FRICTION,
    MAX_MASS,
    MAX_OBJECT_NAME_CHARS,
    MAX_SPEED,
    MIN_MASS,
)
from collide2d.runner.scenario.sections import (
    EVERY_KEYS,
    FRAME_WORDS,
    GOLDEN_KEYS,
    OUTPUT_KEYS,
    Golden,
    Output,
    OutputReader,
)
from collide2d.runner.scenario.table import checked, table_of, with_table

__all__ = [
    "BLOCK_KEYS",
    "BLOCK_SHAPES",
    "DEFAULT_BACKGROUND",
    "DEFAULT_COLOR",
    "DEFAULT_DURATION",
    "DEFAULT_FPS",
    "DEFAULT_FRICTION",
    "DEFAULT_HEIGHT",
    "DEFAULT_MASS",
    "DEFAULT_MAX_EVENTS_PER_TICK",
    "DEFAULT_RESTITUTION",
    "DEFAULT_WIDTH",
    "EVERY_KEYS",
    "FORMAT_VERSION",
    "FRAME_WORDS",
    "GEOMETRIES",
    "GOLDEN_KEYS",
    "MAX_EVENT_CAP",
    "MAX_FPS",
    "MAX_FRICTION",
    "MAX_GRAVITY",
    "MAX_INTEGER",
    "MAX_ITERATIONS",
    "MAX_MASS",
    "MAX_NAME_LENGTH",
    "MAX_OBJECT_NAME_CHARS",
    "MAX_POINT_OFFSET",
    "MAX_SEED",
    "MAX_SPEED",
    "MAX_SUBSTEPS",
    "MIN_MASS",
    "MODEL_BOUNDS",
    "MODEL_KEYS",
    "NAME_FOR_TEXT",
    "NAME_PATTERN",
    "OBJECT_KEYS",
    "OUTPUT_KEYS",
    "OVERRIDE_KEYS",
    "PALETTE_SIZE",
    "RANGE_KEYS",
    "SHAPES",
    "TOP_KEYS",
    "WORLD_KEYS",
    "WORLD_PHYSICS",
    "Golden",
    "Limits",
    "Output",
    "Scenario",
    "ScenarioError",
    "load",
    "loads",
    "polygon_problem",
]

FORMAT_VERSION = 1
DEFAULT_WIDTH = 320  # px
DEFAULT_HEIGHT = 240  # px
DEFAULT_FPS = 10  # ticks per simulated second
MAX_FPS = 10_000  # ticks per simulated second
DEFAULT_DURATION = 10  # s, when neither `ticks` nor `duration` is given
DEFAULT_BACKGROUND = (0, 0, 0)
MAX_NAME_LENGTH = 100  # characters in a scenario name (it names a folder)
NAME_PATTERN = r"[a-z0-9_-][a-z0-9._-]*"  # scenario names; never "." or "..", never a path
NAME_FOR_TEXT = "scenario"  # the name of a scenario read from text without one

_NAME_RE = re.compile(NAME_PATTERN + r"\Z")

TOP_KEYS = (
    "version",
    "name",
    "description",
    "world",
    "model",
    "ticks",
    "duration",
    "objects",
    "generate",
    "output",
    "golden",
)
WORLD_KEYS = ("width", "height", "fps", "background", *WORLD_PHYSICS)
OVERRIDE_KEYS = ("model", "fps", "ticks", "max_events_per_tick")


@dataclass(frozen=True, eq=False)
class Scenario:
    path: str | None  # the file it came from (as given), None for text
    name: str  # [a-z0-9._-]+, not starting with ".", defaults to the file's stem
    description: str
    world: WorldSpec
    background: tuple[int, int, int]
    palette: np.ndarray  # (k, 3) uint8; row 0 the background, then each distinct object colour
    model: str  # "paper" | "stepped" | "exact"
    substeps: int  # >= 1
    geometry: str  # "box" | "exact"
    ticks: int
    bodies: Bodies  # all objects, listed first then generated, id order
    names: tuple[str | None, ...]  # per object
    lines: tuple[int, ...]  # per object, the 1-based YAML line it came from
    output: Output
    golden: Golden
    text_sha256: str  # of the file's bytes; with a table, of both (`table.with_table`)
    # the exact model's cap: --max-events-per-tick, else the model option, else the default
    max_events_per_tick: int = DEFAULT_MAX_EVENTS_PER_TICK
    # each generate block as drawn (runner.scenario.generate.BlockSpec), its objects the last of
    # `bodies`: what a sweep draws again for another seed (runner.sweep.reseed)
    generated: tuple = ()
    # the stepped model's settings for contacts and rest; None: the model's default
    iterations: int | None = None
    slop: float | None = None  # px
    rest_speed: float | None = None  # px/s
    sleep: bool | None = None
    sleep_after: float | None = None  # s
    # the exact model's rest under gravity (docs/models.md#exact-under-gravity); None: its default
    rest_height: float | None = None  # px


def load(
    path,
    *,
    overrides: dict | None = None,
    limits: Limits | None = None,
    defaults=None,
    edit=None,
) -> Scenario:
    """Read and check the scenario file at `path` (str or os.PathLike); ScenarioError if bad.

    `defaults`: model settings a project gives where the file gives none (`kind`, `substeps`,
    `geometry`, `max_events_per_tick`; runner.command.settings), below the file and the overrides.
    `edit(root) -> root`, when given, changes the composed YAML node tree before it is read (a
    sweep's dotted keys, `runner.sweep.matrix`); the result is checked like the file itself."""
    shown = os.fspath(path)
    limits = limits if limits is not None else Limits()
    text, digest = parse.read_file(path, limits)
    return _Reader(shown, shown, overrides, limits, defaults).scenario(text, digest, edit)


def loads(
    text: str, path: str = "<string>", *, overrides=None, limits=None, defaults=None
) -> Scenario:
    """Check scenario text; `path` only names it in errors (and gives the default name).

    Without a `name`, text read under the default path is named NAME_FOR_TEXT.
    """
    limits = limits if limits is not None else Limits()
    parse.check_length(len(text), path, limits)  # characters: never more than the UTF-8 bytes
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()
    return _Reader(path, None, overrides, limits, defaults).scenario(text, digest)


class _Reader(ModelReader):
    """One reading of one scenario: its path, limits and overrides, and the top-level sections."""

    def __init__(self, path: str, file_path: str | None, overrides, limits, defaults=None):
        super().__init__(path)
        self.defaults = dict(defaults or {})
        self.file_path = file_path
        self.limits = limits if limits is not None else Limits()
        self.overrides = {}
        for key, value in (overrides or {}).items():
            if key not in OVERRIDE_KEYS:
                raise ValueError(f"unknown override {key!r}; expected one of {OVERRIDE_KEYS}")
            if value is not None:
                self.overrides[key] = value
        self.root = None
        self.model_from = None  # "--model M" when the model came from the command line
        self.fps_from = None
        self.ticks_from = None

    # -- the document

    def scenario(self, text: str, digest: str, edit=None) -> Scenario:
        """The scenario of `text`, with `edit` (a sweep's dotted keys) applied to its node tree; a
        long object list one flow mapping per line takes the fast lane (runner.scenario.fastlane)
        when nothing is edited, and anything it declines or any error it meets is read again through
        the general path, which alone decides what a file means or why it is refused."""
        fast = fastlane.split(text) if edit is None else None
        if fast is not None and fastlane.bound(fast) <= self.limits.max_yaml_nodes:
            try:
                return self._scenario(fast.rest, digest, fast)
            except (fastlane.FallBack, ScenarioError):
                self.model_from = self.fps_from = self.ticks_from = None
        return self._scenario(text, digest, None, edit)

    def _scenario(self, text: str, digest: str, fast, edit=None) -> Scenario:
        """Read the whole document, collecting the errors of its parts (up to MAX_ERRORS, in
        line order: a check that depends on a refused part is not made, so that no error follows
        from another; the objects are read whatever the world and model, their rules wait for
        both); raise them all, or return the Scenario. `fast`: the fast lane's object rows
        (runner.scenario.fastlane), read in place of the empty list the text then holds."""
        root = parse.compose(text, self.path, self.limits)
        if edit is not None:
            root = edit(root)
        self.root = root
        self.errors = Errors()
        top = self.mapping(root, "the scenario", TOP_KEYS, go_on=True)
        self.attempt(self.version, top, root)
        name = self.attempt(self.name, top)
        description = self.attempt(self.description, top)
        world_background = self.attempt(self.world, top)
        settings = self.attempt(self.model, top)
        if world_background is not FAILED and settings is not FAILED:
            self.attempt(self.check_world_physics, self.physics, settings.kind)
        ticks = FAILED
        if world_background is not FAILED:
            world, background = world_background
            ticks = self.attempt(self.ticks, top, world.fps)
        objects = ObjectReader(self.path, self.limits)
        objects.errors = self.errors
        listed = self.attempt(objects.objects, top)
        table = self.attempt(self.table, top, fast)
        blocks = FAILED
        if listed is not FAILED and table is not FAILED:
            rows = len(listed) + (fast.n if fast else table.n if table else 0)
            blocks = self.attempt(objects.blocks, top, rows)
        # the rules of objects; those that need the world (bounds) or the model wait for them
        world_in = world if world_background is not FAILED else None
        rules = None
        if settings is not FAILED:
            model, geometry = settings.kind, settings.geometry
            rules = ModelRules.of(model, geometry, self.model_from)
        objects.check(listed, blocks, world_in, rules, self.fps_from)
        if table is not FAILED:
            table = self.attempt(self.checked, table, fast, world_in, rules)
        if ticks is not FAILED:
            outputs = OutputReader(self.path, self.limits, self.ticks_from)
            outputs.errors = self.errors
            output = self.attempt(outputs.output, top, ticks)
            golden = self.attempt(outputs.golden, top, ticks)
        found = self.errors.error()
        self.errors = None
        if found is not None:
            raise found
        bodies, names, lines, palette = assemble.bodies(
            self, listed, blocks, world, background, geometry, table
        )
        if table is not None and table.sha256 is not None:
            digest = with_table(digest, table.sha256)
        assemble.check_plugin(self, model, geometry, bodies, lines, top)  # engine.models.protocol
        if model == "exact":
            assemble.check_room(self, world, bodies, geometry, names, listed, lines, table)
        return Scenario(
            path=self.file_path,
            name=name,
            description=description,
            world=world,
            background=background,
            palette=palette,
            model=model,
            substeps=settings.substeps,
            geometry=geometry,
            ticks=ticks,
            bodies=bodies,
            names=names,
            lines=lines,
            output=output,
            golden=golden,
            text_sha256=digest,
            max_events_per_tick=settings.max_events_per_tick,
            generated=tuple(b.spec for b in blocks),
            **settings.stepped,
            **settings.exact,
        )

    def description(self, top: dict) -> str:
        if "description" in top:
            return self.string(top["description"][1], "description")
        return ""

    def version(self, top: dict, root) -> None:
        if "version" not in top:
            raise self.error(
                root, f"missing 'version: {FORMAT_VERSION}' (the scenario format version)"
            )
        node = top["version"][1]
        v = self.scalar(node, "version")
        if not is_number(v) or v != FORMAT_VERSION:
            raise self.error(
                node,
                f"version must be {FORMAT_VERSION} (the only format version "
                f"this collide2d reads), not {parse.describe(node)}",
            )

    def name(self, top: dict) -> str:
        rule = (
            f"lower-case letters, digits, '.', '_' and '-', not starting with '.', at most "
            f"{MAX_NAME_LENGTH} characters; it names the output folder"
        )
        if "name" in top:
            node = top["name"][1]
            v = self.string(node, "name")
            if not _NAME_RE.match(v) or len(v) > MAX_NAME_LENGTH:
                raise self.error(node, f"name {v!r} is not a valid scenario name ({rule})")
            return v
        if self.file_path is None and self.path == "<string>":
            return NAME_FOR_TEXT
        stem = Path(self.path).stem
        if not _NAME_RE.match(stem) or len(stem) > MAX_NAME_LENGTH:
            raise self.error(
                self.root,
                f"the file name {stem!r} cannot be the scenario's name; add a 'name:' ({rule})",
            )
        return stem

    def world(self, top: dict) -> tuple[WorldSpec, tuple[int, int, int]]:
        m = self.mapping(top["world"][1], "world", WORLD_KEYS) if "world" in top else {}
        side = {}
        for key, default in (("width", DEFAULT_WIDTH), ("height", DEFAULT_HEIGHT)):
            if key not in m:
                side[key] = default
                continue
            node = m[key][1]
            # no bound but the side's own, so that the message names the one that holds
            v = self.integer(node, f"world.{key}", lo=1, hi=math.inf, of=" of pixels", unit=" px")
            bound = min(self.limits.max_side, MAX_INTEGER)
            if v > bound:
                shown = str(v) if len(str(v)) <= 24 else node.value  # 1e308, not its 309 digits
                raise self.error(
                    node,
                    f"world.{key} {shown} is past the limit of {bound} px per side; raise it "
                    "with --max-side",
                )
            side[key] = v
        fps_node = m["fps"][1] if "fps" in m else None
        fps = DEFAULT_FPS
        if fps_node is not None:
            fps = self.integer(fps_node, "world.fps", lo=1, hi=MAX_FPS, of=" of ticks per second")
        if "fps" in self.overrides:
            v = self.overrides["fps"]
            origin = f"--fps {v}"
            if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= MAX_FPS:
                raise self.error(
                    fps_node,
                    f"{origin}: fps must be a whole number of ticks per second from 1 to {MAX_FPS}",
                )
            if v != fps:
                self.fps_from = origin
            fps = v
        background = DEFAULT_BACKGROUND
        if "background" in m:
            background = self.color(m["background"][1], "world.background")
        self.physics = p = self.world_physics(m)
        world = WorldSpec(side["width"], side["height"], fps, p.gravity, p.restitution, p.friction)
        return world, background

    def table(self, top, fast):
        """The `objects: {file}` table read (runner.scenario.table), or None; with `fast` (the
        lane's rows, taken by `checked`) None once the text's object list is the empty list the
        lane left, else the lane declines."""
        if fast is None:
            return table_of(self, top, self.file_path, self.limits)
        node = top["objects"][1] if "objects" in top else None
        empty = isinstance(node, yaml.SequenceNode) and not node.value
        if not empty or node.start_mark.line + 1 != fast.first_line:
            raise fastlane.FallBack
        return None

    def checked(self, table, fast, world, rules):
        """The fast lane's rows, or the table read by `table` (or None), every rule held that
        the world and the model (None when refused) allow to check."""
        if fast is not None and world is not None and rules is not None:
            return fastlane.table(fast, world, rules, self.limits.max_objects)
        if table is not None:
            table = checked(table, world, rules.paper_rates if rules else False)
        return table

    def ticks(self, top: dict, fps: int) -> int:
        """Ticks from `ticks`, `duration` (at the fps in force) or the default, then --ticks."""
        limit = self.limits.max_ticks
        raise_it = "raise it with --max-ticks"
        overridden = "ticks" in self.overrides
        if "ticks" in top and "duration" in top:
            raise self.error(top["duration"][0], "give either 'ticks' or 'duration', not both")
        ticks = 0
        if "ticks" in top:
            node = top["ticks"][1]
            ticks = self.integer(
                node,
                "ticks",
                lo=0,
                hi=None if overridden else limit,
                past=lambda shown: f"ticks {shown} is past the limit of {limit} ticks; {raise_it}",
            )
        else:
            node = top["duration"][1] if "duration" in top else None
            seconds = DEFAULT_DURATION
            if node is not None:
                seconds = self.number(node, "duration", lo=0, unit=" s")
            exact = Fraction(seconds) if isinstance(seconds, int) else Fraction(repr(seconds))
            ticks_exact = math.floor(exact * fps + Fraction(1, 2))
            said = f"duration {fmt(seconds)} s" if node is not None else "the default duration"
            if ticks_exact > limit and not overridden:
                raise self.error(
                    node,
                    f"{self.prefix(self.fps_from)}{said} at {fps} fps is {ticks_exact} ticks, "
                    f"past the limit of {limit} ticks; {raise_it}",
                )
            ticks = int(ticks_exact) if not overridden else 0
            self.ticks_from = self.fps_from
        if overridden:
            v = self.overrides["ticks"]
            self.ticks_from = f"--ticks {v}"
            where = top["ticks"][1] if "ticks" in top else None
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise self.error(where, f"{self.ticks_from}: ticks must be a whole number >= 0")
            if v > limit:
                raise self.error(
                    where,
                    f"{self.ticks_from}: ticks is past the limit of {limit} ticks; {raise_it}",
                )
            ticks = v
        return ticks
