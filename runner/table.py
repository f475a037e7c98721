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
    name   text (default none)
    static true | false (default false)
    fill   true | false (default false)

A CSV file has a header row of column names, then one row per object, fields separated by commas
(a field holding a comma is quoted with "); blank lines are skipped. It is read by
`numpy.loadtxt` into one structured array in a single pass. A `.npy` file holds a structured array
whose field names are the columns (numbers as any numeric type, text as unicode or bytes); its
header is read first, so its row count and size are checked before the data is read, and it is
loaded without pickles.

Every check runs over whole columns at once (numpy), and the first failing cell, in row order and
then column order, is reported as `FILE:ROW:COLUMN: error: ...`: the CSV's line and the character
column where the field starts (for `.npy` the row counted from 1 and the field's number). Finding
that place reads the CSV again with Python's csv module, on the error path only.
"""

from __future__ import annotations

import csv
import difflib
import io
import math
import os
from dataclasses import dataclass

import numpy as np

from collide2d.engine import motion
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE
from collide2d.runner import colors
from collide2d.runner.limits import Limits
from collide2d.runner.yamlsafe import ScenarioError

COLUMNS = ("id", "shape", "w", "h", "x", "y", "vx", "vy", "mass", "color", "name", "static", "fill")
REQUIRED = ("id", "shape", "w", "h", "x", "y")
NUMBERS = ("id", "w", "h", "x", "y", "vx", "vy")
SUFFIXES = (".csv", ".npy")
# Longest text a cell may hold, per text column (characters); wider columns would cost memory for
# every row.
TEXT_CHARS = {"shape": 16, "color": 40, "name": 100, "static": 8, "fill": 8, "mass": 100}
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
    where: object  # where(row, column) -> ScenarioError maker, see _Place
    lines: tuple | None = None  # each object's line in the scenario, when it has its own

    @property
    def n(self) -> int:
        return int(self.kind.shape[0])

    def error(self, row: int, column: str, message: str) -> ScenarioError:
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
    try:
        size = os.stat(opened).st_size
    except OSError as exc:
        raise ScenarioError(shown, 1, 1, f"cannot read the table: {exc.strerror or exc}") from None
    if size > limits.max_file_bytes:
        raise ScenarioError(
            shown,
            1,
            1,
            f"the table is larger than the limit of {limits.max_file_bytes:,} bytes; "
            "raise it with --max-file-bytes",
        )
    if opened.lower().endswith(".npy"):
        data, place = _read_npy(opened, shown, limits)
    else:
        data, place = _read_csv(opened, shown, limits)
    return _check(data, place, width, height, fps, paper)


# --- reading ----------------------------------------------------------------------------------


class _Place:
    """Where a cell is, for messages: the CSV's line and character column (found by reading the
    text again, only when an error needs it) or the .npy's row and field number."""

    def __init__(self, shown: str, header: list[str], text: str | None):
        self.shown = shown
        self.header = header
        self.text = text

    def __call__(self, row: int, column: str, message: str) -> ScenarioError:
        col = self.header.index(column) if column in self.header else 0
        message = f"row {row + 1}, column {column}: {message}" if column else message
        if self.text is None:  # .npy: row counted from 1, the field's number
            return ScenarioError(self.shown, row + 1, col + 1, message)
        line, char = _csv_cell(self.text, row, col)
        return ScenarioError(self.shown, line, char, message)


def _data_records(text: str):
    """(data row from 0, line from 1, fields) of each CSV record after the header, blank lines
    skipped as numpy.loadtxt skips them."""
    reader = csv.reader(io.StringIO(text))
    next(reader, None)
    k = -1
    for record in reader:
        if not record or all(not f.strip() for f in record) and len(record) <= 1:
            continue
        k += 1
        yield k, reader.line_num, record


def _csv_cell(text: str, row: int, col: int) -> tuple[int, int]:
    """(line, character column) of field `col` of data row `row` (blank lines skipped, as
    numpy.loadtxt skips them), both from 1."""
    for k, line, _record in _data_records(text):
        if k == row:
            raw = text.splitlines()[line - 1] if line - 1 < len(text.splitlines()) else ""
            return line, _field_start(raw, col)
    return 1, 1


def _field_start(raw: str, col: int) -> int:
    """Character column (from 1) where field `col` of the CSV line `raw` starts."""
    field, quoted = 0, False
    for i, ch in enumerate(raw):
        if field == col:
            return i + 1
        if ch == '"':
            quoted = not quoted
        elif ch == "," and not quoted:
            field += 1
    return len(raw) + 1


def _header_error(shown: str, header: list[str]) -> None:
    """Unknown, repeated and missing columns, at the header line."""
    seen = set()
    at = 1
    for name in header:
        if name not in COLUMNS:
            near = difflib.get_close_matches(name, COLUMNS, n=1)
            hint = f"did you mean '{near[0]}'?" if near else "expected " + ", ".join(COLUMNS)
            raise ScenarioError(shown, 1, at, f"unknown column {name!r}; {hint}")
        if name in seen:
            raise ScenarioError(shown, 1, at, f"column {name!r} appears twice")
        seen.add(name)
        at += len(name) + 1
    missing = [c for c in REQUIRED if c not in seen]
    if missing:
        raise ScenarioError(
            shown,
            1,
            1,
            f"the table lacks the column(s) {', '.join(missing)} (header: id, shape, "
            "w, h, x, y and optionally vx, vy, mass, color, name, static, fill)",
        )


def _read_csv(opened: str, shown: str, limits: Limits):
    try:
        with open(opened, "rb") as f:
            raw = f.read(limits.max_file_bytes + 1)
    except OSError as exc:
        raise ScenarioError(shown, 1, 1, f"cannot read the table: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise ScenarioError(shown, line, 1, "the table is not UTF-8 text") from None
    del raw
    rows = text.count("\n") + (0 if text.endswith("\n") else 1) - 1
    if rows > limits.max_objects:
        raise ScenarioError(
            shown,
            1,
            1,
            f"the table has {rows} rows, past the limit of {limits.max_objects} objects; "
            "raise it with --max-objects",
        )
    first = text.split("\n", 1)[0].rstrip("\r")
    header = [h.strip() for h in next(csv.reader([first]), [])]
    if not first.strip():
        raise ScenarioError(shown, 1, 1, "the table is empty; its first line names the columns")
    _header_error(shown, header)
    place = _Place(shown, header, text)
    dtype = [(c, "f8") if c in NUMBERS else (c, f"U{TEXT_CHARS[c] + 1}") for c in header]
    try:
        data = np.loadtxt(
            io.StringIO(text),
            dtype=dtype,
            delimiter=",",
            skiprows=1,
            comments=None,
            quotechar='"',
            ndmin=1,
        )
    except ValueError:
        raise _first_bad_cell(text, header, place) from None
    return data, place


def _first_bad_cell(text: str, header: list[str], place: _Place) -> ScenarioError:
    """The error numpy met, found again cell by cell: a row of the wrong length or a number that
    is not one."""
    for k, line, record in _data_records(text):
        if len(record) != len(header):
            return ScenarioError(
                place.shown,
                line,
                1,
                f"row {k + 1} has {len(record)} fields; the header names {len(header)}",
            )
        for c, name in enumerate(header):
            if name in NUMBERS:
                try:
                    float(record[c])
                except ValueError:
                    return place(k, name, f"must be a number, not {record[c].strip()!r}")
    return ScenarioError(place.shown, 1, 1, "the table cannot be read as CSV")


def _read_npy(opened: str, shown: str, limits: Limits):
    try:
        with open(opened, "rb") as f:
            version = np.lib.format.read_magic(f)
            if version == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
            else:
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
    except (OSError, ValueError) as exc:
        raise ScenarioError(shown, 1, 1, f"not a .npy file numpy can read ({exc})") from None
    if dtype.names is None or len(shape) != 1:
        raise ScenarioError(
            shown,
            1,
            1,
            "a .npy table holds a one-dimensional structured array whose field "
            "names are the columns",
        )
    if shape[0] > limits.max_objects:
        raise ScenarioError(
            shown,
            1,
            1,
            f"the table has {shape[0]} rows, past the limit of {limits.max_objects} objects; "
            "raise it with --max-objects",
        )
    header = list(dtype.names)
    _header_error(shown, header)
    for c in header:
        kind = dtype[c].kind
        if c in NUMBERS and kind not in "iuf":
            raise ScenarioError(shown, 1, header.index(c) + 1, f"column {c} must hold numbers")
        if c not in NUMBERS and kind not in "iufbUS":
            raise ScenarioError(shown, 1, header.index(c) + 1, f"column {c} must hold text")
    try:
        data = np.load(opened, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise ScenarioError(shown, 1, 1, f"not a .npy file numpy can read ({exc})") from None
    return data, _Place(shown, header, None)


# --- checking, column by column -----------------------------------------------------------------


def _words(data, name: str, default: str, lower: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """A text column as (its distinct values in order of first use, stripped (and lower-cased),
    as an array of str; each row's index into them); [default] for every row when the column is
    absent. Stripping and comparing run over the distinct values only."""
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
    words = []
    for u in first_seen:
        if isinstance(u, bytes):
            u = u.decode("utf-8", "replace")
        u = str(u).strip()
        words.append(u.lower() if lower else u)
    return np.array(words + [""])[:-1], inverse.reshape(-1)


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


def _check(data, place: _Place, width: int, height: int, fps: int, paper: bool) -> Table:
    n = data.shape[0]
    names = data.dtype.names
    problems: list[tuple[int, int, str, str]] = []  # (row, column index, column, message)

    def refuse(bad, column, message_of) -> None:
        r = _first(bad)
        if r is not None:
            problems.append((r, names.index(column), column, message_of(r)))

    def number(column, default=0.0) -> np.ndarray:
        if column not in names:
            return np.full(n, default)
        v = data[column].astype(np.float64)
        refuse(~np.isfinite(v), column, lambda r: f"must be a finite number, not {float(v[r])!r}")
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
    words, of = _words(data, "shape", "box")
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
    if problems:
        r, _, column, message = min(problems)
        raise place(r, column, message)
    names_out = (None,) * n
    if "name" in names:
        col = data["name"].tolist()
        names_out = tuple(
            (v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v)).strip() or None
            for v in col
        )
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


def _flag(data, column: str, refuse) -> np.ndarray:
    n = data.shape[0]
    if column in data.dtype.names and data[column].dtype.kind in "biuf":
        v = data[column].astype(np.float64)
        refuse((v != 0) & (v != 1), column, lambda r: f"must be true or false, not {v[r]!r}")
        return v != 0
    words, of = _words(data, column, "false")
    yes = np.isin(words, TRUE_WORDS)
    known = (yes | np.isin(words, FALSE_WORDS))[of]
    refuse(~known, column, lambda r: f"must be true or false, not {str(words[of[r]])!r}")
    return yes[of] if n else np.zeros(0, bool)


def _mass(data, static, refuse) -> np.ndarray:
    from collide2d.runner.objects import DEFAULT_MASS, MAX_MASS, MIN_MASS

    n = static.shape[0]
    if "mass" not in data.dtype.names:
        return np.full(n, DEFAULT_MASS)
    col = data["mass"]
    if col.dtype.kind in "iuf":
        given = np.ones(n, bool)
        mass = col.astype(np.float64)
    else:
        words, of = _words(data, "mass", "")
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
        lambda r: f"must be from {MIN_MASS:g} to {MAX_MASS:g}, not {mass[r]!r}",
    )
    return np.where(given, mass, DEFAULT_MASS)


def _colors(data, refuse) -> tuple[list, np.ndarray]:
    """The distinct colours in order of first use, and each row's index into them."""
    from collide2d.runner.objects import DEFAULT_COLOR

    n = data.shape[0]
    if "color" not in data.dtype.names:
        return [DEFAULT_COLOR], np.zeros(n, np.int64)
    words, of = _words(data, "color", "", lower=False)  # in order of first use
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
    (or absent). `reader` (a runner.nodes.Nodes) locates errors in the scenario itself."""
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
