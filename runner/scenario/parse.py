"""Reading scenario YAML safely: a file in, a located node tree out, or a located ScenarioError.

A file a user named (a scenario, a sweep file, a table: `read_regular`) is read whole into memory,
so only a regular file is read: a FIFO, a device, a socket or a folder is refused at once, never
waited on (a FIFO opened for reading waits for a writer, a device may stream without end). The file
is opened without blocking and judged on the open descriptor, so what is checked is what is read,
even if the name is swapped in between. At most `limit` bytes are read, in pieces, so a file that
grows while it is read stops at the bound too. Every refusal is a `ScenarioError` at the file's
first line, naming what the file is.

The text is streamed as YAML events first (iteratively, so no nesting can exhaust a stack): nesting
deeper than MAX_YAML_DEPTH, a second document, a tag outside the plain core types (`!!python/...`
and the like) and aliases are checked there; every alias adds the size of the node it repeats to a
count, and past `limits.max_alias_nodes` the file is refused at that alias, so a "billion laughs"
file costs no more than its own length; the file's size (`limits.max_file_bytes`, checked while it
is read) and its count of values (`limits.max_yaml_nodes`, before any is built) bound the memory of
the next step. A number longer than MAX_NUMBER_CHARS characters is refused there too, before
anything converts it: Python's `int()` refuses more than 4,300 digits, YAML 1.1's sexagesimal
integers (`190:20:30`) cost time quadratic in their length, and no field needs so long a number. A
long scalar counts as a number when it is tagged `!!int` or `!!float`, or is plain and looks like
one (`_NUMBER_LIKE_RE`, a superset of YAML 1.1's forms and of the exponent form `1e3`, checked in
linear time); every other long plain scalar is text, and YAML's number patterns are never tried on
it (see `_composing`). So every number is read at a cost linear in its text, and every integer a
scenario holds is below 16**98 (about 1e118), far inside float64's range. Then `yaml.compose` with
the safe loader (libyaml's when available) builds the node tree that the scenario readers walk by
hand (`runner.scenario.nodes`, typed and located, under `runner.scenario.load`). `value` and
`describe` read scalar nodes for them; a plain scalar YAML takes for an integer but that makes none
(`0x_`: its digits are all underscores) is read as its text.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import stat

import yaml

from collide2d.runner.scenario.limits import Limits

MAX_YAML_DEPTH = 64  # nesting levels of YAML collections
MAX_SHOWN_CHARS = 40  # characters of a text quoted in a message
MAX_NUMBER_CHARS = 100  # characters of one number as written (signs, underscores, colons included)
CORE_TAG = "tag:yaml.org,2002:"
READ_CHUNK_BYTES = 2**20  # a file is read in pieces of this many bytes
_O_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_O_BINARY = getattr(os, "O_BINARY", 0)
_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)

_FLOAT12_RE = re.compile(r"[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)[eE][-+]?[0-9]+\Z")
_ALLOWED_TAGS = {CORE_TAG + t for t in ("str", "int", "float", "bool", "null", "seq", "map")}
_CONSTRUCTED_TAGS = {CORE_TAG + t for t in ("int", "float", "bool")}  # a tagged text may not fit
_NUMBER_TAGS = {CORE_TAG + "int", CORE_TAG + "float"}
_CONSTRUCTOR = yaml.constructor.SafeConstructor()
# What a long plain scalar must look like to be taken for a number: a superset of YAML 1.1's
# integers and floats and of the exponent form, matched in time linear in the text and constant
# memory (one character class repeated, nothing to backtrack into).
_NUMBER_LIKE_RE = re.compile(r"[-+]?\.?[0-9][0-9a-fA-Fxob_:.+-]*\Z")


_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


@functools.cache
def _composing(loader: type) -> type:
    """`loader` taking every plain scalar longer than MAX_NUMBER_CHARS for text without trying
    YAML's number patterns on it: the event pass has refused those that look like numbers, and the
    patterns for sexagesimal numbers keep memory per repetition (tens of bytes per character of a
    text such as `1:59:59:...:59 x`)."""

    class Composing(loader):
        def resolve(self, kind, value, implicit):
            if kind is yaml.ScalarNode and implicit[0] and len(value) > MAX_NUMBER_CHARS:
                return CORE_TAG + "str"
            return super().resolve(kind, value, implicit)

    return Composing


class ScenarioError(Exception):
    """A scenario refused, located: str(err) == f"{path}:{line}:{col}: error: {message}"."""

    def __init__(self, path, line, col, message):
        super().__init__(str(path), int(line), int(col), str(message))
        self.path = str(path)
        self.line = int(line)
        self.col = int(col)
        self.message = str(message)

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.col}: error: {self.message}"


class OptionError(ScenarioError):
    """A refusal caused by a command-line option, not by a place in the file: str(err) is
    f"{path}: error: {message}", the message starting with the option (`--ticks 5: ...`)."""

    def __init__(self, path, message):
        super().__init__(path, 0, 0, message)

    def __str__(self) -> str:
        return f"{self.path}: error: {self.message}"


class ScenarioErrors(ScenarioError):
    """Several errors of one file, in line order (`errors`); str(err) is one line each. As a
    ScenarioError it is the first of them."""

    def __init__(self, errors: list[ScenarioError]):
        first = errors[0]
        super().__init__(first.path, first.line, first.col, first.message)
        self.errors = list(errors)

    def __str__(self) -> str:
        return "\n".join(str(e) for e in self.errors)


def read_file(path, limits: Limits) -> tuple[str, str]:
    """(text, SHA-256 of the bytes) of the file at `path`: a regular file of at most
    `limits.max_file_bytes` (`read_regular`); a located ScenarioError when it cannot be
    read or is not UTF-8."""
    shown = os.fspath(path)
    data = read_regular(path, limits.max_file_bytes, shown)
    return decode(data, shown), hashlib.sha256(data).hexdigest()


def kind_of(mode: int) -> str:
    """What a file of stat mode `mode` is, in words ("a FIFO (named pipe)", ...)."""
    for test, words in _KINDS:
        if test(mode):
            return words
    return "not a regular file"


def read_regular(path, limit: int, shown: str, what: str = "file") -> bytes:
    """The bytes of the regular file at `path` (named `shown` in messages, `what` in words: "file",
    "table"), at most `limit` of them; a ScenarioError at `shown`:1:1 when it cannot be opened, is
    not a regular file, or holds more than `limit` bytes."""
    try:
        fd = os.open(path, os.O_RDONLY | _O_NONBLOCK | _O_BINARY)
    except OSError as exc:
        raise ScenarioError(shown, 1, 1, f"cannot read the {what}: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        mode = st.st_mode
        if not stat.S_ISREG(mode):
            raise ScenarioError(
                shown, 1, 1, f"cannot read the {what}: it is {kind_of(mode)}, not a regular file"
            )
        chunks: list[bytes] = []
        size = 0
        want = min(st.st_size, limit) + 1  # the whole file at once, and one byte to see it grew
        while chunk := os.read(fd, want):  # then in pieces: a growing file stops at the limit
            size += len(chunk)
            if size > limit:
                raise ScenarioError(
                    shown,
                    1,
                    1,
                    f"the {what} is larger than the limit of {limit:,} bytes; "
                    "raise it with --max-file-bytes",
                )
            chunks.append(chunk)
            want = READ_CHUNK_BYTES
    except OSError as exc:
        raise ScenarioError(shown, 1, 1, f"cannot read the {what}: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    return b"".join(chunks)


def check_length(length: int, path: str, limits: Limits) -> None:
    if length > limits.max_file_bytes:
        raise ScenarioError(
            path,
            1,
            1,
            f"the file is larger than the limit of {limits.max_file_bytes:,} bytes; "
            "raise it with --max-file-bytes",
        )


def decode(data: bytes, path: str) -> str:
    """The file's text (UTF-8, an initial byte-order mark dropped); a located error otherwise."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        start = exc.start
        line = data.count(b"\n", 0, start) + 1
        line_start = data.rfind(b"\n", 0, start) + 1
        col = len(data[line_start:start].decode("utf-8", "replace")) + 1
        if line_start == 0 and data.startswith(b"\xef\xbb\xbf"):
            col -= 1
        raise ScenarioError(
            path, line, col, f"the file is not UTF-8 text (byte 0x{data[start]:02x} here)"
        ) from None


