"""The `objects` and `generate` sections: each listed object and generate block, read and checked.

`ObjectReader` reads every object field at its place (shape and its size key, position, velocity or
speed, colour, mass, static, fill, name, restitution, friction) whatever the world and the model,
and returns `Listed` objects and `Block`s, from which `runner.scenario.assemble` builds the arrays;
each remembers the node of every value a rule may refuse. Once the world and the model are known,
`check` and `check_blocks` put those values in columns and ask `runner.scenario.rules`, where every
rule of objects is written once for lists, blocks, tables and the fast lane alike, and report each
object's first fault at its node. What differs between models is one `ModelRules` value: under the
paper model positions are whole pixels, every velocity component of a moving object is a rate the
model can take at the world's fps (`engine.motion.paper_rate`), generated velocities are drawn as
whole numbers and restitution and friction are refused; the exact model takes only their defaults.
A polygon must be convex under every model, and have some area under geometry `exact`
(`polygon_problem`); its points lie within MAX_POINT_OFFSET px of the object's position. An object
is named in messages by its `name` beside its place (`objects[3] (ball)`), its name following the
one rule for names wherever it is written (`runner.scenario.rules.object_names`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import yaml

from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, WorldSpec
from collide2d.runner.scenario import generate, parse, rules
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.nodes import FAILED, Nodes, _raise, fmt, is_number
from collide2d.runner.scenario.rules import DEFAULT_MASS, NameRefused, object_names

DEFAULT_COLOR = (255, 255, 255)
MAX_SEED = 2**64 - 1  # the largest generate seed
MAX_POINT_OFFSET = 2**24  # px, largest |coordinate| of a polygon point relative to its position
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
    "restitution",
    "friction",
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
    "restitution",
    "friction",
)
RANGE_KEYS = ("min", "max")


@dataclass(frozen=True)
class ModelRules:
    """What objects must satisfy under the scenario's model and geometry."""

    # positions are whole pixels and a moving object's velocity is a paper rate at the fps (paper)
    paper_rates: bool = False
    whole_velocities: bool = False  # generated velocities are whole numbers (paper)
    polygon_area: bool = False  # polygons have some area (geometry exact)
    origin: str | None = None  # "--model M" when the model came from the command line

    @classmethod
    def of(cls, model: str, geometry: str, origin: str | None = None) -> ModelRules:
        paper = model == "paper"
        return cls(
            paper_rates=paper,
            whole_velocities=paper,
            polygon_area=geometry == "exact",
            origin=origin,
        )


_NO_MODEL = ModelRules()  # the model was refused: its rules wait


def polygon_problem(points: np.ndarray, area: bool = True) -> str | None:
    """Why the closed polygon `points` (k, 2) int is not convex, or None when it is.

    Consecutive repeated points and collinear points are allowed; zero area (unless `area` is
    False: points on one line, drawn as a line), a turn back along the same line, turns both ways
    and winding around more than once are not.
    """
    p = np.asarray(points, np.int64)
    keep = np.any(p != np.roll(p, 1, axis=0), axis=1)
    p = p[keep] if keep.any() else p[:1]
    d = p - p[0]
    if not np.any(d[:, 0] * np.roll(d[:, 1], -1) - np.roll(d[:, 0], -1) * d[:, 1]):
        return "it has zero area (its points lie on one line)" if area else None
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


@dataclass
class Listed:
    """One listed object, read; its rules are checked by column (`ObjectReader.check`)."""

    index: int  # its place in the list
    kind: int
    pos: tuple[float, float]  # the top-left corner of its box
    size: tuple[float, float]
    vel: tuple[float, float]
    mass: float
    static: bool
    color: tuple[int, int, int]
    color_node: object
    fill: bool
    verts: np.ndarray | None
    name: str | None
    node: object
    written: tuple[float, float]  # the position as written (a polygon's box starts elsewhere)
    at: dict  # {(field, axis): (node, what)} of each value a rule may refuse (rules.Fault)
    contact: tuple[float, float] = (math.nan, math.nan)  # restitution, friction (NaN: not given)

    @property
    def line(self) -> int:
        return self.node.start_mark.line + 1


