"""Scenario files: YAML text in, a validated `Scenario` out (SPEC sections 2 and 8), and its schema.

`load(path)` and `loads(text)` read a scenario, apply the command line's overrides (`model`, `fps`,
`ticks`, `max_events_per_tick`), check everything, and return a frozen `Scenario`: the world, the
model settings, every object as `engine.world.Bodies` arrays (listed objects first, then each
`generate` block, in id order), the palette, the output and golden settings. Any problem raises
`ScenarioError`, whose text is `FILE:LINE:COL: error: MESSAGE` (1-based) and points at the
offending YAML node. Nothing large is allocated before every count has been checked against
`Limits`.

Reading goes in two steps: `runner.yamlsafe` turns the text into a node tree within the bounds of
`Limits` (safe tags only, depth, aliases, size, value count); then the tree is walked by hand, so
every value is checked where it stands and every error carries its node's place.

Values follow YAML 1.1 as PyYAML reads it (`yes` is a boolean, `0x1f` an integer), with one
addition: an unquoted number in exponent form such as `1e3` or `1.5E-7`, a string to YAML 1.1, is
read as the number YAML 1.2 and JSON make of it. `<<` merge keys work as in YAML 1.1. A whole number
may be written as a float (`10.0`) wherever an integer is asked for, as in JSON Schema.

Time is counted in ticks: `world.fps` is a whole number of ticks per simulated second (1 to
`MAX_FPS`), `ticks` is given outright, or `duration` (seconds) becomes `duration * fps` ticks,
rounded to the nearest whole tick with halves up and computed exactly from the decimal as written
(`0.05` s at 10 fps is 1 tick); with neither, `DEFAULT_DURATION` seconds. A scenario without a
`name` takes its file's stem (text read by `loads` without a path is named `NAME_FOR_TEXT`).

Numbers: a number is at most `runner.yamlsafe.MAX_NUMBER_CHARS` characters as written, so it is
read at a cost linear in its text whatever its form (decimal, `0x`, `0b`, octal, sexagesimal `1:30`,
underscores); a whole number is at most MAX_INTEGER unless its field says less (a generate seed at
most MAX_SEED), and a number in a float field must be finite (`.inf`, `.nan` and `1e999` are
refused). `-0.0` is read as `0.0`. Masses lie in [MIN_MASS, MAX_MASS] and velocity components in
[-MAX_SPEED, MAX_SPEED], so every object starts with |m v| <= sqrt(2) * 1e24, m |v|^2 / 2 <= 1e33
and 1/m <= 1e15, and n objects with a kinetic energy E <= n * 1e33. The models keep kinetic energy
(up to rounding) or lose it, never gain it, so no object ever moves faster than
sqrt(2 E / MIN_MASS) <= sqrt(n) * 1.5e24 px/s: for any n a machine can hold, every velocity, energy,
momentum and inverse mass of a run stays many orders of magnitude inside float64's range (about
1.8e308). Denormal masses such as `5e-324` are refused by the same bound; `static: true` is the way
to an immovable object.

Every value in the file must be valid on its own. The overrides then replace values (`model`
replaces the file's whole `model` entry unless it names the same kind, whose settings are kept;
`fps` replaces `world.fps`, so a `duration` is counted again in ticks; `ticks` replaces `ticks` and
`duration`; `max_events_per_tick`, the exact model's cap, replaces the model option of that name
under any model, though only the exact model uses it), and everything that depends on them (paper
velocities and positions, the tick limit, frame numbers, room to move under the exact model) is
checked with the values in force; such an error starts with the override, e.g. `--fps 3: ...`.
"""

from __future__ import annotations

import difflib
import hashlib
import math
import os
import re
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import numpy as np
import yaml

from collide2d.engine import motion
from collide2d.engine.models import MODEL_NAMES
from collide2d.engine.models.exact import MAX_EVENTS_PER_TICK, no_room, no_room_message
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, Bodies, WorldSpec
from collide2d.runner import colors
from collide2d.runner import generate as gen
from collide2d.runner import yamlsafe as ys
from collide2d.runner.frames import FrameRule
from collide2d.runner.yamlsafe import ScenarioError

FORMAT_VERSION = 1
DEFAULT_WIDTH = 320  # px
DEFAULT_HEIGHT = 240  # px
DEFAULT_FPS = 10  # ticks per simulated second
MAX_FPS = 10_000  # ticks per simulated second
DEFAULT_DURATION = 10  # s, when neither `ticks` nor `duration` is given
DEFAULT_BACKGROUND = (0, 0, 0)
DEFAULT_COLOR = (255, 255, 255)
DEFAULT_MASS = 1.0  # mass units
MIN_MASS = 1e-15  # mass units, the lightest movable object (see "Numbers" above)
MAX_MASS = 1e15  # mass units, the heaviest movable object (`static: true` is heavier than any)
MAX_INTEGER = 2**63 - 1  # the largest whole number a field takes unless it has its own bound
MAX_SEED = 2**64 - 1  # the largest generate seed
MAX_SPEED = 1e9  # px/s, largest velocity component (a larger one crosses any world in a tick)
MAX_SUBSTEPS = 10_000  # substeps per tick of the stepped model
# The exact model's `max_events_per_tick`: the default, and the largest a scenario or
# --max-events-per-tick may ask for (counted exactly in the kernel's int64 and in float64).
DEFAULT_MAX_EVENTS_PER_TICK = MAX_EVENTS_PER_TICK
MAX_EVENT_CAP = 2**53
MAX_POINT_OFFSET = 2**24  # px, largest |coordinate| of a polygon point relative to its position
MAX_NAME_LENGTH = 100  # characters in a scenario name (it names a folder)
PALETTE_SIZE = 256  # palette rows: the background and up to 255 object colours
NAME_PATTERN = r"[a-z0-9_-][a-z0-9._-]*"  # scenario names; never "." or "..", never a path
NAME_FOR_TEXT = "scenario"  # the name of a scenario read from text without one
SHAPES = ("box", "circle", "polygon")
BLOCK_SHAPES = ("box", "circle")
GEOMETRIES = ("box", "exact")
FRAME_WORDS = ("all", "none", "last")

