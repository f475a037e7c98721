"""Typed, located reading of YAML nodes: a value of the expected kind, or a ScenarioError at it.

`runner.scenario.parse` turns text into a node tree within bounds; `Nodes` reads that tree one node
at a time and knows nothing of scenarios: a mapping (unknown keys refused with a did-you-mean,
repeated keys refused, `<<` merge keys as in YAML 1.1), a list, a single value, text, a boolean, a
number (finite; `-0.0` read as `0.0`), a whole number (a float with no fraction counts, as in JSON
Schema; at most MAX_INTEGER unless the field says less), a colour, an [x, y] pair and a choice among
names. Each refusal is `FILE:LINE:COL: error: MESSAGE` at the node it is about. The scenario's
section readers (`runner.scenario.load`, `runner.scenario.objects`, `runner.scenario.sections`)
extend `Nodes`.
"""

from __future__ import annotations

import difflib
import math

import numpy as np
import yaml

from collide2d.runner.scenario import colors, parse
from collide2d.runner.scenario.parse import ScenarioError

MAX_INTEGER = 2**63 - 1  # the largest whole number a field takes unless it has its own bound
MAX_ERRORS = 20  # errors of one file reported at once
# Keys users write for a key of the format, and why: said with the did-you-mean.
KEY_HINTS = {
    "radius": ("diameter", "a circle is given by its diameter in px, twice the radius"),
    **{
        word: ("restitution", "collide2d calls it restitution: 1 elastic, 0 no bounce")
        for word in ("elasticity", "bounce", "bounciness", "coefficient_of_restitution")
    },
}
# Keys of a physics collide2d does not have: said in place of a did-you-mean, which would point
# at an unrelated key ("rotation" is not "position").
_ROTATION = "collide2d has no rotation: objects keep their orientation and only move"
_DAMPING = (
    "collide2d has no damping: objects keep their velocity between contacts (friction acts in "
    "contacts, under model: stepped)"
)
NO_SUCH_PHYSICS = {
    **{
        word: _ROTATION
        for word in (
            "angle", "rotation", "orientation", "angular_velocity", "angular_speed", "spin",
            "omega", "torque", "inertia", "moment", "moment_of_inertia", "angular_damping",
        )
    },  # fmt: skip
    **{
        word: _DAMPING
        for word in ("damping", "linear_damping", "drag", "air_resistance", "air_friction")
    },
    "density": "collide2d has no density: give an object's mass (default 1)",
    "charge": "collide2d has no forces between objects: they meet only by contact",
}
# Keys of another section: where they belong (a model's settings, the world's keys).
_MODEL_SETTINGS = ("substeps", "geometry", "max_events_per_tick", "iterations", "slop",
                   "rest_speed", "sleep", "sleep_after", "rest_height")  # fmt: skip
ELSEWHERE = {
    **{key: "world" for key in ("width", "height", "fps", "background", "gravity")},
    **{key: "model" for key in _MODEL_SETTINGS},
}


def key_hint(key: str, keys: tuple[str, ...]) -> str:
    """What to say of the unknown `key` among `keys`: where it belongs, or that collide2d lacks
    its physics, or a did-you-mean, or the keys expected."""
    if key in KEY_HINTS and KEY_HINTS[key][0] in keys:
        return f"did you mean '{KEY_HINTS[key][0]}'? ({KEY_HINTS[key][1]})"
    if key in NO_SUCH_PHYSICS:
        return NO_SUCH_PHYSICS[key]
    section = ELSEWHERE.get(key)
    if section == "model" and "kind" not in keys:
        return f"{key} is a model setting: model: {{kind: ..., {key}: ...}}"
    if section == "world" and "width" not in keys:
        return f"{key} belongs to the world: world: {{{key}: ...}}"
    if key in ("restitution", "friction") and "kind" in keys:
        return f"{key} belongs to each object, or to world.{key} for the walls"
    near = difflib.get_close_matches(key, keys, n=1)
    return f"did you mean '{near[0]}'?" if near else "expected one of " + ", ".join(keys)


