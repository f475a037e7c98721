"""Objects from a table: `objects: {file: bodies.csv}` (or `.npy`), read and checked by column.

A scenario with many objects may name a table instead of listing them. The file's path is relative
to the scenario's folder and must stay inside it (no absolute path, no `..` or link leading out);
its size (`--max-file-bytes`) and its number of rows (`--max-objects`) are checked before it is
parsed. Columns, by name (any order; only id, shape, w, h, x, y are required):

    id     0, 1, 2, ... in row order (the object's id)
    shape  box | circle (a circle's w and h are its diameter, so equal)
    w, h   whole pixels >= 1
    x, y   the top-left corner, px (whole pixels under the paper model)
    vx, vy px/s (default 0)
    mass   MIN_MASS ... MAX_MASS (default 1; empty for a static object)
    color  a CSS name or #rrggbb (default white)
    name   text, MAX_OBJECT_NAME_CHARS at most (default none)
    static true | false (default false)
    fill   true | false (default false)

The file is read once (`parse.read_regular`: a regular file within `--max-file-bytes`) and its
bytes go to `runner.scenario.tableread`, which makes one structured array of them: a CSV file (a
header row of column names, then one row per object, fields separated by commas, a field holding a
comma quoted with ", blank lines skipped, lines ending in LF, CRLF or CR) by `numpy.loadtxt` in a
single pass, a `.npy` file (a structured array whose field names are the columns, numbers as any
numeric type, text as unicode or bytes) over the same bytes once its header's claim has been held
against the file's size. The table's SHA-256 is kept (`Table.sha256`): it counts in the scenario's
hash, so goldens and reports see an edited table as an edited scenario.

Every check runs over whole columns at once (numpy), and the first failing cell, in row order and
then column order, is reported as `FILE:ROW:COLUMN: error: ...`: the CSV's line and the character
column where the field starts (for `.npy` the row counted from 1 and the field's number). Finding
that place reads the CSV again with Python's csv module, on the error path only. A text cell longer
than its column's bound (TEXT_CHARS) is refused, never cut short; names follow the one rule for
object names (`runner.scenario.objects.object_names`), and two rows of one name are refused at the
second (`runner.scenario.assemble.check_names`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import os
from dataclasses import dataclass

import numpy as np

from collide2d.engine import motion
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE
from collide2d.runner.scenario import colors
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.parse import read_regular
from collide2d.runner.scenario.tableread import (
    COLUMNS,
    NUMBERS,
    REQUIRED,
    TEXT_CHARS,
    read_csv,
    read_npy,
)

__all__ = ["COLUMNS", "NUMBERS", "REQUIRED", "TEXT_CHARS", "Table", "read_table", "table_of"]

SUFFIXES = (".csv", ".npy")
TRUE_WORDS = ("true", "yes", "on", "1")
FALSE_WORDS = ("false", "no", "off", "0", "")


@dataclass(frozen=True)
class Table:
    """The objects of a table, checked, as arrays in id order; `colors` are the distinct colours
    in order of first use and `color_of` each object's index into them."""

    path: str
    kind: np.ndarray
    pos: np.ndarray
    size: np.ndarray
    vel: np.ndarray
    mass: np.ndarray
    static: np.ndarray
    fill: np.ndarray
    colors: list
    color_of: np.ndarray
    names: tuple
    where: object  # where(row, column) -> ScenarioError maker, see runner.scenario.tableread.Place
    lines: tuple | None = None  # each object's line in the scenario, when it has its own
    sha256: str | None = None  # of the table file's bytes (None: the rows are the scenario's text)

    @property
    def n(self) -> int:
        return int(self.kind.shape[0])

    def error(self, row: int, column: str, message: str):
        """The ScenarioError at the cell of `row` (from 0) and `column`."""
        return self.where(row, column, message)