@dataclass
class Block:
    """One generate block, read; its rules are checked by column (`ObjectReader.check_blocks`)."""

    spec: generate.BlockSpec
    kind: int
    mass: float
    static: bool
    color: tuple[int, int, int]
    color_node: object
    fill: bool
    name: str | None
    node: object
    at: dict  # {(field, axis): (node, what)}, as Listed.at
    index: int = 0
    contact: tuple[float, float] = (math.nan, math.nan)  # restitution, friction (NaN: not given)

    @property
    def line(self) -> int:
        return self.node.start_mark.line + 1

    @property
    def ends(self):
        """(min, max) of its range of speeds or velocities, or None."""
        return self.spec.speed_range or self.spec.velocity_range


def _columns(items, pos, vel) -> rules.Columns:
    """The Columns of listed objects or blocks (`pos`, `vel`: (n, 2) arrays of their values)."""
    n = len(items)
    return rules.Columns(
        size=np.array(
            [o.spec.size if isinstance(o, Block) else o.size for o in items], np.float64
        ).reshape(n, 2),
        pos=np.asarray(pos, np.float64).reshape(n, 2),
        vel=np.asarray(vel, np.float64).reshape(n, 2),
        mass=np.array([o.mass if ("mass", 0) in o.at else np.nan for o in items], np.float64),
        static=np.array([o.static for o in items], bool).reshape(n),
        restitution=np.array([o.contact[0] for o in items], np.float64).reshape(n),
        friction=np.array([o.contact[1] for o in items], np.float64).reshape(n),
    )


