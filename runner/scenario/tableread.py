"""A table's bytes to one structured array: the CSV and `.npy` readers of `runner.scenario.table`.

Both take the file's bytes, read once (`runner.scenario.parse.read_regular`), and give a numpy
structured array whose field names are the columns, with a `Place` that turns (row, column) into the
cell's place for a message. Nothing is parsed before the header has been checked and the row count
held against `--max-objects`.

CSV: UTF-8 text (an initial byte-order mark dropped; a byte that is not UTF-8, or a NUL, which
numpy's text would drop, refused at its line and column); lines end in LF, CRLF or CR alone (all
read as LF first, so the row count and every line number mean what an editor shows). The header
names the columns (read by Python's csv module, its field size limit raised to the line's length,
so a long name is an unknown column like any other). A line of spaces or tabs alone is a blank
line (docs/scenario-format.md) unless it lies inside a quoted field, and blank lines are skipped.
The rows are read by `numpy.loadtxt` in one pass, numbers as float64 and each text column as text
of its TEXT_CHARS width and one character more, so a longer cell is seen, never cut short in
silence (`runner.scenario.table` refuses it). A header with no rows is a table of no objects. When
numpy refuses a row, the cell is found again with the csv module (its field size limit raised to
the text's length for that reading, so a long cell is read like any other): a row of the wrong
length, or a number numpy does not read (`NUMBER_RE`: decimal, exponent, `inf`, `nan`; not
`1_000`, not `0x10`, not full-width digits). A quote that opens a field and is never closed would
take the rest of the file into that field, rows and all, and numpy reads that without a word: it
is refused where it opens (the last quoted field, `QUOTED_RE`, looked at whenever the text holds a
quote).

`.npy`: the header is read from the bytes first; a one-dimensional structured array of numbers
and text (no objects, so no pickles), whose rows at their item size must fill the rest of the file
exactly, before the array is made over those same bytes (no copy, nothing allocated from what the
header claims).
"""

from __future__ import annotations

import bisect
import codecs
import collections
import csv
import difflib
import io
import re
import threading

import numpy as np

from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.parse import ScenarioError
from collide2d.runner.scenario.rules import MAX_OBJECT_NAME_CHARS

COLUMNS = (
    "id", "shape", "w", "h", "x", "y", "vx", "vy", "mass", "color", "name", "static", "fill",
    "restitution", "friction",
)  # fmt: skip
REQUIRED = ("id", "shape", "w", "h", "x", "y")
NUMBERS = ("id", "w", "h", "x", "y", "vx", "vy", "restitution", "friction")
# Longest text a cell may hold, per text column (characters, as written); wider columns would cost
# memory for every row. A name's bound is the one every object name has (runner.scenario.rules).
TEXT_CHARS = {
    "shape": 16,
    "color": 40,
    "name": MAX_OBJECT_NAME_CHARS,
    "static": 8,
    "fill": 8,
    "mass": 100,
}
# A number as numpy.loadtxt reads one (surrounding whitespace aside).
NUMBER_RE = re.compile(
    r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf|infinity|nan)",
    re.IGNORECASE | re.ASCII,
)
# A quoted field as the csv module reads one: a quote where a field starts (at a line's start or
# after a comma: the look-behind follows the quote, so that a search jumps from quote to quote),
# then anything but a lone quote, then the closing quote, which group 1 lacks when the field runs
# to the end of the text. Scanned left to right, a match takes in the commas, line ends and quotes
# of its field, so the next match starts at a field of its own.
QUOTED_RE = re.compile(r'"(?<![^,\n]")[^"]*(?:""[^"]*)*("?)')
_SPACES_RE = re.compile(r"^[^\S\n]+$", re.MULTILINE)  # a line of spaces or tabs alone
_CSV_LIMIT = threading.Lock()  # the csv module's field size limit is one for the whole process


class Place:
    """Where a cell is, for messages: the CSV's line and character column (found by reading the
    text again, only when an error needs it) or the .npy's row and field number."""

    def __init__(self, shown: str, header: list[str], text: str | None):
        self.shown = shown
        self.header = header
        self.text = text

    def __call__(self, row: int, column: str, message: str, name=None) -> ScenarioError:
        """The error `message` at the cell of `row` (from 0) and `column`, the row named by the
        object's `name` when it has one: `row 4 (ball), column w: ...`."""
        col = self.header.index(column) if column in self.header else 0
        named = f" ({name})" if name else ""
        message = f"row {row + 1}{named}, column {column}: {message}" if column else message
        if self.text is None:  # .npy: row counted from 1, the field's number
            return ScenarioError(self.shown, row + 1, col + 1, message)
        line, char = _csv_cell(self.text, row, col)
        return ScenarioError(self.shown, line, char, message)