def table_path(scenario_path: str | None, given: str) -> tuple[str, str]:
    """(the path to open, the path shown in messages) of a table named `given` by the scenario at
    `scenario_path`; ValueError with the reason when it is not a relative path inside the
    scenario's folder."""
    if scenario_path is None:
        raise ValueError("a table of objects needs a scenario file (its folder holds the table)")
    if not given or os.path.isabs(given) or given.startswith(("~", "\\")):
        raise ValueError(f"the table {given!r} must be a path relative to the scenario's folder")
    if os.path.splitext(given)[1].lower() not in SUFFIXES:
        raise ValueError(f"the table {given!r} must be a .csv or .npy file")
    folder = os.path.dirname(os.path.abspath(scenario_path))
    shown = os.path.join(os.path.dirname(scenario_path), given)
    target = os.path.realpath(os.path.join(folder, given))
    root = os.path.realpath(folder)
    if os.path.commonpath([root, target]) != root or target == root:
        raise ValueError(f"the table {given!r} lies outside the scenario's folder")
    return target, shown


def read_table(
    opened: str, shown: str, limits: Limits, width: int, height: int, fps: int, paper: bool
) -> Table:
    """Read and check the table at `opened` (named `shown` in messages) for a world of that size,
    under the paper model's rules when `paper`; a located ScenarioError when anything is wrong."""
    raw = read_regular(opened, limits.max_file_bytes, shown, "table")
    if opened.lower().endswith(".npy"):
        data, place = read_npy(raw, shown, limits)
    else:
        data, place = read_csv(raw, shown, limits)
    table = _check(data, place, width, height, fps, paper)
    return dataclasses.replace(table, sha256=hashlib.sha256(raw).hexdigest())


# --- checking, column by column -----------------------------------------------------------------