def is_number(v) -> bool:
    """Whether a read value is a number (booleans are not)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def fmt(v) -> str:
    """A number as a user would write it (1e+15 rather than 1000000000000000)."""
    if isinstance(v, float) and v.is_integer() and abs(v) < 1e15:
        return str(int(v))
    if isinstance(v, float) and abs(v) >= 1e15:
        return np.format_float_scientific(v, trim="-")
    return repr(v) if isinstance(v, float) else str(v)


class Errors:
    """The errors found so far in one file, reported together (up to MAX_ERRORS, in line order)."""

    def __init__(self):
        self.found: list[ScenarioError] = []
        self.stopped: ScenarioError | None = None  # raised once MAX_ERRORS were found

    def add(self, exc: ScenarioError) -> None:
        self.found.extend(exc.errors if isinstance(exc, parse.ScenarioErrors) else [exc])

    def full(self) -> bool:
        return len(self.found) >= MAX_ERRORS

    def error(self) -> ScenarioError | None:
        """The error to raise for what was found: the one, or all of them; None if none."""
        if not self.found:
            return None
        found = sorted(self.found, key=lambda e: (e.line, e.col))[:MAX_ERRORS]
        return found[0] if len(found) == 1 else parse.ScenarioErrors(found)


FAILED = object()  # what `Nodes.attempt` returns for a part that was refused


def _raise(exc: Exception):
    raise exc


class Nodes:
    """Located reading of the nodes of one file: `path` names it in every error.

    `errors`, when set to an Errors collector, makes `attempt` record a refused part and go on
    (so that one reading reports every error of a file); otherwise the first error is raised."""

    errors: Errors | None = None

    def __init__(self, path: str):
        self.path = str(path)

    def error(self, node, message: str) -> ScenarioError:
        if node is None and message.startswith("--"):  # caused by a command-line option
            return parse.OptionError(self.path, message)
        mark = node.start_mark if node is not None else None
        return parse.mark_error(self.path, mark, message)

    def attempt(self, read, *args):
        """read(*args), or FAILED after recording its error when collecting errors (raising all
        found so far once there are MAX_ERRORS)."""
        if self.errors is None:
            return read(*args)
        try:
            return read(*args)
        except ScenarioError as exc:
            if exc is self.errors.stopped:  # on its way out through the enclosing parts
                raise
            self.errors.add(exc)
            if self.errors.full():
                self.errors.stopped = self.errors.error()
                raise self.errors.stopped from None
            return FAILED

    def each(self, read, items) -> list:
        """[read(i, item) for each item], the refused ones left out when collecting errors."""
        out = [self.attempt(read, i, item) for i, item in enumerate(items)]
        return [x for x in out if x is not FAILED]

    @staticmethod
    def prefix(*origins) -> str:
        """The start of a message caused by command-line options ("--fps 3: "), or ""."""
        given = [o for o in origins if o]
        return " ".join(given) + ": " if given else ""

    def mapping(self, node, where: str, keys: tuple[str, ...], *, go_on: bool = False) -> dict:
        """{key: (key node, value node)} of a mapping; unknown and repeated keys refused, all of
        them at once (`go_on`, when collecting errors: recorded, and the other keys read)."""
        if not isinstance(node, yaml.MappingNode):
            raise self.error(
                node, f"{where} must be a mapping of keys to values, not {parse.describe(node)}"
            )
        out: dict[str, tuple] = {}
        merged = []
        refused = Errors()
        for knode, vnode in node.value:
            if isinstance(knode, yaml.ScalarNode) and knode.tag == parse.CORE_TAG + "merge":
                merged.append(vnode)
                continue
            if not isinstance(knode, yaml.ScalarNode) or not isinstance(parse.value(knode), str):
                shown = parse.describe(knode)
                raise self.error(knode, f"keys in {where} must be names, not {shown}")
            key = knode.value
            if key in out:
                first = out[key][0].start_mark.line + 1
                refused.add(
                    self.error(knode, f"duplicate key '{key}' in {where} (first on line {first})")
                )
                continue
            if key not in keys:
                hint = key_hint(key, keys)
                refused.add(self.error(knode, f"unknown key '{key}' in {where}; {hint}"))
                continue
            out[key] = (knode, vnode)
        if refused.found:
            if not (go_on and self.errors is not None):
                raise refused.error() if self.errors is not None else refused.found[0]
            for exc in refused.found:
                self.attempt(_raise, exc)
        for vnode in merged:
            sources = vnode.value if isinstance(vnode, yaml.SequenceNode) else [vnode]
            for src in sources:
                for key, item in self.mapping(src, where, keys).items():
                    out.setdefault(key, item)
        return out

    def seq(self, node, what: str, min_len: int = 0) -> list:
        if not isinstance(node, yaml.SequenceNode):
            raise self.error(node, f"{what} must be a list, not {parse.describe(node)}")
        if len(node.value) < min_len:
            raise self.error(node, f"{what} needs at least {min_len} items, not {len(node.value)}")
        return node.value

    def scalar(self, node, what: str):
        if not isinstance(node, yaml.ScalarNode):
            raise self.error(node, f"{what} must be a single value, not {parse.describe(node)}")
        return parse.value(node)

    def string(self, node, what: str) -> str:
        v = self.scalar(node, what)
        if not isinstance(v, str):
            raise self.error(node, f"{what} must be text, not {parse.describe(node)} (quote it)")
        return v

    def boolean(self, node, what: str) -> bool:
        v = self.scalar(node, what)
        if not isinstance(v, bool):
            raise self.error(node, f"{what} must be true or false, not {parse.describe(node)}")
        return v

    def number(self, node, what: str, *, lo=None, hi=None, lo_open=False, unit=""):
        """A finite int or float (ints kept exact) in [lo, hi] (or (lo, hi] with lo_open)."""
        v = self.scalar(node, what)
        if not is_number(v):
            raise self.error(node, f"{what} must be a number, not {parse.describe(node)}")
        if isinstance(v, float) and not math.isfinite(v):
            raise self.error(node, f"{what} must be a finite number, not {node.value}")
        if isinstance(v, int) and abs(v) > 1e300:
            raise self.error(node, f"{what} {node.value} is too large a number")
        if v == 0:
            v = v + 0  # -0.0 is read as 0.0
        if lo is not None and (v <= lo if lo_open else v < lo):
            bound = "more than" if lo_open else "at least"
            raise self.error(node, f"{what} must be {bound} {fmt(lo)}{unit}, not {fmt(v)}")
        if hi is not None and v > hi:
            raise self.error(node, f"{what} must be at most {fmt(hi)}{unit}, not {fmt(v)}")
        return v

    def integer(self, node, what: str, *, lo=None, hi=None, of="", unit="", past=None) -> int:
        """A whole number (a float with no fraction counts) in [lo, hi]; hi is MAX_INTEGER unless
        given, and a given lo is at least -MAX_INTEGER.

        `of` completes "a whole number" in messages (" of pixels"), `unit` follows the bounds;
        `past(shown)`, when given, says why a number above hi is refused (a limit and its option).
        """
        v = self.scalar(node, what)
        if isinstance(v, float) and math.isfinite(v) and v.is_integer():
            v = int(v)
        if not is_number(v) or not isinstance(v, int):
            raise self.error(node, f"{what} must be a whole number{of}, not {parse.describe(node)}")
        lo = -MAX_INTEGER if lo is None else lo
        hi = MAX_INTEGER if hi is None else hi
        shown = str(v) if len(str(v)) <= 24 else node.value  # 1e300 rather than its 301 digits
        if v < lo:
            raise self.error(node, f"{what} must be at least {lo}{unit}, not {shown}")
        if v > hi:
            said = f"{what} must be at most {hi}{unit}, not {shown}"
            raise self.error(node, past(shown) if past is not None else said)
        return v

    def color(self, node, what: str) -> tuple[int, int, int]:
        if isinstance(node, yaml.SequenceNode):
            items = node.value
            if len(items) != 3:
                raise self.error(
                    node, f"{what} as a list needs 3 values [r, g, b], not {len(items)}"
                )
            r, g, b = (self.integer(n, f"{what} component", lo=0, hi=255) for n in items)
            return (r, g, b)
        v = self.scalar(node, what)
        if not isinstance(v, str):
            raise self.error(
                node,
                f"{what} must be a colour name, #rrggbb or [r, g, b], not {parse.describe(node)}",
            )
        try:
            return colors.parse_color_text(v)
        except ValueError as exc:
            raise self.error(node, f"{what}: {exc}") from None

    def pair(self, node, what: str) -> tuple[list, list]:
        """([x node, y node], [x, y]) of a two-number list."""
        items = self.seq(node, what)
        if len(items) != 2:
            raise self.error(node, f"{what} must be a list of 2 numbers [x, y], not {len(items)}")
        values = [self.number(n, f"{what} {axis}") for n, axis in zip(items, "xy", strict=True)]
        return items, values

    def choice(self, node, what: str, options: tuple[str, ...], origin=None) -> str:
        v = self.scalar(node, what)
        if not isinstance(v, str) or v not in options:
            shown = f"'{v}'" if isinstance(v, str) else parse.describe(node)
            near = difflib.get_close_matches(v, options, n=1) if isinstance(v, str) else []
            hint = f"did you mean '{near[0]}'?" if near else "expected " + " | ".join(options)
            raise self.error(node, f"{self.prefix(origin)}unknown {what} {shown}; {hint}")
        return v