def header_error(shown: str, header: list[str], column_of) -> None:
    """Unknown, repeated and missing columns, at the header line; `column_of(i)` is the column
    of field i (from 0) in messages."""
    seen = set()
    for i, name in enumerate(header):
        if name not in COLUMNS:
            near = difflib.get_close_matches(name, COLUMNS, n=1)
            hint = f"did you mean '{near[0]}'?" if near else "expected " + ", ".join(COLUMNS)
            raise ScenarioError(shown, 1, column_of(i), f"unknown column {_cut(name)!r}; {hint}")
        if name in seen:
            raise ScenarioError(shown, 1, column_of(i), f"column {_cut(name)!r} appears twice")
        seen.add(name)
    missing = [c for c in REQUIRED if c not in seen]
    if missing:
        raise ScenarioError(
            shown,
            1,
            1,
            f"the table lacks the column(s) {', '.join(missing)} (header: id, shape, "
            "w, h, x, y and optionally vx, vy, mass, color, name, static, fill, restitution, "
            "friction)",
        )


def _too_many(shown: str, rows: int, limits: Limits) -> None:
    if rows > limits.max_objects:
        raise ScenarioError(
            shown,
            1,
            1,
            f"the table has {rows} rows, past the limit of {limits.max_objects} objects; "
            "raise it with --max-objects",
        )


# --- CSV ----------------------------------------------------------------------------------------


def read_csv(raw: bytes, shown: str, limits: Limits):
    """(structured array, Place) of the CSV table `raw`."""
    text = _decoded(raw, shown)
    rows = text.count("\n") + (0 if text.endswith("\n") else 1) - 1
    _too_many(shown, rows, limits)
    first, _, body = text.partition("\n")
    if not first.strip():
        said = "the table is empty; its first line names the columns"
        if body.strip():
            said = "the table's first line is blank; it must name the columns"
        raise ScenarioError(shown, 1, 1, said)
    if '"' in text:
        _refuse_unclosed(first, shown)  # the header is one line
        _refuse_unclosed(text, shown)
    header = [h.strip() for h in _fields(first)]
    header_error(shown, header, lambda i: _field_start(first, i))
    if _SPACES_RE.search(body):  # lines of spaces are blank lines, skipped as numpy skips ""
        text = _blank_spaces(text)
    place = Place(shown, header, text)
    dtype = [(c, "f8") if c in NUMBERS else (c, f"U{TEXT_CHARS[c] + 1}") for c in header]
    if not body.strip():  # a header alone: no objects (numpy would warn of no data)
        return np.zeros(0, dtype), place
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


def _decoded(raw: bytes, shown: str) -> str:
    """The table's text, its line ends made LF; a byte that is not UTF-8 refused at its line and
    column (the characters before it on its line, counted)."""
    raw = raw.removeprefix(codecs.BOM_UTF8)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        at = exc.start
        line = raw.count(b"\n", 0, at) + raw.count(b"\r", 0, at) - raw.count(b"\r\n", 0, at) + 1
        start = max(raw.rfind(b"\n", 0, at), raw.rfind(b"\r", 0, at)) + 1
        before = raw[start:at].decode("utf-8", "replace")
        raise ScenarioError(shown, line, len(before) + 1, "the table is not UTF-8 text") from None
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    if "\x00" in text:  # numpy's text drops a trailing NUL: a cell would change unseen
        at = text.index("\x00")
        line, col = text.count("\n", 0, at) + 1, at - text.rfind("\n", 0, at)
        raise ScenarioError(shown, line, col, "the table holds a NUL character; it must be text")
    return text


def _fields(line: str) -> list[str]:
    """The fields of one CSV line, a field of any length read (the csv module's limit raised)."""
    with _CSV_LIMIT:
        old = csv.field_size_limit()
        csv.field_size_limit(max(old, len(line) + 1))
        try:
            return next(csv.reader([line]), [])
        finally:
            csv.field_size_limit(old)


def _refuse_unclosed(text: str, shown: str) -> None:
    """A ScenarioError where a quoted field of `text` opens and is never closed: the last quoted
    field (QUOTED_RE), when it runs to the end."""
    last = collections.deque(QUOTED_RE.finditer(text), maxlen=1)
    if last and not last[0][1]:
        at = last[0].start()
        line = text.count("\n", 0, at) + 1
        col = at - text.rfind("\n", 0, at)
        message = 'a quoted field opens here and is never closed (a " is missing)'
        raise ScenarioError(shown, line, col, message)


