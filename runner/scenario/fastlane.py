"""The fast lane for long object lists in YAML, flow or block style, read by column.

A scenario that lists thousands of objects usually writes one per line,

    objects:
      - {shape: box, size: [10, 10], position: [40, 60], velocity: [12.5, -3], color: red}

or, as `yaml.safe_dump` and most generators write it, in block style,

    objects:
    - shape: box
      position:
      - 40
      - 60

and reading that through the general path (an event pass, a node tree, a reader per object) costs
tens of microseconds per value. When every item of the `objects` list has one of those forms, with
only plain values of the simplest kinds (decimal numbers, [x, y] pairs of them, and words), this
lane reads it instead. A block-style item is first written as the one flow mapping it means
(`_block_items`) when it has the simplest block form: its keys at one indent, each value plain on
its key's line, or an [x, y] pair as two `- number` lines. Then the values of each key are taken
from the lines (when every line has the first line's keys, in its order, with values of the same
forms, by one pattern over the whole list, its groups the columns; else line by line), converted and
checked a column at a time with numpy, and handed on as a `runner.scenario.table.Table`; the rest of
the file, with the list's lines blanked (so every line keeps its number), goes through the general
path as before.

The lane never decides what a file means: a file it would read differently from the general path,
or one with anything wrong in its objects (a value out of range, an overlap, a rule of the model),
goes through the general path whole (`FallBack`), which reads it, or refuses it at its place with
its usual message. So the lane changes how long a file takes, never what it means. What it leaves
to the general path: other block forms (values on lines of their own, other indents), multi-line
flow mappings, quoted or tagged values, anchors and aliases, comments or blank lines inside the
list, polygons, numbers with leading zeros (YAML 1.1 octal), exponents, underscores, or other YAML
1.1 forms, words YAML reads as booleans or null where a text is asked for, two objects of one name,
and lists shorter than FAST_MIN_OBJECTS. Names pass the one rule for object names
(`runner.scenario.rules.object_names`) as the general path's do.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass

import numpy as np

from collide2d.engine.world import KIND_BOX, KIND_CIRCLE
from collide2d.runner.scenario import colors, rules
from collide2d.runner.scenario.rules import DEFAULT_MASS, NameRefused, object_names

FAST_MIN_OBJECTS = 1000  # shorter lists take the general path (it is fast enough there)

_NUM = r"-?(?:0|[1-9][0-9]{0,29})(?:\.[0-9]{1,30})?"
_WORD = r"[A-Za-z_][A-Za-z0-9_.-]{0,99}"
_VALUE = rf"(?:{_NUM}|\[ *{_NUM} *, *{_NUM} *\]|{_WORD})"
_ITEM_RE = re.compile(rf" *- \{{ *[a-z]+: {_VALUE}(?: *, *[a-z]+: {_VALUE})* *\}} *")
_FIELD_RE = re.compile(rf"([a-z]+): (?:\[ *({_NUM}) *, *({_NUM}) *\]|({_NUM}|{_WORD}))")
_BLOCK_FIELD_RE = re.compile(
    rf"([a-z]+):(?: ({_NUM}|{_WORD}|\[ *{_NUM} *, *{_NUM} *\])|\n *- ({_NUM})\n *- ({_NUM}))\n"
)
_HEAD_RE = re.compile(r"objects: *\n")
_BLOCK_RE = re.compile(r"(?: *- [^\n]*(?:\n|\Z))*")
KEYS = (
    "shape",
    "size",
    "diameter",
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
# Plain words YAML 1.1 reads as something other than text (booleans, null).
_NOT_TEXT = {
    w
    for base in ("y", "n", "yes", "no", "on", "off", "true", "false", "null")
    for w in (base, base.capitalize(), base.upper())
}


class FallBack(Exception):
    """The fast lane declines: read the whole file through the general path."""


@dataclass
class Split:
    """A file whose object list the fast lane takes: the rest of its text (the list's lines
    blanked), and the list's lines with their 0-based line numbers."""

    rest: str
    lines: list[str]
    first_line: int
    same: dict | None = None  # the columns when every line has the first's form (_same_as_first)
    starts: tuple | None = None  # each object's first line (from 1) when not one line each
    blanked: int = 0  # lines of the list blanked in `rest` (block style: more than one an item)

    @property
    def n(self) -> int:
        return len(self.lines)