def mark_error(path: str, mark, message: str) -> ScenarioError:
    if mark is None:
        return ScenarioError(path, 1, 1, message)
    return ScenarioError(path, mark.line + 1, mark.column + 1, message)


def _yaml_error(exc: yaml.YAMLError, path: str, text: str) -> ScenarioError:
    """A PyYAML error as a located ScenarioError."""
    if isinstance(exc, yaml.reader.ReaderError):
        index = text.find(chr(exc.character)) if isinstance(exc.character, int) else -1
        index = exc.position if index < 0 else index
        line = text.count("\n", 0, index) + 1
        col = index - (text.rfind("\n", 0, index) + 1) + 1
        char = exc.character if isinstance(exc.character, int) else 0
        return ScenarioError(path, line, col, f"invalid character U+{char:04X} in YAML text")
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        problem = exc.problem or "unexpected text"
        if mark is not None and 0 <= mark.index < len(text) and text[mark.index] == "\t":
            start = text.rfind("\n", 0, mark.index) + 1
            where = "in the indentation" if not text[start : mark.index].strip() else "here"
            return mark_error(
                path,
                mark,
                f"a tab character {where}: YAML indents with spaces only; replace the tab "
                "with spaces (2 per level is usual)",
            )
        context = f" ({exc.context})" if exc.context else ""
        return mark_error(path, mark, f"invalid YAML{context}: {problem}")
    return ScenarioError(path, 1, 1, f"invalid YAML: {exc}")


