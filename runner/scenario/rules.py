"""The rules every object meets, written once and checked by column, whatever wrote the object.

A YAML list (`runner.scenario.objects`), a generate block, a CSV or .npy table
(`runner.scenario.table`) and the fast lane (`runner.scenario.fastlane`) each read their objects'
values into `Columns` (numpy arrays, one row per object) and ask `faults` and `first_overlap` what
breaks a rule; they differ only in how they read values and in how they say where a fault is. A
`Fault` names its row, its field ("size", "position", "velocity", "mass", or "box" for the whole
object) and axis (0 for x or w, 1 for y or h), and the rule's words; the source that wrote the
row turns it into a located error: the YAML node of the value (`objects[3].size w must be ...`),
the table's cell (`row 4, column w: must be ...`), or, in the fast lane, a fall back to the
general path. The words after that subject are the same for every source.

The rules (docs/scenario-format.md, docs/limits.md):
- a size is a whole number of pixels from 1 to MAX_SIZE;
- a mass, when given, lies in [MIN_MASS, MAX_MASS], and a static object has none (it is infinite);
- a velocity component lies in [-MAX_SPEED, MAX_SPEED], and a static object's is 0;
- a restitution, when given, lies in [0, 1], and a friction in [0, MAX_FRICTION]; the paper model
  takes neither (the paper has no restitution, friction or gravity;
  docs/scenario-format.md#gravity-restitution-and-friction);
- under the paper model a position is a whole number of pixels and a moving object's velocity
  component is a rate the model can take at the world's fps (`engine.motion.paper_rate`);
- with the world known, every object's box lies inside it, and at the start no two objects overlap
  (boxes, or under `geometry: exact` the real shapes; touching is fine).

An object's name follows one rule wherever it is written (a list, a table, the fast lane, a generate
block's `name`): `object_names`. Surrounding whitespace is not part of it, a name left empty is no
name, and a name holds at most MAX_OBJECT_NAME_CHARS characters of text; that no two objects share
one is checked once all are known (`runner.scenario.assemble.check_names`).

Within a row the fields are checked in FIELDS order and each cell's rules in the order above, so
`first_per_row` gives each object's first fault as reading the object from its start would meet it.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from collide2d.engine import motion
from collide2d.runner import lanes
from collide2d.runner.scenario.nodes import fmt

DEFAULT_MASS = 1.0  # mass units
MIN_MASS = 1e-15  # mass units, the lightest movable object
MAX_MASS = 1e15  # mass units, the heaviest movable object (`static: true` is heavier than any)
MAX_SPEED = 1e9  # px/s, largest velocity component (a larger one crosses any world in a tick)
MAX_OBJECT_NAME_CHARS = 100  # characters in an object's name (it labels the object in every output)
MAX_SIZE = 2**53  # px, the largest side of an object (every whole number up to it is a float64)
DEFAULT_RESTITUTION = 1.0  # e of an object: elastic
DEFAULT_FRICTION = 0.0  # Coulomb's mu of an object: frictionless
# The largest mu: far past any real pair of materials (rubber on concrete is about 1), small
# enough that mu times any impulse a scenario can give stays many orders inside float64.
MAX_FRICTION = 1e6
FIELDS = ("size", "position", "mass", "velocity", "restitution", "friction", "box")
MAX_FAULTS = 20  # rows reported per rule (runner.scenario.nodes.MAX_ERRORS are reported at once)


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
class Columns:
    """The values of n objects, read but not yet checked: sizes (n, 2) px, positions (n, 2) px as
    written, velocities (n, 2) px/s, masses (n,) (NaN where none is given), static (n,) bool;
    `corner` (n, 2) the top-left corner when it is not the position written (a polygon's);
    restitution and friction (n,) (NaN where none is given; None: given for none)."""

    size: np.ndarray
    pos: np.ndarray
    vel: np.ndarray
    mass: np.ndarray
    static: np.ndarray
    corner: np.ndarray | None = None
    restitution: np.ndarray | None = None
    friction: np.ndarray | None = None

    @property
    def n(self) -> int:
        return int(self.static.shape[0])

    @property
    def box(self) -> np.ndarray:
        return self.pos if self.corner is None else self.corner


@dataclass(frozen=True)
class Fault:
    """A rule broken at `row`'s `field` (axis 0: x or w, 1: y or h): the subject the source gives
    it, then `text`. `by` names what in force made it a fault ("model": the model's rule, "fps":
    and the fps), for a message that starts with the command-line option that set it; `other`
    is the row it overlaps, named by the source where `text` says {other}."""

    row: int
    field: str
    axis: int
    text: str
    by: tuple = ()
    other: int | None = None
    named: bool = True  # False: the text names the value itself (the engine's words)

    @property
    def order(self) -> tuple:
        return (self.row, FIELDS.index(self.field), self.axis)


def _rows(bad: np.ndarray) -> list[int]:
    return np.flatnonzero(bad)[:MAX_FAULTS].tolist()


def _cells(bad: np.ndarray) -> list[tuple[int, int]]:
    """(row, axis) of the first bad cells of an (n, 2) mask, in row then axis order."""
    rows = _rows(bad.any(axis=1))
    return [(r, a) for r in rows for a in (0, 1) if bad[r, a]]


def faults(
    cols: Columns, paper: bool, fps: int | None, world=None
) -> list[Fault]:
    """Every rule broken by `cols` (at most MAX_FAULTS rows a rule), in no particular order: those
    of each object alone under the model (`paper`) at `fps` (None: the paper model's rates wait
    for it), and, when `world` (width, height) is given, the world's bounds."""
    out: list[Fault] = []
    size = cols.size
    fraction = size != np.floor(size)
    low = ~fraction & (size < 1)
    high = ~fraction & (size > MAX_SIZE)
    for r, a in _cells(fraction | low | high):
        v = fmt(float(size[r, a]))
        if fraction[r, a]:
            out.append(Fault(r, "size", a, f"must be a whole number of pixels, not {v}"))
        elif low[r, a]:
            out.append(Fault(r, "size", a, f"must be at least 1 px, not {v}"))
        else:
            out.append(Fault(r, "size", a, f"must be at most {MAX_SIZE} px, not {v}"))
    if paper:
        pos = cols.pos
        for r, a in _cells(pos != np.floor(pos)):
            v = fmt(float(pos[r, a]))
            text = f"must be a whole number of pixels under the paper model, not {v}"
            out.append(Fault(r, "position", a, text, ("model",)))
    _mass_faults(cols, out)
    _velocity_faults(cols, paper, fps, out)
    _contact_faults(cols, paper, out)
    if world is not None:
        out += outside(cols, *world)
    return out


def _mass_faults(cols: Columns, out: list) -> None:
    mass, static = cols.mass, cols.static
    given = ~np.isnan(mass)
    low = given & (mass < MIN_MASS)
    high = given & (mass > MAX_MASS)
    for r in _rows(low | high | (given & static)):
        v = fmt(float(mass[r]))
        if low[r]:
            out.append(Fault(r, "mass", 0, f"must be at least {fmt(MIN_MASS)}, not {v}"))
        elif high[r]:
            out.append(Fault(r, "mass", 0, f"must be at most {fmt(MAX_MASS)}, not {v}"))
        else:
            text = "must not be given: the object is static, so its mass is infinite"
            out.append(Fault(r, "mass", 0, text))


def _velocity_faults(cols: Columns, paper: bool, fps: int, out: list) -> None:
    vel, static = cols.vel, cols.static[:, None]
    fast = np.abs(vel) > MAX_SPEED
    for r, a in _cells(fast):
        text = f"must be at most {fmt(MAX_SPEED)} px/s in size, not {fmt(float(vel[r, a]))}"
        out.append(Fault(r, "velocity", a, text))
    for r, a in _cells(static & (vel != 0) & ~fast):
        out.append(Fault(r, "velocity", a, "must be 0: the object is static, so it cannot move"))
    if not paper or fps is None:
        return
    moving = ~static & ~fast
    said = {}
    # the distinct values only (sorted(set()): np.unique would import numpy.ma on every load)
    for v in sorted(set(vel[moving].tolist())):
        try:
            motion.paper_rate(int(v) if v.is_integer() else v, fps)
        except ValueError as exc:
            said[v] = str(exc)
    if said:
        bad = moving & np.isin(vel, list(said))
        for r, a in _cells(bad):
            out.append(
                Fault(r, "velocity", a, said[float(vel[r, a])], ("model", "fps"), named=False)
            )


# What the paper model, without gravity, restitution or friction, says of an object's restitution
# or friction (the subject is the value: `objects[2].restitution cannot be given: ...`).
PAPER_REFUSES = (
    "cannot be given: the paper model has no {key} (the paper's objects bounce by its flip rule, "
    "elastic and weightless); {key} needs model: stepped"
)


def _contact_faults(cols: Columns, paper: bool, out: list) -> None:
    """Restitution in [0, 1], friction in [0, MAX_FRICTION], each where given; the paper model
    takes neither."""
    for key, hi in (("restitution", 1.0), ("friction", MAX_FRICTION)):
        v = getattr(cols, key)
        if v is None:
            continue
        given = ~np.isnan(v)
        low, high = given & (v < 0), given & (v > hi)
        for r in _rows(low | high):
            bound = "at least 0" if low[r] else f"at most {fmt(hi)}"
            out.append(Fault(r, key, 0, f"must be {bound}, not {fmt(float(v[r]))}"))
        if paper:
            for r in _rows(given & ~low & ~high):
                out.append(Fault(r, key, 0, PAPER_REFUSES.format(key=key), ("model",)))


def outside(cols: Columns, width: int, height: int) -> list[Fault]:
    """The objects whose box does not lie inside the world (axis: the first axis it leaves)."""
    lo = cols.box
    out_of = (lo < 0) | (lo + cols.size > np.array([width, height]))
    faults_ = []
    for r in _rows(out_of.any(axis=1)):
        text = (
            f"lies outside the world: its box {box_text(lo[r], cols.size[r])} must fit in "
            f"[0, {width}) x [0, {height})"
        )
        faults_.append(Fault(r, "box", 0 if out_of[r, 0] else 1, text))
    return faults_


def first_per_row(found: list[Fault]) -> list[Fault]:
    """Each row's first fault (FIELDS order, then axis), in row order."""
    out: dict[int, Fault] = {}
    for f in sorted(found, key=lambda f: f.order):
        out.setdefault(f.row, f)
    return list(out.values())


def box_text(p, s) -> str:
    """The half-open box [x, x+w) x [y, y+h) as text."""
    x0, x1 = fmt(float(p[0])), fmt(float(p[0] + s[0]))
    y0, y1 = fmt(float(p[1])), fmt(float(p[1] + s[1]))
    return f"[{x0}, {x1}) x [{y0}, {y1})"


def first_overlap(pos, size, shapes=None) -> Fault | None:
    """The first object, in id order, that overlaps an earlier one at the start (boxes at `pos`
    of `size`, (n, 2) px, all inside the world), as a Fault naming the earlier one {other}; None
    when none do. With `shapes` (kind (n,), vert_start, verts as in engine.world.Bodies) the real
    shapes under geometry exact decide: boxes that overlap hold shapes that may only touch."""
    from collide2d.runner.scenario.generate import first_overlap as boxes_overlap

    found = boxes_overlap(pos, size)
    if found is not None and shapes is not None:
        with lanes.objects(pos.shape[0]):
            found = _shape_overlap(shapes, pos, size)
    if found is None:
        return None
    a, b = found
    what = "shapes in boxes" if shapes is not None else "boxes"
    text = (
        f"overlaps {{other}} at the start: {what} {box_text(pos[b], size[b])} and "
        f"{box_text(pos[a], size[a])}"
    )
    return Fault(b, "box", 0, text, other=a)


def _shape_overlap(shapes, pos, size) -> tuple[int, int] | None:
    """The first pair (a, b) in (b, a) order whose exact shapes overlap with positive area."""
    from collide2d.engine.broadphase import METHOD_SWEEP, find_pairs
    from collide2d.engine.contact import penetration
    from collide2d.engine.shapes import build_cores

    n = pos.shape[0]
    cores = build_cores(SimpleNamespace(size=size, **shapes), "exact")
    pairs = find_pairs(METHOD_SWEEP, pos, pos + size, np.ones(n, bool))

    def shape(i):
        core = slice(cores.start[i], cores.start[i + 1])
        return (
            cores.shape[i],
            size[i, 0],
            size[i, 1],
            cores.radius[i],
            cores.verts[core],
            cores.normals[core],
        )

    for a, b in sorted(pairs.tolist(), key=lambda p: (p[1], p[0])):
        q = pos[b] - pos[a]
        if penetration(q[0], q[1], *shape(a), *shape(b))[0] > 0:
            return a, b
    return None