def split(text: str) -> Split | None:
    """The Split of `text` when its top-level `objects:` list has FAST_MIN_OBJECTS lines or more,
    each one flow mapping of plain simple values; None otherwise."""
    m = None
    for m in _HEAD_RE.finditer(text):
        if m.start() == 0 or text[m.start() - 1] == "\n":
            break
    else:
        return None
    if m is None:
        return None
    start = m.end()
    head_line = text.count("\n", 0, m.start())
    if text.startswith("-", len(text) - len(text[start:].lstrip(" "))) and not _ITEM_RE.match(
        text, start
    ):
        return _block_split(text, m, head_line)
    pos = _BLOCK_RE.match(text, start).end()
    block = text[start:pos]
    if block.endswith("\n"):
        block = block[:-1]
    lines = block.split("\n") if block else []
    if len(lines) < FAST_MIN_OBJECTS:
        return None
    if pos < len(text) and not (text[pos].isalpha() or text[pos] == "#"):
        return None  # the list must end at the next top-level key (or a comment, or the end)
    if not _ITEM_RE.fullmatch(lines[0]):
        return None
    rows = _same_as_first(lines[0], block, len(lines))
    if rows is None:
        indent = len(lines[0]) - len(lines[0].lstrip())
        if any(not _ITEM_RE.fullmatch(line) for line in lines) or any(
            len(line) - len(line.lstrip()) != indent for line in lines
        ):
            return None
    rest = text[: m.start()] + "objects: []\n" + "\n" * len(lines) + text[pos:]
    if pos >= len(text) and not text.endswith("\n"):
        rest = rest[:-1]
    return Split(rest, lines, head_line + 1, rows, blanked=len(lines))


def _block_split(text: str, m: re.Match, head_line: int) -> Split | None:
    """The Split of a block-style `objects:` list (its items written as flow lines), or None."""
    found = _block_items(text, m.end())
    if found is None:
        return None
    lines, starts, pos = found
    if len(lines) < FAST_MIN_OBJECTS:
        return None
    if pos < len(text) and not (text[pos].isalpha() or text[pos] == "#"):
        return None  # the list must end at the next top-level key (or a comment, or the end)
    taken = text.count("\n", m.end(), pos)
    rest = text[: m.start()] + "objects: []\n" + "\n" * taken + text[pos:]
    if pos >= len(text) and not text.endswith("\n"):
        rest = rest[:-1]
    first = head_line + 2  # the first item's line, from 1
    starts = tuple(first + s for s in starts)
    same = _same_as_first(lines[0], "\n".join(lines), len(lines))
    return Split(rest, lines, head_line + 1, same, starts, taken)


def _block_items(text: str, start: int):
    """The items of the block-style list at `start` as one-line flow mappings, with each item's
    line counted from the list's first (0-based) and the offset just past the list; None unless
    every item has the simplest block form (see the module's docstring) at the first one's indent.

    An item is `- key: value` followed by `  key: value` lines at the key's indent; a value is a
    plain simple value (_VALUE) on its line, or nothing there and an [x, y] pair as two lines
    `- number` at the key's indent or two spaces deeper. Whatever else YAML allows (comments,
    blank lines, quotes, longer lists, other indents) ends the match, and the list is declined
    when the match does not reach its end."""
    indent = len(text[start:]) - len(text[start:].lstrip(" "))
    item_re = _block_item_re(indent)
    lines: list[str] = []
    starts: list[int] = []
    at_line = 0
    pos = start
    pad = " " * indent
    while pos < len(text) and text.startswith(pad + "- ", pos):
        item = item_re.match(text, pos)
        if item is None:
            return None
        fields = []
        for key, one, x, y in _BLOCK_FIELD_RE.findall(item.group(0)):
            fields.append(f"{key}: {one}" if one else f"{key}: [{x}, {y}]")
        lines.append(f"{pad}- {{{', '.join(fields)}}}")
        starts.append(at_line)
        at_line += item.group(0).count("\n")
        pos = item.end()
    if pos < len(text) and text[pos] == " ":
        return None  # a line of the list the item form does not take
    return lines, starts, pos


@functools.cache
def _block_item_re(indent: int) -> re.Pattern:
    """One block-style item at `indent` (its dash's column), each line ended by a newline."""
    key = " " * (indent + 2)
    pair = "|".join(rf"\n{i}- {_NUM}\n{i}- {_NUM}" for i in (key, key + "  "))
    field = rf"[a-z]+:(?: {_VALUE}|{pair})\n"
    return re.compile(rf" {{{indent}}}- {field}(?:{key}{field})*")


