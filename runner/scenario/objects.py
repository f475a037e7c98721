"""The `objects` and `generate` sections: each listed object and each generate block, checked.

`ObjectReader` reads every object field at its place (shape and its size key, position, velocity or
speed, colour, mass, static, fill, name) and returns `Listed` objects and `Block`s, from which
`runner.scenario.assemble` builds the arrays. What differs between models is one `ModelRules` value
instead of a flag threaded through each reader: under the paper model positions are whole pixels,
every velocity component of a moving object is a rate the model can take at the world's fps
(`engine.motion.paper_rate`) and generated velocities are drawn as whole numbers; under geometry
`exact` a polygon must be convex with some area (`polygon_problem`).

Masses lie in [MIN_MASS, MAX_MASS] and velocity components in [-MAX_SPEED, MAX_SPEED] (see the
"Numbers" paragraph of `runner.scenario.load`); polygon points lie within MAX_POINT_OFFSET px of the
object's position.

An object's name follows one rule wherever it is written (a list here, a table in
`runner.scenario.table`, the fast lane in `runner.scenario.fastlane`, a generate block's `name`):
`object_names`. Surrounding whitespace is not part of it, a name left empty is no name, and a name
holds at most MAX_OBJECT_NAME_CHARS characters of text; that no two objects share one is checked
once all are known (`runner.scenario.assemble.check_names`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import yaml

from collide2d.engine import motion
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, WorldSpec
from collide2d.runner.scenario import generate as gen
from collide2d.runner.scenario import parse as ys
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.nodes import Nodes, fmt

DEFAULT_COLOR = (255, 255, 255)
DEFAULT_MASS = 1.0  # mass units
MIN_MASS = 1e-15  # mass units, the lightest movable object
MAX_MASS = 1e15  # mass units, the heaviest movable object (`static: true` is heavier than any)
MAX_SEED = 2**64 - 1  # the largest generate seed
MAX_SPEED = 1e9  # px/s, largest velocity component (a larger one crosses any world in a tick)
MAX_POINT_OFFSET = 2**24  # px, largest |coordinate| of a polygon point relative to its position
MAX_OBJECT_NAME_CHARS = 100  # characters in an object's name (it labels the object in every output)
SHAPES = ("box", "circle", "polygon")
BLOCK_SHAPES = ("box", "circle")
_KIND_OF_SHAPE = {"box": KIND_BOX, "circle": KIND_CIRCLE, "polygon": KIND_POLYGON}
_SIZE_KEY = {"box": "size", "circle": "diameter", "polygon": "points"}

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


@dataclass(frozen=True)
class ModelRules:
    """What objects must satisfy under the scenario's model and geometry."""

    whole_positions: bool = False  # positions are whole pixels (paper)
    paper_rates: bool = False  # a moving object's velocity is a paper rate at the fps (paper)
    whole_velocities: bool = False  # generated velocities are whole numbers (paper)
    convex_polygons: bool = False  # polygons are convex with some area (geometry exact)
    origin: str | None = None  # "--model M" when the model came from the command line

    @classmethod
    def of(cls, model: str, geometry: str, origin: str | None = None) -> ModelRules:
        paper = model == "paper"
        return cls(
            whole_positions=paper,
            paper_rates=paper,
            whole_velocities=paper,
            convex_polygons=geometry == "exact",
            origin=origin,
        )


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


class NameRefused(ValueError):
    """A name the rule refuses, with the reason; `index` is its place among those given."""

    def __init__(self, index: int, reason: str):
        super().__init__(reason)
        self.index = index


def object_names(texts) -> list[str | None]:
    """The names that objects written with `texts` get (a list's `name`, a table's column, the
    fast lane's names), under the one rule: the text without surrounding whitespace, None when
    nothing is left; NameRefused at the first longer than MAX_OBJECT_NAME_CHARS characters or
    holding what is not text (a lone surrogate, which a .npy string may hold: no output could
    write it)."""
    names = [t.strip() or None for t in texts]
    if max(map(len, texts), default=0) > MAX_OBJECT_NAME_CHARS:  # else none can be too long
        for i, name in enumerate(names):
            if name is not None and len(name) > MAX_OBJECT_NAME_CHARS:
                raise NameRefused(
                    i, f"a name holds at most {MAX_OBJECT_NAME_CHARS} characters, not {len(name):,}"
                )
    try:
        "".join(filter(None, names)).encode("utf-8")
    except UnicodeEncodeError:
        for i, name in enumerate(names):
            try:
                (name or "").encode("utf-8")
            except UnicodeEncodeError as exc:
                code = ord(name[exc.start])
                raise NameRefused(i, f"a name is text, not a lone surrogate U+{code:04X}") from None
    return names


@dataclass
class Listed:
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
class Block:
    """One generate block, checked, before its objects are drawn."""

    spec: gen.BlockSpec
    kind: int
    mass: float
    static: bool
    color: tuple[int, int, int]
    color_node: object
    fill: bool
    name: str | None
    node: object