def _words(
    data, name: str, default: str, refuse, lower: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """A text column as (its distinct values in order of first use, stripped (and lower-cased),
    as an array of str; each row's index into them); [default] for every row when the column is
    absent. A value past the column's TEXT_CHARS as written is refused (a CSV's is read one
    character longer, so it is seen, never cut short). Stripping, comparing and measuring run
    over the distinct values only."""
    n = data.shape[0]
    if name not in data.dtype.names:
        return np.array([default]), np.zeros(n, np.int64)
    column = data[name]
    few = _few_distinct(column) if column.dtype.kind in "US" else None
    if few is not None:
        first_seen, inverse = few
    else:  # many texts, or numbers (a .npy column: 1 and 1.0 one value, each NaN apart)
        first_seen = {}
        inverse = np.array(
            [first_seen.setdefault(v, len(first_seen)) for v in column.tolist()], np.int64
        )
    inverse = inverse.reshape(-1)
    most = TEXT_CHARS[name]
    words = []
    for k, u in enumerate(first_seen):
        if isinstance(u, bytes):
            u = u.decode("utf-8", "replace")
        u = str(u)
        if column.dtype.kind in "US" and len(u) > most:
            refuse(inverse == k, name, lambda r: f"the cell holds more than {most} characters")
        u = u.strip()
        words.append(u.lower() if lower else u)
    return np.array(words + [""])[:-1], inverse


FEW_DISTINCT = 16  # a text column with more distinct values is taken apart by a dict


def _few_distinct(column: np.ndarray):
    """({value: None} in order of first use, each row's index into them) of a text column with
    at most FEW_DISTINCT distinct values, found by comparing whole columns; None when it has
    more."""
    n = column.shape[0]
    inverse = np.full(n, -1, np.int64)
    seen: dict = {}
    at = 0
    while at < n:
        if len(seen) == FEW_DISTINCT:
            return None
        value = column[at : at + 1]
        inverse[at:][column[at:] == value[0]] = len(seen)
        seen[value.tolist()[0]] = None
        rest = np.flatnonzero(inverse[at:] < 0)
        at = at + int(rest[0]) if rest.size else n
    return seen, inverse


def _first(bad: np.ndarray) -> int | None:
    return int(np.argmax(bad)) if bad.any() else None


def _check(data, place, width: int, height: int, fps: int, paper: bool) -> Table:
    n = data.shape[0]
    names = data.dtype.names
    # (row, column index, order found, column, message): the first cell in row and column order,
    # and of two problems in one cell the one found first
    problems: list[tuple[int, int, int, str, str]] = []

    def refuse(bad, column, message_of) -> None:
        r = _first(bad)
        if r is not None:
            problems.append((r, names.index(column), len(problems), column, message_of(r)))

    def number(column, default=0.0) -> np.ndarray:
        if column not in names:
            return np.full(n, default)
        v = data[column].astype(np.float64)
        refuse(~np.isfinite(v), column, lambda r: f"must be a finite number, not {_shown(v[r])}")
        return np.where(np.isfinite(v), v, default) + 0.0  # -0.0 is 0.0

    def whole(v, column, lo, unit):
        refuse(
            (v != np.floor(v)) | (v < lo),
            column,
            lambda r: f"must be a whole number {unit}>= {lo}, not {_shown(v[r])}",
        )

    ids = number("id")
    refuse(
        ids != np.arange(n),
        "id",
        lambda r: f"must be {r} (ids run 0, 1, 2, ... in row order), not {_shown(ids[r])}",
    )
    words, of = _words(data, "shape", "box", refuse)
    kind = np.where(words == "circle", KIND_CIRCLE, KIND_BOX).astype(np.int8)[of]
    known = ((words == "box") | (words == "circle"))[of]
    refuse(~known, "shape", lambda r: f"must be box or circle, not {str(words[of[r]])!r}")
    w, h = number("w", 1.0), number("h", 1.0)
    whole(w, "w", 1, "of pixels ")
    whole(h, "h", 1, "of pixels ")
    refuse(
        (kind == KIND_CIRCLE) & (w != h),
        "h",
        lambda r: (
            f"a circle's w and h are its diameter and must be equal, not {_shown(w[r])} "
            f"and {_shown(h[r])}"
        ),
    )
    x, y = number("x"), number("y")
    if paper:
        for v, c in ((x, "x"), (y, "y")):
            refuse(
                v != np.floor(v),
                c,
                lambda r, v=v: (
                    f"must be a whole number of pixels under the paper model, not {_shown(v[r])}"
                ),
            )
    for v, c, side, size in ((x, "x", width, w), (y, "y", height, h)):
        refuse(
            (v < 0) | (v + size > side),
            c,
            lambda r, v=v, size=size, side=side: (
                f"the box [{_shown(v[r])}, {_shown(v[r] + size[r])}) must lie in [0, {side})"
            ),
        )
    static = _flag(data, "static", refuse)
    fill = _flag(data, "fill", refuse)
    vx, vy = number("vx"), number("vy")
    for v, c in ((vx, "vx"), (vy, "vy")):
        refuse(
            np.abs(v) > 1e9,
            c,
            lambda r, v=v: f"must be at most 1e9 px/s in size, not {_shown(v[r])}",
        )
        refuse(static & (v != 0), c, lambda r: "the object is static, so it cannot move")
        if paper:
            moving = ~static & np.isfinite(v)
            for value in np.unique(v[moving]):
                try:
                    motion.paper_rate(float(value), fps)
                except ValueError as exc:
                    refuse(moving & (v == value), c, lambda r, exc=exc: str(exc))
                    break
    mass = _mass(data, static, refuse)
    rgb, color_of = _colors(data, refuse)
    names_out = _names(data, refuse)
    if problems:
        r, _, _, column, message = min(problems)
        raise place(r, column, message)
    return Table(
        path=place.shown,
        kind=kind,
        pos=np.stack([x, y], 1),
        size=np.stack([w, h], 1),
        vel=np.where(static[:, None], 0.0, np.stack([vx, vy], 1)),
        mass=np.where(static, np.inf, mass),
        static=static,
        fill=fill,
        colors=rgb,
        color_of=color_of,
        names=names_out,
        where=place,
    )


def _shown(v) -> str:
    v = float(v)
    return str(int(v)) if math.isfinite(v) and v.is_integer() and abs(v) < 1e15 else repr(v)


def _names(data, refuse) -> tuple:
    """Each row's name under the one rule for object names (runner.scenario.objects.object_names), a
    cell past TEXT_CHARS as written refused first (a CSV's is read one character longer, never cut
    short unseen); a number in a .npy name column is its text."""
    from collide2d.runner.scenario.objects import NameRefused, object_names

    n = data.shape[0]
    if "name" not in data.dtype.names:
        return (None,) * n
    column = data["name"]
    texts = column.tolist()
    if column.dtype.kind == "S":
        texts = [v.decode("utf-8", "replace") for v in texts]
    elif column.dtype.kind != "U":
        texts = [str(v) for v in texts]
    most = TEXT_CHARS["name"]
    if max(map(len, texts), default=0) > most:
        long = np.fromiter(map(len, texts), np.int64, n) > most
        refuse(long, "name", lambda r: f"the cell holds more than {most} characters")
        return (None,) * n
    try:
        return tuple(object_names(texts))
    except NameRefused as exc:
        said = str(exc)
        refuse(np.arange(n) == exc.index, "name", lambda r: said)
        return (None,) * n


def _flag(data, column: str, refuse) -> np.ndarray:
    n = data.shape[0]
    if column in data.dtype.names and data[column].dtype.kind in "biuf":
        v = data[column].astype(np.float64)
        refuse((v != 0) & (v != 1), column, lambda r: f"must be true or false, not {_shown(v[r])}")
        return v != 0
    words, of = _words(data, column, "false", refuse)
    yes = np.isin(words, TRUE_WORDS)
    known = (yes | np.isin(words, FALSE_WORDS))[of]
    refuse(~known, column, lambda r: f"must be true or false, not {str(words[of[r]])!r}")
    return yes[of] if n else np.zeros(0, bool)


def _mass(data, static, refuse) -> np.ndarray:
    from collide2d.runner.scenario.objects import DEFAULT_MASS, MAX_MASS, MIN_MASS

    n = static.shape[0]
    if "mass" not in data.dtype.names:
        return np.full(n, DEFAULT_MASS)
    col = data["mass"]
    if col.dtype.kind in "iuf":
        given = np.ones(n, bool)
        mass = col.astype(np.float64)
    else:
        words, of = _words(data, "mass", "", refuse)
        values = np.full(words.shape[0], np.nan)
        bad_word = np.zeros(words.shape[0], bool)
        for k, w in enumerate(words.tolist()):  # the distinct values only
            if w:
                try:
                    values[k] = float(w)
                except ValueError:
                    bad_word[k] = True
        refuse(bad_word[of], "mass", lambda r: f"must be a number, not {str(words[of[r]])!r}")
        given = (words != "")[of]
        mass = np.where(bad_word[of], DEFAULT_MASS, values[of])
    refuse(
        given & static,
        "mass",
        lambda r: "the object is static, so its mass is infinite; leave the cell empty",
    )
    refuse(
        given & ~static & ~((mass >= MIN_MASS) & (mass <= MAX_MASS)),
        "mass",
        lambda r: f"must be from {MIN_MASS:g} to {MAX_MASS:g}, not {_shown(mass[r])}",
    )
    return np.where(given, mass, DEFAULT_MASS)


def _colors(data, refuse) -> tuple[list, np.ndarray]:
    """The distinct colours in order of first use, and each row's index into them."""
    from collide2d.runner.scenario.objects import DEFAULT_COLOR

    n = data.shape[0]
    if n == 0:
        return [], np.zeros(0, np.int64)
    if "color" not in data.dtype.names:
        return [DEFAULT_COLOR], np.zeros(n, np.int64)
    words, of = _words(data, "color", "", refuse, lower=False)  # in order of first use
    rgb = []
    for u, word in enumerate(words.tolist()):
        try:
            rgb.append(colors.parse_color_text(word) if word else DEFAULT_COLOR)
        except ValueError as exc:
            refuse(of == u, "color", lambda r, exc=exc: str(exc))
            rgb.append(DEFAULT_COLOR)
    return rgb, of


TABLE_KEYS = ("file",)


def table_of(reader, top: dict, scenario_path: str | None, limits: Limits, world, paper: bool):
    """The Table the scenario's `objects: {file: NAME}` names, or None when `objects` is a list
    (or absent). `reader` (a runner.scenario.nodes.Nodes) locates errors in the scenario itself."""
    import yaml

    if "objects" not in top or not isinstance(top["objects"][1], yaml.MappingNode):
        return None
    whole = top["objects"][1]
    if not any(getattr(k, "value", None) == "file" for k, _ in whole.value):
        raise reader.error(
            whole, "objects must be a list, or {file: NAME} naming a table, not a mapping"
        )
    m = reader.mapping(whole, "objects", TABLE_KEYS)
    node = m["file"][1]
    given = reader.string(node, "objects.file")
    try:
        opened, shown = table_path(scenario_path, given)
    except ValueError as exc:
        raise reader.error(node, str(exc)) from None
    return read_table(opened, shown, limits, world.width, world.height, world.fps, paper)
