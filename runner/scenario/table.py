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
    restitution  0 ... 1 (default 1; not under the paper model, only 1 under the exact model)
    friction     0 ... MAX_FRICTION (default 0; not under paper, only 0 under exact)
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
hash (`with_table`), so goldens and reports see an edited table as an edited scenario.

Every check runs over whole columns at once (numpy): first what each cell holds (`read_table`: a
number, a shape, a flag, a colour, a name), then, once the world and the model are known, the
rules every object meets however it is written (`checked`, by `runner.scenario.rules`; a start
overlap by `runner.scenario.assemble`). The first failing cell, in row order and then column
order, is reported as `FILE:ROW:COLUMN: error: ...`: the CSV's line and the character
column where the field starts (for `.npy` the row counted from 1 and the field's number). Finding
that place reads the CSV again with Python's csv module, on the error path only. A text cell longer
than its column's bound (TEXT_CHARS) is refused, never cut short; names follow the one rule for
object names (`runner.scenario.rules.object_names`), and two rows of one name are refused at the
second (`runner.scenario.assemble.check_names`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import os
from dataclasses import dataclass

import numpy as np

from collide2d.engine.world import KIND_BOX, KIND_CIRCLE
from collide2d.runner.scenario import colors, rules
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.parse import read_regular
from collide2d.runner.scenario.rules import DEFAULT_MASS, NameRefused, object_names
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
    """The objects of a table as arrays in id order; `colors` are the distinct colours in order of
    first use and `color_of` each object's index into them. As read, `mass` is NaN where none is
    given and `vel` as written; `checked` gives them as the objects have them, every rule held."""

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
    problems: tuple = ()  # cells at fault when read: (row, column index, order, column, text)
    restitution: np.ndarray | None = None  # (n,) NaN where not given (None: no column)
    friction: np.ndarray | None = None  # (n,) NaN where not given (None: no column)

    @property
    def n(self) -> int:
        return int(self.kind.shape[0])

    def error(self, row: int, column: str, message: str):
        """The ScenarioError at the cell of `row` (from 0) and `column`, the row named by its
        object's name when it has one (but in a message about the name itself)."""
        name = self.names[row] if column != "name" and row < len(self.names) else None
        return self.where(row, column, message, name)


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


def read_table(opened: str, shown: str, limits: Limits) -> Table:
    """Read the table at `opened` (named `shown` in messages): a located ScenarioError when the
    file cannot be read as a table, else its values, each cell's own faults kept for `refuse` and
    `checked`."""
    raw = read_regular(opened, limits.max_file_bytes, shown, "table")
    if opened.lower().endswith(".npy"):
        data, place = read_npy(raw, shown, limits)
    else:
        data, place = read_csv(raw, shown, limits)
    table = _check(data, place)
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


def _check(data, place) -> Table:
    """The table's values, each cell read as what its column holds (a number, a shape, a flag, a
    colour, a name); what a cell itself gets wrong is kept in `Table.problems`, and the rules
    of objects wait for `checked`."""
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
    refuse(
        (kind == KIND_CIRCLE) & (w != h),
        "h",
        lambda r: (
            f"a circle's w and h are its diameter and must be equal, not {_shown(w[r])} "
            f"and {_shown(h[r])}"
        ),
    )
    x, y = number("x"), number("y")
    static = _flag(data, "static", refuse)
    fill = _flag(data, "fill", refuse)
    vx, vy = number("vx"), number("vy")
    mass = _mass(data, refuse)
    rgb, color_of = _colors(data, refuse)
    names_out = _names(data, refuse)
    contact = {
        key: number(key, np.nan) if key in names else None for key in ("restitution", "friction")
    }
    return Table(
        path=place.shown,
        kind=kind,
        pos=np.stack([x, y], 1),
        size=np.stack([w, h], 1),
        vel=np.stack([vx, vy], 1),
        mass=mass,
        static=static,
        fill=fill,
        colors=rgb,
        color_of=color_of,
        names=names_out,
        where=place,
        problems=tuple(problems),
        **contact,
    )


# The table's column of each field and axis a rule may refuse (runner.scenario.rules.Fault).
_COLUMN_OF = {
    "size": ("w", "h"),
    "position": ("x", "y"),
    "box": ("x", "y"),
    "velocity": ("vx", "vy"),
    "mass": ("mass", "mass"),
    "restitution": ("restitution", "restitution"),
    "friction": ("friction", "friction"),
}


def checked(table: Table, world, paper: bool) -> Table:
    """The table with every rule of objects checked (runner.scenario.rules) in `world` (None:
    its bounds and rates wait for a good world), under the paper model's rules when `paper`: the
    first fault of a cell, in row order and then the file's
    column order, raised at its cell; else the table, static objects still and of infinite
    mass."""
    cols = rules.Columns(
        table.size, table.pos, table.vel, table.mass, table.static,
        restitution=table.restitution, friction=table.friction,
    )  # fmt: skip
    problems = list(table.problems)
    header = table.where.header
    fps, bounds = (world.fps, (world.width, world.height)) if world is not None else (None, None)
    for f in rules.faults(cols, paper, fps, bounds):
        column = _COLUMN_OF[f.field][f.axis]
        problems.append((f.row, header.index(column), len(problems), column, f.text))
    if problems:
        r, _, _, column, message = min(problems)
        raise table.error(r, column, message)
    static = table.static
    return dataclasses.replace(
        table,
        vel=np.where(static[:, None], 0.0, table.vel),
        mass=np.where(static, np.inf, np.where(np.isnan(table.mass), DEFAULT_MASS, table.mass)),
    )


def _shown(v) -> str:
    v = float(v)
    return str(int(v)) if math.isfinite(v) and v.is_integer() and abs(v) < 1e15 else repr(v)


def _names(data, refuse) -> tuple:
    """Each row's name under the one rule for object names (runner.scenario.rules.object_names), a
    cell past TEXT_CHARS as written refused first (a CSV's is read one character longer, never cut
    short unseen); a number in a .npy name column is its text, its bytes UTF-8 text (else refused,
    never replaced unseen)."""
    n = data.shape[0]
    if "name" not in data.dtype.names:
        return (None,) * n
    column = data["name"]
    texts = column.tolist()
    if column.dtype.kind == "S":
        try:
            texts = [v.decode("utf-8") for v in texts]
        except UnicodeDecodeError:
            bad = np.fromiter((not _utf8(v) for v in texts), bool, n)
            refuse(bad, "name", lambda r: "the cell is not UTF-8 text")
            return (None,) * n
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


def _utf8(raw: bytes) -> bool:
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


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


def _mass(data, refuse) -> np.ndarray:
    """Each row's mass as written, NaN where the cell is empty or the column absent."""
    n = data.shape[0]
    if "mass" not in data.dtype.names:
        return np.full(n, np.nan)
    col = data["mass"]
    if col.dtype.kind in "iuf":
        mass = col.astype(np.float64)
        given = np.ones(n, bool)
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
        given = (words != "")[of] & ~bad_word[of]
        mass = values[of]
    bad = given & ~np.isfinite(mass)
    refuse(bad, "mass", lambda r: f"must be a finite number, not {_shown(mass[r])}")
    return np.where(bad, DEFAULT_MASS, mass) + 0.0


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


def with_table(text_sha256: str, table_sha256: str) -> str:
    """The hash of a scenario whose objects come from a table: the file's and the table's hashes
    hashed together, so that goldens and reports see an edit of the table as an edit of the
    scenario. A scenario without a table keeps the hash of its file's bytes alone."""
    return hashlib.sha256(f"{text_sha256} {table_sha256}".encode("ascii")).hexdigest()


TABLE_KEYS = ("file",)


def table_of(reader, top: dict, scenario_path: str | None, limits: Limits):
    """The Table the scenario's `objects: {file: NAME}` names, read (`read_table`; its rules
    wait for `checked`), or None when `objects` is a list (or absent). `reader` (a
    runner.scenario.nodes.Nodes) locates errors in the scenario itself."""
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
    return read_table(opened, shown, limits)