class ObjectReader(Nodes):
    """Reads the objects and generate blocks of one scenario, under its world and model rules."""

    def __init__(
        self, path: str, limits: Limits, world: WorldSpec, rules: ModelRules, fps_from=None
    ):
        super().__init__(path)
        self.limits = limits
        self.world = world
        self.rules = rules
        self.fps_from = fps_from  # "--fps F" when the fps came from the command line

    def velocity_pair(self, node, what: str, paper_rate: bool) -> tuple[float, float]:
        """[vx, vy] within MAX_SPEED; with `paper_rate`, each a rate the paper model can take."""
        items, values = self.pair(node, what)
        for n, v, axis in zip(items, values, "xy", strict=True):
            if abs(v) > MAX_SPEED:
                raise self.error(
                    n,
                    f"{what} {axis} must be at most {fmt(MAX_SPEED)} px/s in size, not {fmt(v)}",
                )
            if paper_rate:
                self.paper_rate(n, v)
        return float(values[0]), float(values[1])

    def paper_rate(self, node, v) -> None:
        try:
            motion.paper_rate(v, self.world.fps)
        except ValueError as exc:
            raise self.error(
                node, f"{self.prefix(self.rules.origin, self.fps_from)}{exc}"
            ) from None

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
        name = None
        if "name" in m:
            try:
                (name,) = object_names([self.string(m["name"][1], f"{what}.name")])
            except NameRefused as exc:
                raise self.error(m["name"][1], f"{what}.name: {exc}") from None
        return color, color_node, mass, static, fill, name

    def objects(self, top: dict) -> list[Listed]:
        if "objects" not in top:
            return []
        node = top["objects"][1]
        if isinstance(node, yaml.MappingNode):  # a table of objects (runner.scenario.table)
            return []
        items = self.seq(node, "objects")
        if len(items) > self.limits.max_objects:
            raise self.error(
                node,
                f"{len(items)} objects are past the limit of "
                f"{self.limits.max_objects} objects; raise it with --max-objects",
            )
        return self.each(self.listed, items)

    def listed(self, i: int, node) -> Listed:
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
            if self.rules.convex_polygons:
                problem = polygon_problem(p)
                if problem is not None:
                    raise self.error(
                        pnode,
                        f"{self.prefix(self.rules.origin)}{what}.points: under geometry "
                        f"'exact' a polygon must be convex with some area, but {problem}",
                    )
        else:
            size = self.size_of(shape, m[_SIZE_KEY[shape]][1], what)
        if "position" not in m:
            raise self.error(node, f"{what} is missing 'position' ([x, y] of its top-left corner)")
        pos_items, xy = self.pair(m["position"][1], f"{what}.position")
        if self.rules.whole_positions:
            for n, v, axis in zip(pos_items, xy, "xy", strict=True):
                if not float(v).is_integer():
                    raise self.error(
                        n,
                        f"{self.prefix(self.rules.origin)}{what}.position {axis} "
                        f"must be a whole number of pixels under the paper model, "
                        f"not {fmt(v)}",
                    )
        color, color_node, mass, static, fill, name = self.common(m, what)
        vel = (0.0, 0.0)
        if "velocity" in m:
            vnode = m["velocity"][1]
            vel = self.velocity_pair(
                vnode, f"{what}.velocity", self.rules.paper_rates and not static
            )
            if static and vel != (0.0, 0.0):
                raise self.error(
                    vnode,
                    f"{what} is static, so it cannot move: its velocity must be [0, 0] or absent",
                )
        pos = (float(xy[0]) + offset[0], float(xy[1]) + offset[1])
        return Listed(
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

    def blocks(self, top: dict, n_listed: int) -> list[Block]:
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
            out.append(self.block(k, m, node))
        return out

    def block(self, k: int, m: dict, node) -> Block:
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
                    raise self.error(snode, f"{what}.speed: min {fmt(a)} is more than max {fmt(b)}")
                speed_range = (float(a), float(b))
                moving = b > 0
            else:
                s = self.number(snode, f"{what}.speed", lo=0, hi=MAX_SPEED, unit=" px/s")
                if self.rules.paper_rates and not static:
                    self.paper_rate(snode, s)
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
                            f"{fmt(MAX_SPEED)} px/s in size",
                        )
                    if self.rules.whole_velocities and not float(c).is_integer():
                        raise self.error(
                            n,
                            f"{self.prefix(self.rules.origin)}{what}.velocity "
                            f"{key} {axis} must be a whole number under the paper "
                            f"model (it draws whole-number velocities), not "
                            f"{fmt(c)}",
                        )
                ends.append((float(v[0]), float(v[1])))
            for axis in (0, 1):
                if ends[0][axis] > ends[1][axis]:
                    raise self.error(
                        vnode,
                        f"{what}.velocity: min {'xy'[axis]} "
                        f"{fmt(ends[0][axis])} is more than max {'xy'[axis]} "
                        f"{fmt(ends[1][axis])}",
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
            whole=self.rules.whole_velocities,
        )
        return Block(spec, _KIND_OF_SHAPE[shape], mass, static, color, color_node, fill, name, node)

    def range_ends(self, r: dict, node, what: str):
        """(min, max) of a speed range {min, max}: numbers in [0, MAX_SPEED]."""
        for key in RANGE_KEYS:
            if key not in r:
                raise self.error(node, f"{what} is missing '{key}'")
        a = self.number(r["min"][1], f"{what} min", lo=0, hi=MAX_SPEED, unit=" px/s")
        b = self.number(r["max"][1], f"{what} max", lo=0, hi=MAX_SPEED, unit=" px/s")
        return a, b