def _same_as_first(first: str, block: str, n: int):
    """When every line of `block` has the keys of `first`, in its order, each with a value of the
    same form (a pair or one value) and the same indent: {key: column} of the values' texts, a
    pair's as two columns (key, key + "_y"); else None (the lines are then read one by one)."""
    keys = []
    parts = []
    for key, x, _y, _one in _FIELD_RE.findall(first):
        pair = bool(x)
        keys.append((key, pair))
        if pair:
            parts.append(rf"{key}: \[ *({_NUM}) *, *({_NUM}) *\]")
        else:
            parts.append(rf"{key}: ({_NUM}|{_WORD})")
    if len(keys) != first.count(":") or len({k for k, _ in keys}) != len(keys):
        return None
    if any(k not in KEYS for k, _ in keys):
        return None
    indent = len(first) - len(first.lstrip())
    line_re = re.compile(rf"^ {{{indent}}}- \{{ *" + " *, *".join(parts) + r" *\} *$", re.MULTILINE)
    rows = line_re.findall(block)
    if len(rows) != n:
        return None
    if len(parts) == 1 and not keys[0][1]:
        rows = [(r,) for r in rows]
    columns = list(zip(*rows, strict=True)) if rows else []
    out = {}
    at = 0
    for key, pair in keys:
        out[key] = columns[at]
        if pair:
            out[key + "_y"] = columns[at + 1]
        at += 2 if pair else 1
    return {"keys": keys, "columns": out}


def bound(split_: Split) -> int:
    """An upper bound of the YAML values of the whole file: the list's (`nodes`), and one per
    character of the rest but for the list's blanked lines, which hold none."""
    return nodes(split_) + len(split_.rest) - split_.blanked


def nodes(split_: Split) -> int:
    """YAML values the list holds (as the general path counts them): the mapping, each key and
    value, and two more for each pair."""
    if split_.same is not None:
        first = split_.lines[0]
        return split_.n * (1 + 2 * first.count(":") + 2 * first.count("["))
    n = 0
    for line in split_.lines:
        n += 1 + 2 * line.count(":") + 2 * line.count("[")
    return n


@dataclass
class _Column:
    """One key's values over the lines: `one` marks the lines giving one value (texts in `ones`,
    in line order), `two` those giving an [x, y] pair (texts in `xs`, `ys`)."""

    one: np.ndarray
    ones: list
    two: np.ndarray
    xs: list
    ys: list

    @property
    def present(self) -> np.ndarray:
        return self.one | self.two


def _columns(split_: Split) -> dict[str, _Column]:
    """Every key's _Column: taken whole when all lines share the first's form, else line by line
    (FallBack on an unknown or repeated key)."""
    n = split_.n
    none = np.zeros(n, bool)
    every = np.ones(n, bool)
    if split_.same is not None:
        out = {k: _Column(none, [], none, [], []) for k in KEYS}
        cols = split_.same["columns"]
        for key, pair in split_.same["keys"]:
            if pair:
                out[key] = _Column(none, [], every, list(cols[key]), list(cols[key + "_y"]))
            else:
                out[key] = _Column(every, list(cols[key]), none, [], [])
        return out
    raw: dict[str, list] = {k: ([], [], [], [], []) for k in KEYS}
    for i, line in enumerate(split_.lines):
        fields = _FIELD_RE.findall(line)
        if len(fields) != line.count(":"):
            raise FallBack
        seen = set()
        for key, x, y, one in fields:
            col = raw.get(key)
            if col is None or key in seen:
                raise FallBack  # an unknown or repeated key: the general path says so
            seen.add(key)
            if one:
                col[0].append(i)
                col[1].append(one)
            else:
                col[2].append(i)
                col[3].append(x)
                col[4].append(y)
    out = {}
    for key, (one_at, ones, two_at, xs, ys) in raw.items():
        one = none.copy()
        one[one_at] = True
        two = none.copy()
        two[two_at] = True
        out[key] = _Column(one, ones, two, xs, ys)
    return out


def _number(values: list[str]) -> np.ndarray:
    """Decimal texts (checked by the item pattern) to float64, parsed by numpy in one call."""
    if not values:
        return np.zeros(0)
    try:
        v = np.array(" ".join(values).split(" "), dtype=np.float64)
    except ValueError:
        raise FallBack from None  # a word where a number belongs
    return v + 0.0  # -0.0 is read as 0.0