def _blank_spaces(text: str) -> str:
    """`text` with each line of spaces made empty, but for a line inside a quoted field."""
    inside = [m.span() for m in QUOTED_RE.finditer(text) if "\n" in m[0]] if '"' in text else []
    starts = [a for a, _ in inside]

    def blank(m: re.Match) -> str:
        k = bisect.bisect_right(starts, m.start()) - 1
        return m[0] if k >= 0 and m.start() < inside[k][1] else ""

    return _SPACES_RE.sub(blank, text)


def _records(text: str) -> list[tuple[int, int, list[str]]]:
    """(data row from 0, its first line from 1, fields) of each CSV record after the header, blank
    lines skipped as numpy.loadtxt skips them. A cell of any length is read: the csv module's field
    limit is raised to the text's length while it reads."""
    out = []
    with _CSV_LIMIT:
        old = csv.field_size_limit()
        csv.field_size_limit(max(old, len(text) + 1))
        try:
            reader = csv.reader(io.StringIO(text))
            next(reader, None)
            k = -1
            start = reader.line_num + 1
            for record in reader:
                if record:  # an empty line is none (a line of spaces was made one)
                    k += 1
                    out.append((k, start, record))
                start = reader.line_num + 1
        finally:
            csv.field_size_limit(old)
    return out


def _csv_cell(text: str, row: int, col: int) -> tuple[int, int]:
    """(line, character column) of field `col` of data row `row` (blank lines skipped, as
    numpy.loadtxt skips them), both from 1."""
    for k, line, _record in _records(text):
        if k == row:
            return line, _field_start(text.split("\n", line)[line - 1], col)
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


def _first_bad_cell(text: str, header: list[str], place: Place) -> ScenarioError:
    """The error numpy met, found again cell by cell: a row of the wrong length or a number that
    is not one."""
    for k, line, record in _records(text):
        if len(record) != len(header):
            return ScenarioError(
                place.shown,
                line,
                1,
                f"row {k + 1} has {len(record)} fields; the header names {len(header)}",
            )
        for c, name in enumerate(header):
            if name in NUMBERS and not NUMBER_RE.fullmatch(record[c].strip()):
                return place(k, name, f"must be a number, not {_cut(record[c].strip())!r}")
    return ScenarioError(place.shown, 1, 1, "the table cannot be read as CSV")


def _cut(text: str, chars: int = 40) -> str:
    """`text`, or its first `chars` characters and an ellipsis."""
    return text if len(text) <= chars else text[:chars] + "…"


# --- .npy ---------------------------------------------------------------------------------------


def read_npy(raw: bytes, shown: str, limits: Limits):
    """(structured array, Place) of the .npy table `raw`: the array is made over these bytes."""
    f = io.BytesIO(raw)
    try:
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            shape, _fortran, dtype = np.lib.format.read_array_header_1_0(f)
        else:
            shape, _fortran, dtype = np.lib.format.read_array_header_2_0(f)
    except (ValueError, EOFError) as exc:
        raise ScenarioError(shown, 1, 1, f"not a .npy file numpy can read ({exc})") from None
    if dtype.names is None or len(shape) != 1:
        raise ScenarioError(
            shown,
            1,
            1,
            "a .npy table holds a one-dimensional structured array whose field "
            "names are the columns",
        )
    _too_many(shown, shape[0], limits)
    header = list(dtype.names)
    header_error(shown, header, lambda i: i + 1)  # the field's number
    for c in header:
        kind = dtype[c].kind
        if c in NUMBERS and kind not in "iuf":
            raise ScenarioError(shown, 1, header.index(c) + 1, f"column {c} must hold numbers")
        if c not in NUMBERS and kind not in "iufbUS":
            raise ScenarioError(shown, 1, header.index(c) + 1, f"column {c} must hold text")
    start = f.tell()
    need = shape[0] * dtype.itemsize
    if len(raw) - start != need:
        raise ScenarioError(
            shown,
            1,
            1,
            f"not a whole .npy file: its header claims {shape[0]:,} row(s) of "
            f"{dtype.itemsize:,} bytes ({need:,} bytes), the file holds {len(raw) - start:,} "
            "bytes after the header",
        )
    data = np.frombuffer(raw, dtype=dtype, count=shape[0], offset=start)
    return data, Place(shown, header, None)