_NAME_RE = re.compile(NAME_PATTERN + r"\Z")
_KIND_OF_SHAPE = {"box": KIND_BOX, "circle": KIND_CIRCLE, "polygon": KIND_POLYGON}
_SIZE_KEY = {"box": "size", "circle": "diameter", "polygon": "points"}

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
WORLD_KEYS = ("width", "height", "fps", "background")
MODEL_KEYS = ("kind", "substeps", "geometry", "max_events_per_tick")
OBJECT_KEYS = (
    "shape",
    "size",
    "diameter",
    "points",
    "position",
    "velocity",
    "color",
    "mass",
    "static",
    "fill",
    "name",
)
BLOCK_KEYS = (
    "count",
    "shape",
    "size",
    "diameter",
    "speed",
    "velocity",
    "seed",
    "color",
    "mass",
    "fill",
    "static",
    "name",
)
RANGE_KEYS = ("min", "max")
EVERY_KEYS = ("every",)
OUTPUT_KEYS = ("frames", "gif", "events")
GOLDEN_KEYS = ("frames", "time_tolerance", "max_diff_pixels", "color_threshold")
OVERRIDE_KEYS = ("model", "fps", "ticks", "max_events_per_tick")


@dataclass(frozen=True)
class Limits:
    """Bounds on what a scenario may ask for; each is a command-line option."""

    max_objects: int = 1_000_000
    max_ticks: int = 10**9
    max_side: int = 16384  # px per world side
    max_alias_nodes: int = 10_000  # YAML nodes reached a second time or more through aliases
    max_output_bytes: int = 4 * 2**30  # bytes of frame files on disk (PNG and GIF), at most
    max_frame_bytes: int = 2**30  # bytes of one frame in memory: width x height x scale^2 x 3
    max_frames: int = 1_000_000  # frames one `frames` entry may ask for, and a run may write
    max_file_bytes: int = 64 * 2**20  # bytes of a scenario file (it is read whole)
    max_yaml_nodes: int = 2_000_000  # YAML values in a file: each costs memory when composed


@dataclass(frozen=True)
class Output:
    frames: FrameRule  # the frames (0..ticks) asked for
    frames_spec: (
        object  # what the file said, normalised: "all" | "none" | "last" | list | {"every": k}
    )
    gif: bool
    events: bool


@dataclass(frozen=True)
class Golden:
    frames: tuple[int, ...]  # default (0, ticks // 2, ticks), deduplicated and sorted
    time_tolerance: float = 0.0  # s
    max_diff_pixels: int = 0
    color_threshold: int = 0  # per-pixel largest channel difference still counted as equal (0..255)


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
    text_sha256: str  # of the file's bytes
    # the exact model's cap: --max-events-per-tick, else the model option, else the default
    max_events_per_tick: int = DEFAULT_MAX_EVENTS_PER_TICK


def load(path, *, overrides: dict | None = None, limits: Limits | None = None) -> Scenario:
    """Read and check the scenario file at `path` (str or os.PathLike); ScenarioError if bad."""
    shown = os.fspath(path)
    limits = limits if limits is not None else Limits()
    text, digest = ys.read_file(path, limits)
    return _Reader(shown, shown, overrides, limits).scenario(text, digest)


def loads(text: str, path: str = "<string>", *, overrides=None, limits=None) -> Scenario:
    """Check scenario text; `path` only names it in errors (and gives the default name).

    Without a `name`, text read under the default path is named NAME_FOR_TEXT.
    """
    limits = limits if limits is not None else Limits()
    ys.check_length(len(text), path, limits)  # characters: never more than the UTF-8 bytes
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()
    return _Reader(path, None, overrides, limits).scenario(text, digest)


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _fmt(v) -> str:
    """A number as a user would write it (1e+15 rather than 1000000000000000)."""
    if isinstance(v, float) and v.is_integer() and abs(v) < 1e15:
        return str(int(v))
    if isinstance(v, float) and abs(v) >= 1e15:
        return np.format_float_scientific(v, trim="-")
    return repr(v) if isinstance(v, float) else str(v)


# ----------------------------------------------------------------------------- polygons


def polygon_problem(points: np.ndarray) -> str | None:
    """Why the closed polygon `points` (k, 2) int is not convex, or None when it is.

    Consecutive repeated points and collinear points are allowed; zero area, a turn back along the
    same line, turns both ways and winding around more than once are not.
    """
    p = np.asarray(points, np.int64)
    keep = np.any(p != np.roll(p, 1, axis=0), axis=1)
    p = p[keep] if keep.any() else p[:1]
    d = p - p[0]
    if not np.any(d[:, 0] * np.roll(d[:, 1], -1) - np.roll(d[:, 0], -1) * d[:, 1]):
        return "it has zero area (its points lie on one line)"
    area2 = int(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
    if area2 == 0:
        return "it is not convex: it crosses itself"
    e = np.roll(p, -1, axis=0) - p
    f = np.roll(e, -1, axis=0)
    cross = e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0]
    dot = e[:, 0] * f[:, 0] + e[:, 1] * f[:, 1]
    back = np.nonzero((cross == 0) & (dot < 0))[0]
    if back.shape[0]:
        return "it is not convex: it turns back along its own edge"
    if np.any(cross > 0) and np.any(cross < 0):
        return "it is not convex: it turns both ways"
    turning = float(np.sum(np.arctan2(cross.astype(np.float64), dot.astype(np.float64))))
    if abs(turning) > 3.0 * math.pi:
        return "it is not convex: it winds around more than once"
    return None