def table(split_: Split, world, model, max_objects: int):
    """The objects of the list as a runner.scenario.table.Table, every check of the general path run
    by column under the model's rules (`model`: a runner.scenario.objects.ModelRules); FallBack
    when anything would make the general path refuse or read it otherwise."""
    from collide2d.runner.scenario.objects import DEFAULT_COLOR
    from collide2d.runner.scenario.table import Table

    n = split_.n
    if n > max_objects:
        raise FallBack
    cols = _columns(split_)

    def present(key) -> np.ndarray:
        return cols[key].present

    def words(key) -> np.ndarray:
        col = cols[key]
        if col.two.any():
            raise FallBack
        if col.one.all():
            return np.array(col.ones)
        out = np.full(n, "", dtype=np.array([*col.ones, ""]).dtype)
        out[col.one] = col.ones
        return out

    def pairs(key, default) -> np.ndarray:
        col = cols[key]
        if col.one.any():
            raise FallBack
        out = np.full((n, 2), default, np.float64)
        out[col.two, 0] = _number(col.xs)
        out[col.two, 1] = _number(col.ys)
        return out

    shape = words("shape")
    if not np.all((shape == "box") | (shape == "circle")):
        raise FallBack  # missing, a polygon, or not a shape
    circle = shape == "circle"
    # sizes: a box takes size (one number or [w, h]), a circle diameter (one number)
    if np.any(present("size") == circle) or np.any(present("diameter") != circle):
        raise FallBack
    box_size, diameter = cols["size"], cols["diameter"]
    if diameter.two.any():
        raise FallBack
    size = np.empty((n, 2))
    size[box_size.one] = _number(box_size.ones)[:, None]
    size[diameter.one] = _number(diameter.ones)[:, None]
    size[box_size.two, 0] = _number(box_size.xs)
    size[box_size.two, 1] = _number(box_size.ys)
    if not present("position").all():
        raise FallBack
    pos = pairs("position", 0.0)
    vel = pairs("velocity", 0.0)
    static = _flag(words("static"))
    fill = _flag(words("fill"))
    mass = np.full(n, np.nan)
    has_mass = present("mass")
    if has_mass.any():
        raw = cols["mass"].ones
        if cols["mass"].two.any() or not all(v[-1:].isdigit() for v in raw):
            raise FallBack
        mass[has_mass] = _number(raw)
    contact = {key: _numbers(cols[key], n) for key in ("restitution", "friction")}
    # every rule of objects (runner.scenario.rules): any fault is the general path's to say
    found = rules.Columns(size, pos, vel, mass, static, **contact)
    bounds = (world.width, world.height)
    if rules.faults(found, model.paper_rates, world.fps, bounds):
        raise FallBack
    color_word = words("color")
    unique, first, of = np.unique(color_word, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.shape[0])
    rgb = []
    for u in order.tolist():
        word = str(unique[u])
        if word in _NOT_TEXT or word[:1].isdigit() or word.startswith("-"):
            raise FallBack
        try:
            rgb.append(colors.parse_color_text(word) if word else DEFAULT_COLOR)
        except ValueError:
            raise FallBack from None
    name = cols["name"]
    if name.two.any():
        raise FallBack
    if name.one.all():
        names = tuple(name.ones)
    else:
        listed = [None] * n
        for i, text in zip(np.flatnonzero(name.one).tolist(), name.ones, strict=True):
            listed[i] = text
        names = tuple(listed)
    distinct = set(name.ones)
    if len(distinct) != len(name.ones):
        raise FallBack  # two objects of one name: the general path refuses the second
    for text in distinct:
        if text in _NOT_TEXT or text[:1].isdigit() or text[0] == "-":
            raise FallBack
    try:  # each name under the one rule for names: the lane takes those it leaves as written
        if object_names(list(distinct)) != list(distinct):
            raise FallBack
    except NameRefused:
        raise FallBack from None
    if rules.first_overlap(pos, size) is not None:  # boxes: the general path judges shapes
        raise FallBack
    return Table(
        path="",
        kind=np.where(circle, KIND_CIRCLE, KIND_BOX).astype(np.int8),
        pos=pos,
        size=size,
        vel=np.where(static[:, None], 0.0, vel),
        mass=np.where(static, np.inf, np.where(has_mass, mass, DEFAULT_MASS)),
        static=static,
        fill=fill,
        colors=rgb,
        color_of=rank[of.reshape(-1)],
        names=names,
        where=_fall_back,
        lines=split_.starts or tuple(range(split_.first_line + 1, split_.first_line + 1 + n)),
        **contact,
    )


def _numbers(col: _Column, n: int) -> np.ndarray:
    """(n,) a column of single numbers, NaN where not given."""
    if col.two.any():
        raise FallBack
    out = np.full(n, np.nan)
    out[col.one] = _number(col.ones)
    return out


def _flag(word: np.ndarray) -> np.ndarray:
    if not np.all((word == "") | (word == "true") | (word == "false")):
        raise FallBack
    return word == "true"


def _fall_back(row, column, message, name=None):
    """A later check (the exact model's room to move) refused an object of the fast lane: the
    general path reads the file again and refuses it at the object's line, in its own words."""
    raise FallBack