def _tag_name(tag: str) -> str:
    return "!!" + tag[len(CORE_TAG) :] if tag.startswith(CORE_TAG) else tag


def _check_events(text: str, path: str, limits: Limits) -> None:
    """Stream the YAML events once: depth, one document, plain tags, and the alias bound.

    The fast parser (libyaml's, when PyYAML has it) reads ahead of the events it hands out and
    may hold limits of its own (PyYAML 6.0.4's libyaml stops at 1,000 flow levels, found while
    reading ahead of our 65th). So when it fails, the same pass runs again with PyYAML's pure
    Python parser, which has no limit of its own: our bounds decide wherever they are passed
    first, and a file that is invalid YAML is reported in the same words with or without libyaml.
    Only refused files pay for the second pass, which stops at the first problem it meets.
    """
    try:
        _stream_events(text, path, limits, _LOADER)
    except yaml.YAMLError as exc:
        if _LOADER is yaml.SafeLoader:
            raise _yaml_error(exc, path, text) from None
        try:
            _stream_events(text, path, limits, yaml.SafeLoader)
        except yaml.YAMLError as pure:
            raise _yaml_error(pure, path, text) from None
        raise _yaml_error(exc, path, text) from None


def _stream_events(text: str, path: str, limits: Limits, loader) -> None:
    """The checks of `_check_events` over the events of one parser; YAMLError passes through."""
    sizes: dict[str, int] = {}  # anchor -> nodes in the node it names, aliases expanded
    stack: list[list] = []  # per open collection: [nodes so far, anchor]
    repeated = 0  # nodes reached again through aliases
    nodes = 0  # nodes written out in the text
    documents = 0

    def add(n: int) -> None:
        if stack:
            stack[-1][0] += n

    for ev in yaml.parse(text, Loader=loader):
        if isinstance(ev, yaml.DocumentStartEvent):
            documents += 1
            if documents > 1:
                raise mark_error(
                    path,
                    ev.start_mark,
                    "a scenario file holds one YAML document; this is a second one",
                )
        elif isinstance(ev, yaml.AliasEvent):
            n = sizes.get(ev.anchor)
            if n is None:
                inside = any(entry[1] == ev.anchor for entry in stack)
                what = "refers to a node that contains it" if inside else "has no anchor"
                raise mark_error(path, ev.start_mark, f"alias '*{ev.anchor}' {what}")
            repeated += n
            if repeated > limits.max_alias_nodes:
                raise mark_error(
                    path,
                    ev.start_mark,
                    f"aliases repeat more than {limits.max_alias_nodes} YAML nodes "
                    f"(alias '*{ev.anchor}' repeats {n}); refusing to expand them",
                )
            add(n)
        elif isinstance(ev, yaml.NodeEvent) and not isinstance(ev, yaml.CollectionEndEvent):
            tag = getattr(ev, "tag", None)
            nodes += 1
            if nodes > limits.max_yaml_nodes:
                raise mark_error(
                    path,
                    ev.start_mark,
                    f"the file holds more than {limits.max_yaml_nodes:,} YAML values, the "
                    "limit; raise it with --max-yaml-nodes",
                )
            if tag is not None and tag not in _ALLOWED_TAGS:
                raise mark_error(
                    path,
                    ev.start_mark,
                    f"YAML tag '{_tag_name(tag)}' is not "
                    "allowed; a scenario holds plain values only",
                )
            if isinstance(ev, yaml.ScalarEvent):
                if len(ev.value) > MAX_NUMBER_CHARS and _is_number(ev):
                    raise mark_error(
                        path,
                        ev.start_mark,
                        f"this number is {len(ev.value):,} characters long; a number in a "
                        f"scenario has at most {MAX_NUMBER_CHARS} (quote it if it is text)",
                    )
                if tag in _CONSTRUCTED_TAGS:
                    _check_tagged(ev, tag, path)
                if ev.anchor is not None:
                    sizes[ev.anchor] = 1
                add(1)
            else:
                stack.append([1, ev.anchor])
                if len(stack) > MAX_YAML_DEPTH:
                    raise mark_error(
                        path,
                        ev.start_mark,
                        f"YAML nested more than {MAX_YAML_DEPTH} levels deep",
                    )
        elif isinstance(ev, yaml.CollectionEndEvent):
            n, anchor = stack.pop()
            if anchor is not None:
                sizes[anchor] = n
            add(n)