# ----------------------------------------------------------------------------- the walk


@dataclass
class _Listed:
    """One listed object, checked, before the arrays are built."""

    kind: int
    pos: tuple[float, float]
    size: tuple[int, int]
    vel: tuple[float, float]
    mass: float
    static: bool
    color: tuple[int, int, int]
    color_node: object
    fill: bool
    verts: np.ndarray | None
    name: str | None
    node: object


@dataclass
class _Block:
    spec: gen.BlockSpec
    kind: int
    mass: float
    static: bool
    color: tuple[int, int, int]
    color_node: object
    fill: bool
    name: str | None
    node: object


class _Reader:
    """One reading of one scenario: its path, limits and overrides, and the checks themselves."""

    def __init__(self, path: str, file_path: str | None, overrides, limits):
        self.path = str(path)
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

    # -- errors and plumbing

    def error(self, node, message: str) -> ScenarioError:
        mark = node.start_mark if node is not None else None
        return ys.mark_error(self.path, mark, message)

    @staticmethod
    def prefix(*origins) -> str:
        given = [o for o in origins if o]
        return " ".join(given) + ": " if given else ""

    def mapping(self, node, where: str, keys: tuple[str, ...]) -> dict:
        """{key: (key node, value node)} of a mapping; unknown and repeated keys refused."""
        if not isinstance(node, yaml.MappingNode):
            raise self.error(
                node, f"{where} must be a mapping of keys to values, not {ys.describe(node)}"
            )
        out: dict[str, tuple] = {}
        merged = []
        for knode, vnode in node.value:
            if isinstance(knode, yaml.ScalarNode) and knode.tag == ys.CORE_TAG + "merge":
                merged.append(vnode)
                continue
            if not isinstance(knode, yaml.ScalarNode) or not isinstance(ys.value(knode), str):
                raise self.error(knode, f"keys in {where} must be names, not {ys.describe(knode)}")
            key = knode.value
            if key in out:
                first = out[key][0].start_mark.line + 1
                raise self.error(knode, f"duplicate key '{key}' in {where} (first on line {first})")
            if key not in keys:
                near = difflib.get_close_matches(key, keys, n=1)
                hint = (
                    f"did you mean '{near[0]}'?" if near else "expected one of " + ", ".join(keys)
                )
                raise self.error(knode, f"unknown key '{key}' in {where}; {hint}")
            out[key] = (knode, vnode)
        for vnode in merged:
            sources = vnode.value if isinstance(vnode, yaml.SequenceNode) else [vnode]
            for src in sources:
                for key, item in self.mapping(src, where, keys).items():
                    out.setdefault(key, item)
        return out

    def seq(self, node, what: str, min_len: int = 0) -> list:
        if not isinstance(node, yaml.SequenceNode):
            raise self.error(node, f"{what} must be a list, not {ys.describe(node)}")
        if len(node.value) < min_len:
            raise self.error(node, f"{what} needs at least {min_len} items, not {len(node.value)}")
        return node.value

    def scalar(self, node, what: str):
        if not isinstance(node, yaml.ScalarNode):
            raise self.error(node, f"{what} must be a single value, not {ys.describe(node)}")
        return ys.value(node)

    def string(self, node, what: str) -> str:
        v = self.scalar(node, what)
        if not isinstance(v, str):
            raise self.error(node, f"{what} must be text, not {ys.describe(node)} (quote it)")
        return v

    def boolean(self, node, what: str) -> bool:
        v = self.scalar(node, what)
        if not isinstance(v, bool):
            raise self.error(node, f"{what} must be true or false, not {ys.describe(node)}")
        return v

    def number(self, node, what: str, *, lo=None, hi=None, lo_open=False, unit=""):
        """A finite int or float (ints kept exact) in [lo, hi] (or (lo, hi] with lo_open)."""
        v = self.scalar(node, what)
        if not _is_number(v):
            raise self.error(node, f"{what} must be a number, not {ys.describe(node)}")
        if isinstance(v, float) and not math.isfinite(v):
            raise self.error(node, f"{what} must be a finite number, not {node.value}")
        if isinstance(v, int) and abs(v) > 1e300:
            raise self.error(node, f"{what} {node.value} is too large a number")
        if v == 0:
            v = v + 0  # -0.0 is read as 0.0
        if lo is not None and (v <= lo if lo_open else v < lo):
            bound = "more than" if lo_open else "at least"
            raise self.error(node, f"{what} must be {bound} {_fmt(lo)}{unit}, not {_fmt(v)}")
        if hi is not None and v > hi:
            raise self.error(node, f"{what} must be at most {_fmt(hi)}{unit}, not {_fmt(v)}")
        return v

    def integer(self, node, what: str, *, lo=None, hi=None, of="", unit="") -> int:
        """A whole number (a float with no fraction counts) in [lo, hi]; hi is MAX_INTEGER unless
        given, and a given lo is at least -MAX_INTEGER.

        `of` completes "a whole number" in messages (" of pixels"), `unit` follows the bounds.
        """
        v = self.scalar(node, what)
        if isinstance(v, float) and math.isfinite(v) and v.is_integer():
            v = int(v)
        if not _is_number(v) or not isinstance(v, int):
            raise self.error(node, f"{what} must be a whole number{of}, not {ys.describe(node)}")
        lo = -MAX_INTEGER if lo is None else lo
        hi = MAX_INTEGER if hi is None else hi
        shown = str(v) if len(str(v)) <= 24 else node.value  # 1e300 rather than its 301 digits
        if v < lo:
            raise self.error(node, f"{what} must be at least {lo}{unit}, not {shown}")
        if v > hi:
            raise self.error(node, f"{what} must be at most {hi}{unit}, not {shown}")
        return v

    def color(self, node, what: str) -> tuple[int, int, int]:
        if isinstance(node, yaml.SequenceNode):
            items = node.value
            if len(items) != 3:
                raise self.error(
                    node, f"{what} as a list needs 3 values [r, g, b], not {len(items)}"
                )
            r, g, b = (self.integer(n, f"{what} component", lo=0, hi=255) for n in items)
            return (r, g, b)
        v = self.scalar(node, what)
        if not isinstance(v, str):
            raise self.error(
                node, f"{what} must be a colour name, #rrggbb or [r, g, b], not {ys.describe(node)}"
            )
        try:
            return colors.parse_color_text(v)
        except ValueError as exc:
            raise self.error(node, f"{what}: {exc}") from None

    def pair(self, node, what: str) -> tuple[list, list]:
        """([x node, y node], [x, y]) of a two-number list."""
        items = self.seq(node, what)
        if len(items) != 2:
            raise self.error(node, f"{what} must be a list of 2 numbers [x, y], not {len(items)}")
        values = [self.number(n, f"{what} {axis}") for n, axis in zip(items, "xy", strict=True)]
        return items, values

    def choice(self, node, what: str, options: tuple[str, ...], origin=None) -> str:
        v = self.scalar(node, what)
        if not isinstance(v, str) or v not in options:
            shown = f"'{v}'" if isinstance(v, str) else ys.describe(node)
            near = difflib.get_close_matches(v, options, n=1) if isinstance(v, str) else []
            hint = f"did you mean '{near[0]}'?" if near else "expected " + " | ".join(options)
            raise self.error(node, f"{self.prefix(origin)}unknown {what} {shown}; {hint}")
        return v

    # -- the document

    def scenario(self, text: str, digest: str) -> Scenario:
        root = ys.compose(text, self.path, self.limits)
        self.root = root
        top = self.mapping(root, "the scenario", TOP_KEYS)
        self.version(top, root)
        name = self.name(top)
        description = ""
        if "description" in top:
            description = self.string(top["description"][1], "description")
        world, background = self.world(top)
        model, substeps, geometry, cap = self.model(top)
        ticks = self.ticks(top, world.fps)
        paper = model == "paper"
        listed = self.objects(top, world, paper, geometry)
        blocks = self.blocks(top, len(listed), world, paper)
        output = self.output(top, ticks)
        golden = self.golden(top, ticks)
        bodies, names, lines, palette = self.bodies(listed, blocks, world, background)
        if model == "exact":
            self.room(world, bodies, geometry, names, listed, lines)
        return Scenario(
            path=self.file_path,
            name=name,
            description=description,
            world=world,
            background=background,
            palette=palette,
            model=model,
            substeps=substeps,
            geometry=geometry,
            ticks=ticks,
            bodies=bodies,
            names=names,
            lines=lines,
            output=output,
            golden=golden,
            text_sha256=digest,
            max_events_per_tick=cap,
        )

    def version(self, top: dict, root) -> None:
        if "version" not in top:
            raise self.error(
                root, f"missing 'version: {FORMAT_VERSION}' (the scenario format version)"
            )
        node = top["version"][1]
        v = self.scalar(node, "version")
        if not _is_number(v) or v != FORMAT_VERSION:
            raise self.error(
                node,
                f"version must be {FORMAT_VERSION} (the only format version "
                f"this collide2d reads), not {ys.describe(node)}",
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
            v = self.integer(node, f"world.{key}", lo=1, of=" of pixels", unit=" px")
            if v > self.limits.max_side:
                raise self.error(
                    node,
                    f"world.{key} {v} is past the limit of "
                    f"{self.limits.max_side} px per side; raise it with "
                    "--max-side",
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
        return WorldSpec(side["width"], side["height"], fps), background

    def model(self, top: dict) -> tuple[str, int, str, int]:
        """(kind, substeps, geometry, max_events_per_tick) from `model` and the overrides."""
        kind, substeps, geometry, cap = "paper", 1, None, DEFAULT_MAX_EVENTS_PER_TICK
        sub_node = geo_node = None
        if "model" in top:
            node = top["model"][1]
            if isinstance(node, yaml.MappingNode):
                m = self.mapping(node, "model", MODEL_KEYS)
                if "kind" not in m:
                    raise self.error(node, "model is missing 'kind' (paper | stepped | exact)")
                kind = self.choice(m["kind"][1], "model", MODEL_NAMES)
                if "substeps" in m:
                    sub_node = m["substeps"][1]
                    substeps = self.integer(sub_node, "model.substeps", lo=1, hi=MAX_SUBSTEPS)
                    if kind != "stepped":
                        raise self.error(
                            sub_node, f"substeps applies to the stepped model only, not to {kind}"
                        )
                if "max_events_per_tick" in m:
                    cap_node = m["max_events_per_tick"][1]
                    cap = self.integer(
                        cap_node, "model.max_events_per_tick", lo=1, hi=MAX_EVENT_CAP
                    )
                    if kind != "exact":
                        raise self.error(
                            cap_node,
                            f"max_events_per_tick applies to the exact model only, not to {kind}",
                        )
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
                kind = self.choice(node, "model", MODEL_NAMES)
        if "model" in self.overrides:
            v = self.overrides["model"]
            origin = f"--model {v}"
            if not isinstance(v, str) or v not in MODEL_NAMES:
                near = difflib.get_close_matches(str(v), MODEL_NAMES, n=1)
                hint = (
                    f"did you mean '{near[0]}'?" if near else "expected " + " | ".join(MODEL_NAMES)
                )
                raise self.error(None, f"{origin}: unknown model {v!r}; {hint}")
            if v != kind:
                self.model_from = origin
                kind, substeps, geometry = v, 1, None
                cap = DEFAULT_MAX_EVENTS_PER_TICK
        if "max_events_per_tick" in self.overrides:  # any model: only the exact one uses it
            v = self.overrides["max_events_per_tick"]
            if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= MAX_EVENT_CAP:
                raise self.error(
                    None,
                    f"--max-events-per-tick {v}: must be a whole number from 1 to {MAX_EVENT_CAP}",
                )
            cap = v
        if geometry is None:
            geometry = "exact" if kind == "exact" else "box"
        return kind, substeps, geometry, cap

    def room(self, world, bodies, geometry, names, listed, lines) -> None:
        """Refuse, at the object, a moving object with no room on an axis it moves on (the exact
        model would collide it again and again with no time passing; engine.models.exact)."""
        found = no_room(world, bodies, geometry)
        if not found:
            return
        i = found[0].obj
        message = self.prefix(self.model_from) + no_room_message(found, bodies, names)
        if i < len(listed):
            raise self.error(listed[i].node, message)
        raise ys.ScenarioError(self.path, lines[i], 1, message)

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
            ticks = self.integer(node, "ticks", lo=0)
            if ticks > limit and not overridden:
                raise self.error(
                    node, f"ticks {ticks} is past the limit of {limit} ticks; {raise_it}"
                )
        else:
            node = top["duration"][1] if "duration" in top else None
            seconds = DEFAULT_DURATION
            if node is not None:
                seconds = self.number(node, "duration", lo=0, unit=" s")
            exact = Fraction(seconds) if isinstance(seconds, int) else Fraction(repr(seconds))
            ticks_exact = math.floor(exact * fps + Fraction(1, 2))
            said = f"duration {_fmt(seconds)} s" if node is not None else "the default duration"
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

    # -- objects

    def velocity_pair(self, node, what: str, fps: int, paper: bool) -> tuple[float, float]:
        items, values = self.pair(node, what)
        for n, v, axis in zip(items, values, "xy", strict=True):
            if abs(v) > MAX_SPEED:
                raise self.error(
                    n,
                    f"{what} {axis} must be at most {_fmt(MAX_SPEED)} px/s in size, not {_fmt(v)}",
                )
            if paper:
                self.paper_rate(n, v, fps)
        return float(values[0]), float(values[1])

    def paper_rate(self, node, v, fps: int) -> None:
        try:
            motion.paper_rate(v, fps)
        except ValueError as exc:
            raise self.error(node, f"{self.prefix(self.model_from, self.fps_from)}{exc}") from None

    def size_of(self, shape: str, node, what: str) -> tuple[int, int]:
        px = {"of": " of pixels", "unit": " px"}
        if shape == "circle":
            d = self.integer(node, f"{what}.diameter", lo=1, **px)
            return d, d
        if isinstance(node, yaml.SequenceNode):
            if len(node.value) != 2:
                raise self.error(
                    node,
                    f"{what}.size must be one number or [w, h], not a list of {len(node.value)}",
                )
            w = self.integer(node.value[0], f"{what}.size w", lo=1, **px)
            h = self.integer(node.value[1], f"{what}.size h", lo=1, **px)
            return w, h
        s = self.integer(node, f"{what}.size", lo=1, **px)
        return s, s

    def shape_of(self, m: dict, node, what: str, shapes: tuple[str, ...]) -> str:
        if "shape" not in m:
            raise self.error(node, f"{what} is missing 'shape' ({' | '.join(shapes)})")
        shape = self.choice(m["shape"][1], "shape", shapes)
        wanted = _SIZE_KEY[shape]
        for key in ("size", "diameter", "points"):
            if key in m and key != wanted:
                raise self.error(
                    m[key][0], f"'{key}' does not apply to a {shape}; a {shape} takes '{wanted}'"
                )
        if wanted not in m:
            raise self.error(node, f"{what} ({shape}) is missing '{wanted}'")
        return shape

    def common(self, m: dict, what: str):
        """color, mass, static, fill, name of an object or a block."""
        color_node = m["color"][1] if "color" in m else None
        color = DEFAULT_COLOR if color_node is None else self.color(color_node, f"{what}.color")
        static = self.boolean(m["static"][1], f"{what}.static") if "static" in m else False
        mass = DEFAULT_MASS
        if "mass" in m:
            mass = float(self.number(m["mass"][1], f"{what}.mass", lo=MIN_MASS, hi=MAX_MASS))
            if static:
                raise self.error(
                    m["mass"][0], f"{what} is static, so its mass is infinite; remove 'mass'"
                )
        fill = self.boolean(m["fill"][1], f"{what}.fill") if "fill" in m else False
        name = self.string(m["name"][1], f"{what}.name") if "name" in m else None
        return color, color_node, mass, static, fill, name

    def objects(self, top: dict, world: WorldSpec, paper: bool, geometry: str) -> list[_Listed]:
        if "objects" not in top:
            return []
        node = top["objects"][1]
        items = self.seq(node, "objects")
        if len(items) > self.limits.max_objects:
            raise self.error(
                node,
                f"{len(items)} objects are past the limit of "
                f"{self.limits.max_objects} objects; raise it with --max-objects",
            )
        return [self.listed(i, item, world, paper, geometry) for i, item in enumerate(items)]

    def listed(self, i: int, node, world: WorldSpec, paper: bool, geometry: str) -> _Listed:
        what = f"objects[{i}]"
        m = self.mapping(node, "object", OBJECT_KEYS)
        shape = self.shape_of(m, node, what, SHAPES)
        verts = None
        offset = (0, 0)
        if shape == "polygon":
            pnode = m["points"][1]
            items = self.seq(pnode, f"{what}.points", min_len=3)
            pts = []
            for k, item in enumerate(items):
                pair = self.seq(item, f"{what}.points[{k}]")
                if len(pair) != 2:
                    raise self.error(
                        item, f"{what}.points[{k}] must be [x, y], not a list of {len(pair)}"
                    )
                pts.append(
                    [
                        self.integer(
                            n,
                            f"{what}.points[{k}] {axis}",
                            lo=-MAX_POINT_OFFSET,
                            hi=MAX_POINT_OFFSET,
                            of=" of pixels",
                            unit=" px",
                        )
                        for n, axis in zip(pair, "xy", strict=True)
                    ]
                )
            p = np.array(pts, np.int64)
            lo = p.min(axis=0)
            verts = p - lo
            size = (int(verts[:, 0].max()) + 1, int(verts[:, 1].max()) + 1)
            offset = (int(lo[0]), int(lo[1]))
            if geometry == "exact":
                problem = polygon_problem(p)
                if problem is not None:
                    raise self.error(
                        pnode,
                        f"{self.prefix(self.model_from)}{what}.points: under geometry "
                        f"'exact' a polygon must be convex with some area, but {problem}",
                    )
        else:
            size = self.size_of(shape, m[_SIZE_KEY[shape]][1], what)
        if "position" not in m:
            raise self.error(node, f"{what} is missing 'position' ([x, y] of its top-left corner)")
        pos_items, xy = self.pair(m["position"][1], f"{what}.position")
        if paper:
            for n, v, axis in zip(pos_items, xy, "xy", strict=True):
                if not float(v).is_integer():
                    raise self.error(
                        n,
                        f"{self.prefix(self.model_from)}{what}.position {axis} "
                        f"must be a whole number of pixels under the paper model, "
                        f"not {_fmt(v)}",
                    )
        color, color_node, mass, static, fill, name = self.common(m, what)
        vel = (0.0, 0.0)
        if "velocity" in m:
            vnode = m["velocity"][1]
            vel = self.velocity_pair(vnode, f"{what}.velocity", world.fps, paper and not static)
            if static and vel != (0.0, 0.0):
                raise self.error(
                    vnode,
                    f"{what} is static, so it cannot move: its velocity must be [0, 0] or absent",
                )
        pos = (float(xy[0]) + offset[0], float(xy[1]) + offset[1])
        return _Listed(
            _KIND_OF_SHAPE[shape],
            pos,
            size,
            vel,
            mass,
            static,
            color,
            color_node,
            fill,
            verts,
            name,
            node,
        )

    def blocks(self, top: dict, n_listed: int, world: WorldSpec, paper: bool) -> list[_Block]:
        if "generate" not in top:
            return []
        items = self.seq(top["generate"][1], "generate")
        total = n_listed
        out = []
        for k, node in enumerate(items):
            what = f"generate[{k}]"
            m = self.mapping(node, "generate block", BLOCK_KEYS)
            if "count" not in m:
                raise self.error(node, f"{what} is missing 'count'")
            cnode = m["count"][1]
            count = self.integer(cnode, f"{what}.count", lo=0)
            total += count
            if total > self.limits.max_objects:
                raise self.error(
                    cnode,
                    f"{what}.count {count} makes {total} objects, past the "
                    f"limit of {self.limits.max_objects} objects; raise it with "
                    "--max-objects",
                )
            out.append(self.block(k, m, node, world, paper))
        return out

    def block(self, k: int, m: dict, node, world: WorldSpec, paper: bool) -> _Block:
        what = f"generate[{k}]"
        shape = self.shape_of(m, node, what, BLOCK_SHAPES)
        size = self.size_of(shape, m[_SIZE_KEY[shape]][1], what)
        count = self.integer(m["count"][1], f"{what}.count", lo=0)
        seed = self.integer(m["seed"][1], f"{what}.seed", lo=0, hi=MAX_SEED) if "seed" in m else 0
        color, color_node, mass, static, fill, name = self.common(m, what)
        if "speed" in m and "velocity" in m:
            raise self.error(
                m["velocity"][0], f"{what}: give either 'speed' or 'velocity', not both"
            )
        speed = speed_range = velocity_range = None
        moving = False
        if "speed" in m:
            snode = m["speed"][1]
            if isinstance(snode, yaml.MappingNode):
                r = self.mapping(snode, "speed", RANGE_KEYS)
                a, b = self.range_ends(r, snode, f"{what}.speed")
                if a > b:
                    raise self.error(
                        snode, f"{what}.speed: min {_fmt(a)} is more than max {_fmt(b)}"
                    )
                speed_range = (float(a), float(b))
                moving = b > 0
            else:
                s = self.number(snode, f"{what}.speed", lo=0, hi=MAX_SPEED, unit=" px/s")
                if paper and not static:
                    self.paper_rate(snode, s, world.fps)
                speed = float(s)
                moving = s > 0
        if "velocity" in m:
            vnode = m["velocity"][1]
            if not isinstance(vnode, yaml.MappingNode):
                raise self.error(
                    vnode,
                    f"{what}.velocity must be {{min: [vx, vy], max: [vx, vy]}}"
                    f", not {ys.describe(vnode)}",
                )
            r = self.mapping(vnode, "velocity", RANGE_KEYS)
            ends = []
            for key in RANGE_KEYS:
                if key not in r:
                    raise self.error(vnode, f"{what}.velocity is missing '{key}'")
                items, v = self.pair(r[key][1], f"{what}.velocity {key}")
                for n, c, axis in zip(items, v, "xy", strict=True):
                    if abs(c) > MAX_SPEED:
                        raise self.error(
                            n,
                            f"{what}.velocity {key} {axis} must be at most "
                            f"{_fmt(MAX_SPEED)} px/s in size",
                        )
                    if paper and not float(c).is_integer():
                        raise self.error(
                            n,
                            f"{self.prefix(self.model_from)}{what}.velocity "
                            f"{key} {axis} must be a whole number under the paper "
                            f"model (it draws whole-number velocities), not "
                            f"{_fmt(c)}",
                        )
                ends.append((float(v[0]), float(v[1])))
            for axis in (0, 1):
                if ends[0][axis] > ends[1][axis]:
                    raise self.error(
                        vnode,
                        f"{what}.velocity: min {'xy'[axis]} "
                        f"{_fmt(ends[0][axis])} is more than max {'xy'[axis]} "
                        f"{_fmt(ends[1][axis])}",
                    )
            velocity_range = (ends[0], ends[1])
            moving = any(c != 0 for end in ends for c in end)
        if static and moving:
            key = "speed" if "speed" in m else "velocity"
            raise self.error(
                m[key][1],
                f"{what} is static, so its objects cannot move: its {key} must be zero or absent",
            )
        if static:
            speed = speed_range = velocity_range = None
        spec = gen.BlockSpec(
            count=count,
            size=size,
            seed=seed,
            speed=speed,
            speed_range=speed_range,
            velocity_range=velocity_range,
            whole=paper,
        )
        return _Block(
            spec, _KIND_OF_SHAPE[shape], mass, static, color, color_node, fill, name, node
        )

    def range_ends(self, r: dict, node, what: str):
        """(min, max) of a speed range {min, max}: numbers in [0, MAX_SPEED]."""
        for key in RANGE_KEYS:
            if key not in r:
                raise self.error(node, f"{what} is missing '{key}'")
        a = self.number(r["min"][1], f"{what} min", lo=0, hi=MAX_SPEED, unit=" px/s")
        b = self.number(r["max"][1], f"{what} max", lo=0, hi=MAX_SPEED, unit=" px/s")
        return a, b

    # -- output and golden

    def frames(self, node, what: str, ticks: int) -> tuple[FrameRule, object]:
        """(the frame rule, normalised spec) of a `frames` entry; its count is checked against
        limits.max_frames by arithmetic, so no list sized by `ticks` is ever built."""
        origin = self.prefix(self.ticks_from)
        too_many = (
            f"{origin}{what} asks for {{n:,}} frames, past the limit of "
            f"{self.limits.max_frames:,} frames; raise it with --max-frames"
        )
        if isinstance(node, yaml.SequenceNode):
            given = []
            for item in node.value:
                f = self.integer(item, f"{what} item", lo=0)
                if f > ticks and self.ticks_from:
                    continue  # the run was shortened from the command line: past its end
                if f > ticks:
                    raise self.error(
                        item,
                        f"{origin}{what}: frame {f} is past the last frame, "
                        f"{ticks} (ticks: {ticks})",
                    )
                given.append(f)
            rule = FrameRule.of(given, ticks)
            if len(rule) > self.limits.max_frames:
                raise self.error(node, too_many.format(n=len(rule)))
            return rule, given
        if isinstance(node, yaml.MappingNode):
            m = self.mapping(node, what, EVERY_KEYS)
            if "every" not in m:
                raise self.error(node, f"{what} as a mapping must be {{every: k}}")
            k = self.integer(m["every"][1], f"{what}.every", lo=1, of=" of ticks")
            rule = FrameRule.every_k(k, ticks)
            if len(rule) > self.limits.max_frames:
                raise self.error(node, too_many.format(n=len(rule)))
            return rule, {"every": k}
        v = self.scalar(node, what)
        if v not in FRAME_WORDS or not isinstance(v, str):
            near = difflib.get_close_matches(v, FRAME_WORDS, n=1) if isinstance(v, str) else []
            hint = f"; did you mean '{near[0]}'?" if near else ""
            raise self.error(
                node,
                f"{what} must be all, none, last, a list of frame numbers or "
                f"{{every: k}}, not {ys.describe(node)}{hint}",
            )
        rule = {"all": FrameRule.all, "last": FrameRule.last, "none": FrameRule.none}[v](ticks)
        if len(rule) > self.limits.max_frames:
            raise self.error(node, too_many.format(n=len(rule)))
        return rule, v

    def output(self, top: dict, ticks: int) -> Output:
        m = self.mapping(top["output"][1], "output", OUTPUT_KEYS) if "output" in top else {}
        frames, spec = FrameRule.none(ticks), "none"
        if "frames" in m:
            frames, spec = self.frames(m["frames"][1], "output.frames", ticks)
        gif = self.boolean(m["gif"][1], "output.gif") if "gif" in m else True
        events = self.boolean(m["events"][1], "output.events") if "events" in m else True
        return Output(frames=frames, frames_spec=spec, gif=gif, events=events)

    def golden(self, top: dict, ticks: int) -> Golden:
        m = self.mapping(top["golden"][1], "golden", GOLDEN_KEYS) if "golden" in top else {}
        frames = tuple(sorted({0, ticks // 2, ticks}))
        if "frames" in m:
            rule, _ = self.frames(m["frames"][1], "golden.frames", ticks)
            frames = tuple(rule)  # within limits.max_frames: goldens store each one
        tol = 0.0
        if "time_tolerance" in m:
            tol = float(
                self.number(m["time_tolerance"][1], "golden.time_tolerance", lo=0, unit=" s")
            )
        pixels = 0
        if "max_diff_pixels" in m:
            pixels = self.integer(m["max_diff_pixels"][1], "golden.max_diff_pixels", lo=0)
        threshold = 0
        if "color_threshold" in m:
            threshold = self.integer(
                m["color_threshold"][1], "golden.color_threshold", lo=0, hi=255
            )
        return Golden(
            frames=frames, time_tolerance=tol, max_diff_pixels=pixels, color_threshold=threshold
        )

    # -- arrays

    def bodies(self, listed: list[_Listed], blocks: list[_Block], world: WorldSpec, background):
        n_listed = len(listed)
        pos = np.array([o.pos for o in listed], np.float64).reshape(-1, 2)
        size = np.array([o.size for o in listed], np.float64).reshape(-1, 2)
        self.check_placement(listed, pos, size, world)

        palette = [background]
        index: dict[tuple[int, int, int], int] = {}

        def color_index(rgb, node) -> int:
            if rgb not in index:
                if len(palette) >= PALETTE_SIZE:
                    raise self.error(
                        node,
                        f"too many colours: the palette holds {PALETTE_SIZE} "
                        f"(the background and {PALETTE_SIZE - 1} object "
                        "colours)",
                    )
                index[rgb] = len(palette)
                palette.append(rgb)
            return index[rgb]

        listed_colors = [color_index(o.color, o.color_node or o.node) for o in listed]
        block_colors = [color_index(b.color, b.color_node or b.node) for b in blocks]

        try:
            drawn = gen.generate(world.width, world.height, pos, size, [b.spec for b in blocks])
        except gen.PlacementError as exc:
            raise self.error(blocks[exc.block].node, f"generate[{exc.block}]: {exc}") from None

        counts = [b.spec.count for b in blocks]
        n = n_listed + sum(counts)
        rep = np.array(counts, np.int64)

        def per_object(listed_values, block_values, dtype):
            a = np.asarray(listed_values, dtype).reshape(n_listed)
            b = np.repeat(np.asarray(block_values, dtype).reshape(len(blocks)), rep)
            return np.concatenate([a, b])

        kind = per_object([o.kind for o in listed], [b.kind for b in blocks], np.int8)
        static = per_object([o.static for o in listed], [b.static for b in blocks], bool)
        mass = per_object([o.mass for o in listed], [b.mass for b in blocks], np.float64)
        mass[static] = np.inf
        color = per_object(listed_colors, block_colors, np.uint8)
        fill = per_object([o.fill for o in listed], [b.fill for b in blocks], bool)
        all_pos = np.concatenate([pos] + [d[0] for d in drawn]).reshape(n, 2)
        all_vel = np.concatenate(
            [np.array([o.vel for o in listed], np.float64).reshape(-1, 2)] + [d[1] for d in drawn]
        ).reshape(n, 2)
        block_size = [
            np.broadcast_to(np.asarray(b.spec.size, np.float64), (c, 2))
            for b, c in zip(blocks, counts, strict=True)
        ]
        all_size = np.concatenate([size] + block_size).reshape(n, 2)
        nverts = np.zeros(n, np.int64)
        nverts[:n_listed] = [0 if o.verts is None else o.verts.shape[0] for o in listed]
        vert_start = np.concatenate([[0], np.cumsum(nverts)]).astype(np.int64)
        polys = [o.verts for o in listed if o.verts is not None]
        verts = np.concatenate(polys).astype(np.int64) if polys else np.zeros((0, 2), np.int64)
        bodies = Bodies(
            kind=kind,
            pos=all_pos,
            size=all_size,
            vel=all_vel,
            mass=mass,
            static=static,
            color=color,
            fill=fill,
            vert_start=vert_start,
            verts=verts,
        )

        names: list = [o.name for o in listed]
        lines: list = [o.node.start_mark.line + 1 for o in listed]
        for b, c in zip(blocks, counts, strict=True):
            names.extend([f"{b.name}-{j}" for j in range(c)] if b.name is not None else [None] * c)
            lines.extend([b.node.start_mark.line + 1] * c)
        return bodies, tuple(names), tuple(lines), np.array(palette, np.uint8).reshape(-1, 3)

    def check_placement(self, listed: list[_Listed], pos, size, world: WorldSpec) -> None:
        """Every listed box inside the world, no two overlapping (touching is fine)."""
        if not listed:
            return
        end = pos + size
        outside = np.any((pos < 0) | (end > np.array([world.width, world.height])), axis=1)
        if outside.any():
            i = int(np.argmax(outside))
            raise self.error(
                listed[i].node,
                f"objects[{i}] lies outside the world: its box "
                f"{_box_text(pos[i], size[i])} must fit in [0, {world.width}) x "
                f"[0, {world.height})",
            )
        found = gen.first_overlap(pos, size)
        if found is not None:
            a, b = found
            la = listed[a].node.start_mark.line + 1
            lb = listed[b].node.start_mark.line + 1
            raise self.error(
                listed[b].node,
                f"objects[{b}] (line {lb}) overlaps objects[{a}] "
                f"(line {la}) at the start: boxes {_box_text(pos[b], size[b])} and "
                f"{_box_text(pos[a], size[a])}",
            )


def _box_text(p, s) -> str:
    """The half-open box [x, x+w) x [y, y+h) as text."""
    x0, x1 = _fmt(float(p[0])), _fmt(float(p[0] + s[0]))
    y0, y1 = _fmt(float(p[1])), _fmt(float(p[1] + s[1]))
    return f"[{x0}, {x1}) x [{y0}, {y1})"