class ObjectReader(Nodes):
    """Reads the objects and generate blocks of one scenario (what each value is: keys, shapes,
    types), and checks their rules once the world and the model are known (`check`,
    `check_blocks`)."""

    def __init__(self, path: str, limits: Limits):
        super().__init__(path)
        self.limits = limits

    def pixels(self, node, what: str) -> float:
        """A number of pixels as written; that it is whole and at least 1 is a rule."""
        v = self.scalar(node, what)
        if not is_number(v) or (isinstance(v, float) and not math.isfinite(v)):
            raise self.error(
                node, f"{what} must be a whole number of pixels, not {parse.describe(node)}"
            )
        return float(v) + 0.0  # a number is at most MAX_NUMBER_CHARS long, so within float range

    def size_of(self, shape: str, node, what: str, at: dict) -> tuple[float, float]:
        if shape == "circle":
            at[("size", 0)] = at[("size", 1)] = (node, f"{what}.diameter")
            d = self.pixels(node, f"{what}.diameter")
            return d, d
        if isinstance(node, yaml.SequenceNode):
            if len(node.value) != 2:
                raise self.error(
                    node,
                    f"{what}.size must be one number or [w, h], not a list of {len(node.value)}",
                )
            at[("size", 0)] = (node.value[0], f"{what}.size w")
            at[("size", 1)] = (node.value[1], f"{what}.size h")
            return self.pixels(node.value[0], f"{what}.size w"), self.pixels(
                node.value[1], f"{what}.size h"
            )
        at[("size", 0)] = at[("size", 1)] = (node, f"{what}.size")
        s = self.pixels(node, f"{what}.size")
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

    def contact(self, m: dict, what: str, at: dict) -> tuple[float, float]:
        """(restitution, friction) of an object or a block as written, NaN where not given: their
        bounds and what the model takes of them are rules (runner.scenario.rules)."""
        out = []
        for key in ("restitution", "friction"):
            v = math.nan
            if key in m:
                v = float(self.number(m[key][1], f"{what}.{key}")) + 0.0
                at[(key, 0)] = (m[key][1], f"{what}.{key}")
            out.append(v)
        return out[0], out[1]

    def common(self, m: dict, what: str, at: dict):
        """color, mass, static, fill, name of an object or a block."""
        color_node = m["color"][1] if "color" in m else None
        color = DEFAULT_COLOR if color_node is None else self.color(color_node, f"{what}.color")
        static = self.boolean(m["static"][1], f"{what}.static") if "static" in m else False
        mass = DEFAULT_MASS
        if "mass" in m:
            mass = float(self.number(m["mass"][1], f"{what}.mass"))
            at[("mass", 0)] = (m["mass"][1], f"{what}.mass")
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
        at: dict = {}
        m = self.mapping(node, "object", OBJECT_KEYS)
        what = f"objects[{i}]" + _named(m)
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
            size = (float(verts[:, 0].max()) + 1, float(verts[:, 1].max()) + 1)
            offset = (int(lo[0]), int(lo[1]))
            at[("size", 0)] = at[("size", 1)] = (pnode, f"{what}.points")
        else:
            size = self.size_of(shape, m[_SIZE_KEY[shape]][1], what, at)
        if "position" not in m:
            raise self.error(node, f"{what} is missing 'position' ([x, y] of its top-left corner)")
        pos_items, xy = self.pair(m["position"][1], f"{what}.position")
        for a, (n, axis) in enumerate(zip(pos_items, "xy", strict=True)):
            at[("position", a)] = (n, f"{what}.position {axis}")
        color, color_node, mass, static, fill, name = self.common(m, what, at)
        vel = (0.0, 0.0)
        if "velocity" in m:
            items, values = self.pair(m["velocity"][1], f"{what}.velocity")
            for a, (n, axis) in enumerate(zip(items, "xy", strict=True)):
                at[("velocity", a)] = (n, f"{what}.velocity {axis}")
            vel = (float(values[0]), float(values[1]))
        pos = (float(xy[0]) + offset[0], float(xy[1]) + offset[1])
        written = (float(xy[0]), float(xy[1]))
        kind = _KIND_OF_SHAPE[shape]
        return Listed(
            i, kind, pos, size, vel, mass, static, color, color_node, fill, verts, name, node,
            written, at, self.contact(m, what, at),
        )  # fmt: skip

    # -- the rules, once the world and the model are known

    def check(self, listed, blocks, world: WorldSpec | None, model, fps_from=None) -> None:
        """Every rule of the listed objects and the blocks (each FAILED when refused): those of
        the rules (None when refused) wait for them."""
        if listed is not FAILED:
            self.check_listed(listed, world, model, fps_from)
        if blocks is not FAILED:
            self.check_blocks(blocks, world, model, fps_from)

    def check_listed(self, listed: list[Listed], world: WorldSpec | None, model, fps_from=None):
        """Every rule of the listed objects (runner.scenario.rules), each object's first fault at
        its value's node; under geometry exact a polygon is convex with some area. The rules
        that need the world (None when refused) or the `model` (a ModelRules, None when
        refused) wait for them."""
        model = model or _NO_MODEL
        refused = set()
        for row, o in enumerate(listed):
            problem = None
            if o.verts is not None:
                problem = polygon_problem(o.verts, model.polygon_area)
            if problem is not None:
                refused.add(row)
                node, what = o.at[("size", 0)]
                said = f"{what}: a polygon must be convex, but {problem}"
                if model.polygon_area:
                    said = (
                        f"{self.prefix(model.origin)}{what}: under geometry 'exact' a polygon "
                        f"must be convex with some area, but {problem}"
                    )
                self.attempt(_raise, self.error(node, said))
        cols = _columns(listed, [o.written for o in listed], [o.vel for o in listed])
        cols.corner = np.array([o.pos for o in listed], np.float64).reshape(-1, 2)
        fps, bounds = (world.fps, (world.width, world.height)) if world else (None, None)
        found = rules.faults(cols, model.paper_rates, fps, bounds)
        for f in rules.first_per_row(found):
            if f.row not in refused:
                self.attempt(_raise, self.fault(listed, f, model, fps_from, "objects"))

    def fault(self, items, f: rules.Fault, model: ModelRules, fps_from, kind: str):
        return fault_error(self, items, f, kind, model.origin, fps_from)

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
        at: dict = {}
        shape = self.shape_of(m, node, what, BLOCK_SHAPES)
        size = self.size_of(shape, m[_SIZE_KEY[shape]][1], what, at)
        count = self.integer(m["count"][1], f"{what}.count", lo=0)
        seed = self.integer(m["seed"][1], f"{what}.seed", lo=0, hi=MAX_SEED) if "seed" in m else 0
        color, color_node, mass, static, fill, name = self.common(m, what, at)
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
                a, b = self.range_ends(r, snode, f"{what}.speed", at)
                if a > b:
                    raise self.error(snode, f"{what}.speed: min {fmt(a)} is more than max {fmt(b)}")
                speed_range = (float(a), float(b))
                moving = b > 0
            else:
                s = self.number(snode, f"{what}.speed", lo=0, unit=" px/s")
                at[("velocity", 0)] = at[("velocity", 1)] = (snode, f"{what}.speed")
                speed = float(s)
                moving = s > 0
        if "velocity" in m:
            velocity_range = self.velocity_range(m["velocity"][1], what, at)
            moving = any(c != 0 for end in velocity_range for c in end)
        if static and moving:
            key = "speed" if "speed" in m else "velocity"
            raise self.error(
                m[key][1],
                f"{what} is static, so its objects cannot move: its {key} must be zero or absent",
            )
        if static:
            speed = speed_range = velocity_range = None
        spec = generate.BlockSpec(
            count=count,
            size=(int(size[0]), int(size[1])) if all(map(float.is_integer, size)) else size,
            seed=seed,
            speed=speed,
            speed_range=speed_range,
            velocity_range=velocity_range,
        )
        kind = _KIND_OF_SHAPE[shape]
        contact = self.contact(m, what, at)
        return Block(spec, kind, mass, static, color, color_node, fill, name, node, at, k, contact)

    def velocity_range(self, vnode, what: str, at: dict):
        """((vx0, vy0), (vx1, vy1)) of `velocity: {min: [vx, vy], max: [vx, vy]}`."""
        if not isinstance(vnode, yaml.MappingNode):
            raise self.error(
                vnode,
                f"{what}.velocity must be {{min: [vx, vy], max: [vx, vy]}}"
                f", not {parse.describe(vnode)}",
            )
        r = self.mapping(vnode, "velocity", RANGE_KEYS)
        ends = []
        for key in RANGE_KEYS:
            if key not in r:
                raise self.error(vnode, f"{what}.velocity is missing '{key}'")
            items, v = self.pair(r[key][1], f"{what}.velocity {key}")
            for a, (n, axis) in enumerate(zip(items, "xy", strict=True)):
                at[(f"velocity {key}", a)] = (n, f"{what}.velocity {key} {axis}")
            ends.append((float(v[0]), float(v[1])))
        for axis in (0, 1):
            if ends[0][axis] > ends[1][axis]:
                raise self.error(
                    vnode,
                    f"{what}.velocity: min {'xy'[axis]} "
                    f"{fmt(ends[0][axis])} is more than max {'xy'[axis]} "
                    f"{fmt(ends[1][axis])}",
                )
        return ends[0], ends[1]

    def range_ends(self, r: dict, node, what: str, at: dict):
        """(min, max) of a speed range {min, max}: numbers >= 0."""
        for key in RANGE_KEYS:
            if key not in r:
                raise self.error(node, f"{what} is missing '{key}'")
        a = self.number(r["min"][1], f"{what} min", lo=0, unit=" px/s")
        b = self.number(r["max"][1], f"{what} max", lo=0, unit=" px/s")
        for key in RANGE_KEYS:
            at[(f"velocity {key}", 0)] = at[(f"velocity {key}", 1)] = (r[key][1], f"{what} {key}")
        return a, b

    def check_blocks(self, blocks: list[Block], world: WorldSpec | None, model, fps_from=None):
        """The rules of each block's objects (runner.scenario.rules), each block's first fault at
        its node: its size and mass, its `speed` as each velocity component, and each end of its
        ranges as a velocity; under the paper model a range of velocities is drawn as whole
        numbers, so its ends are whole. Those that need the world or the model wait for them."""
        fps = world.fps if world else None
        model = model or _NO_MODEL
        for b in blocks:
            b.spec = dataclasses.replace(b.spec, whole=model.whole_velocities)
        speed = [(b.spec.speed or 0.0,) * 2 for b in blocks]
        cols = _columns(blocks, np.zeros((len(blocks), 2)), speed)
        found = rules.first_per_row(rules.faults(cols, model.paper_rates, fps, None))
        refused = {f.row for f in found}
        for f in found:
            self.attempt(_raise, self.fault(blocks, f, model, fps_from, "generate"))
        ends = [_End(b, key) for b in blocks for key in ("min", "max") if b.ends is not None]
        n = len(ends)
        cols = rules.Columns(
            np.ones((n, 2)), np.zeros((n, 2)), np.array([e.vel for e in ends]).reshape(n, 2),
            np.full(n, np.nan), np.zeros(n, bool),
        )  # fmt: skip
        for f in rules.first_per_row(rules.faults(cols, False, fps)):
            if ends[f.row].index not in refused:
                refused.add(ends[f.row].index)
                self.attempt(_raise, self.fault(ends, f, model, fps_from, "generate"))
        if not model.whole_velocities:
            return
        for e in ends:
            if e.index in refused or e.speed:
                continue
            for a in (0, 1):
                if not float(e.vel[a]).is_integer():
                    refused.add(e.index)
                    node, what = e.at[("velocity", a)]
                    self.attempt(
                        _raise,
                        self.error(
                            node,
                            f"{self.prefix(model.origin)}{what} must be a whole number under "
                            f"the paper model (it draws whole-number velocities), not "
                            f"{fmt(e.vel[a])}",
                        ),
                    )
                    break


