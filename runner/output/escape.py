"""Text made safe for where it goes: a terminal, an XML file, a page's script, a spreadsheet cell,
a markdown table, a label drawn in a frame.

Names, file names and golden files are the user's text and may hold anything. Each output that
shows them passes them through one function here, so that none of them can break the output or
act on whoever reads it:

- `visible(text)`: control characters (C0 but tab and newline, DEL, C1), lone surrogates (a file
  name's undecodable bytes) and the non-characters U+FFFE / U+FFFF written as `\\x1b`,
  `\\udc80`-style escapes. What a terminal shows (`visible_streams` wraps stdout and stderr while a
  command runs) and what an XML file holds (XML 1.0 forbids most control characters even as
  character references, so they are spelled out instead).
- `script_json(data)`: JSON that cannot end or comment out the `<script>` element holding it:
  `<`, `>` and `&` as `\\u003c`, `\\u003e`, `\\u0026`, which JSON.parse reads back unchanged.
- `csv_cell(text)`: a text cell that a spreadsheet will not run as a formula: one starting with
  `=`, `+`, `-`, `@` or a tab gets a leading `'`, unless it is a plain number (`-12.5` stays a
  number); its control characters are `visible` (but tab and newline, which CSV quotes).
- `markdown_cell(text)`: `|` and `\\` escaped, control characters and line breaks made visible, so
  a cell stays one cell of one row.
- `one_line(text)`: `visible` with newlines and tabs spelled out too (a label, a heading).
"""

from __future__ import annotations

import contextlib
import json
import re
import sys
from collections.abc import Iterator

# Control characters (but tab and newline), lone surrogates, U+FFFE and U+FFFF.
_UNSAFE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")
_UNSAFE_LINE = re.compile("[\x00-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")
_NAMED = {"\r": "\\r", "\n": "\\n", "\t": "\\t"}
# A spreadsheet runs a cell starting with one of these as a formula (or an import, with a tab
# before it; a carriage return, the other such start, is spelled out by `visible`).
_FORMULA_START = ("=", "+", "-", "@", "\t")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
_SCRIPT = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026"}


def _spelled(match: re.Match) -> str:
    c = match.group()
    if c in _NAMED:
        return _NAMED[c]
    code = ord(c)
    if 0xDC80 <= code <= 0xDCFF:  # a byte the file system's encoding could not decode
        return f"\\x{code - 0xDC00:02x}"
    return f"\\x{code:02x}" if code <= 0xFF else f"\\u{code:04x}"


def visible(text: str) -> str:
    """`text` with control characters but tab and newline, lone surrogates and U+FFFE / U+FFFF
    spelled out as escapes (`\\x1b`, `\\r`, `\\x9b`, `\\xff` for an undecodable byte)."""
    return _UNSAFE.sub(_spelled, str(text))


def one_line(text: str) -> str:
    """`visible(text)` with newlines and tabs spelled out too: one line whatever the text."""
    return _UNSAFE_LINE.sub(_spelled, str(text))


def script_json(data) -> str:
    """Compact JSON of `data` that is safe inside a `<script>` element of an HTML page."""
    text = json.dumps(data, separators=(",", ":"))
    return re.sub("[<>&]", lambda m: _SCRIPT[m.group()], text)


def csv_cell(value):
    """A CSV cell of `value`: text is `visible` (a bare carriage return would split its row in
    many readers) and, when it starts a formula, gets a leading `'`; numbers (values that are
    not text, and text that is a plain number) are left as they are."""
    if not isinstance(value, str):
        return value
    value = visible(value)
    if not value.startswith(_FORMULA_START) or _NUMBER.fullmatch(value):
        return value
    return "'" + value


def markdown_cell(text) -> str:
    """`text` as one cell of a markdown table row."""
    return one_line(str(text)).replace("\\", "\\\\").replace("|", "\\|")


class VisibleStream:
    """A text stream writing `visible(text)` to `stream` (its `raw`); the rest is the stream's."""

    def __init__(self, stream):
        self.raw = stream

    def write(self, text: str) -> int:
        self.raw.write(visible(text))
        return len(text)

    def __getattr__(self, name):
        return getattr(self.raw, name)


def raw(stream):
    """The stream under a `VisibleStream` (`stream` itself otherwise): for a progress bar, which
    redraws its line with carriage returns of its own."""
    return stream.raw if isinstance(stream, VisibleStream) else stream


@contextlib.contextmanager
def visible_streams() -> Iterator[None]:
    """While open, whatever is printed to stdout and stderr goes through `visible`."""
    before = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = VisibleStream(before[0]), VisibleStream(before[1])
    try:
        yield
    finally:
        sys.stdout, sys.stderr = before