def _is_number(ev: yaml.ScalarEvent) -> bool:
    """Whether a scalar longer than MAX_NUMBER_CHARS is a number: tagged as an int or a float, or
    plain and looking like one (_NUMBER_LIKE_RE)."""
    if ev.tag is None or ev.tag == "!":
        return ev.implicit[0] and _NUMBER_LIKE_RE.match(ev.value) is not None
    return ev.tag in _NUMBER_TAGS


def _check_tagged(ev, tag: str, path: str) -> None:
    """A scalar with an explicit `!!int`, `!!float` or `!!bool` tag must be such a value."""
    try:
        _construct(yaml.ScalarNode(tag, ev.value, style=ev.style))
    except (ValueError, KeyError, IndexError, TypeError):
        raise mark_error(
            path, ev.start_mark, f"{ev.value!r} is not a valid {_tag_name(tag)} value"
        ) from None


def compose(text: str, path: str, limits: Limits) -> yaml.Node:
    _check_events(text, path, limits)
    try:
        root = yaml.compose(text, Loader=_composing(_LOADER))
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, path, text) from None
    if root is None:
        raise ScenarioError(path, 1, 1, "the file is empty; a scenario starts with 'version: 1'")
    return root


def plain(node) -> bool:
    return node.style in (None, "")


def value(node):
    """The Python value of a scalar node (str, int, float, bool or None).

    A scalar tagged as a number or a boolean whose text makes none is read as its text; the event
    pass of `compose` has refused such a text when the tag was written out.
    """
    try:
        return _construct(node)
    except (ValueError, KeyError, IndexError, TypeError):
        return node.value


def _construct(node):
    tag = node.tag
    if tag == CORE_TAG + "int":
        return _CONSTRUCTOR.construct_yaml_int(node)
    if tag == CORE_TAG + "float":
        return _CONSTRUCTOR.construct_yaml_float(node)
    if tag == CORE_TAG + "bool":
        return _CONSTRUCTOR.construct_yaml_bool(node)
    if tag == CORE_TAG + "null":
        return None
    if (
        tag == CORE_TAG + "str"
        and plain(node)
        and len(node.value) <= MAX_NUMBER_CHARS  # longer ones are text (see _composing)
        and _FLOAT12_RE.match(node.value)
    ):
        return float(node.value)
    return node.value  # str, and timestamps, "=" and "<<" read as their text


def describe(node) -> str:
    """A few words naming what a node holds, for messages."""
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    v = value(node)
    if v is None:
        return "an empty value"
    if isinstance(v, bool):
        return f"the boolean {node.value}"
    if isinstance(v, (int, float)):
        return f"{node.value}"
    if len(v) > MAX_SHOWN_CHARS:  # a long text is shown by its start and its length
        return f"the text {v[:MAX_SHOWN_CHARS]!r}... ({len(v):,} characters)"
    return f"the text {v!r}"