class _End:
    """One end (min or max) of a block's range of speeds or velocities, checked as a velocity."""

    def __init__(self, block: Block, key: str):
        self.index, self.node, self.line = block.index, block.node, block.line
        self.speed = block.spec.speed_range is not None
        end = block.ends[RANGE_KEYS.index(key)]
        self.vel = (end, 0.0) if self.speed else end
        self.at = {("velocity", a): block.at[(f"velocity {key}", a)] for a in (0, 1)}


def fault_error(reader: Nodes, items, f: rules.Fault, kind: str, origin=None, fps_from=None):
    """The ScenarioError of Fault `f` of `items` (listed objects or blocks, `kind` "objects" or
    "generate"), at the node of the value it is about: `--model M: objects[3].size w must be
    ...`; a fault of the whole object (its box) is at the object, and an object it overlaps is
    named with its line; each by its name too when it has one (`objects[3] (ball, line 7)`)."""
    o = items[f.row]

    def who(x, line=False) -> str:
        said = [getattr(x, "name", None)] + [f"line {x.line}"] * line
        return f"{kind}[{x.index}]" + (f" ({', '.join(filter(None, said))})" if any(said) else "")

    box = f.field == "box"
    node, what = (o.node, who(o, f.other is not None)) if box else o.at[(f.field, f.axis)]
    text = f.text
    if f.other is not None:
        text = text.format(other=who(items[f.other], True))
    origins = (origin if "model" in f.by else None, fps_from if "fps" in f.by else None)
    said = f"{what} {text}" if f.named else text
    return reader.error(node, f"{reader.prefix(*origins)}{said}")


def _named(m: dict) -> str:
    """" (NAME)" of an object mapping whose `name` is plain text, for its messages; else ""."""
    node = m["name"][1] if "name" in m else None
    text = parse.value(node) if isinstance(node, yaml.ScalarNode) else None
    return f" ({text.strip()})" if isinstance(text, str) and text.strip() else ""
