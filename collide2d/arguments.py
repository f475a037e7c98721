"""The public API's arguments, checked as the command line checks its options.

Each function takes one argument of `collide2d.load`, `run` or `check` and gives it back as the
runner takes it (a numpy whole number as an int, a numpy boolean as a bool), or refuses it: a
TypeError for a value of the wrong type, a ValueError for one out of its range, the message
starting with the argument as given (`scale=0: must be at least 1`), as `collide2d run --scale 0`
refuses it (docs/reference/api.md). A range the scenario reader judges (`fps`, `ticks`) is left
to it, as the command line leaves it.

`scenario_text` writes a scenario given as a dict as the YAML text it stands for: numpy numbers,
arrays, tuples and other mappings are the numbers, lists and mappings YAML would give, and any
other value is a ScenarioError naming its place in the dict (`objects[1].velocity: ...`), located
in that text. A list or dict met twice is written once and referred to (a YAML alias), so the
reader's alias bound holds for it; one that holds itself, or nests past the reader's depth, is
refused there.

Importing this module costs only the standard library: a numpy value is recognised through
`sys.modules` (none exists before numpy is imported).
"""

from __future__ import annotations

import difflib
import operator
import os
import secrets
import sys
from collections.abc import Mapping, Sequence

# The words `run(frames=...)` takes besides frame numbers.
FRAME_WORDS = ("all", "last", "golden", "output")
_SHOWN_CHARS = 60  # characters of a value's repr in a message


def brief(value) -> str:
    """`repr(value)`, cut to _SHOWN_CHARS characters."""
    text = repr(value)
    return text if len(text) <= _SHOWN_CHARS else text[: _SHOWN_CHARS - 3] + "..."


def _numpy():
    return sys.modules.get("numpy")


def _integer(value) -> int | None:
    """`value` as an int when it is a whole number (an int or a numpy integer; not a bool, not a
    float), else None."""
    np = _numpy()
    if isinstance(value, bool) or (np is not None and isinstance(value, np.bool_)):
        return None
    try:
        return operator.index(value)
    except TypeError:
        return None


def whole(name: str, value, *, lo: int | None = None) -> int | None:
    """A whole-number argument (None: not given); below `lo` refused."""
    if value is None:
        return None
    number = _integer(value)
    if number is None:
        raise TypeError(f"{name}={brief(value)}: expected a whole number, not {_kind(value)}")
    if not _printable(number):
        raise ValueError(f"{name}: a whole number too long to write out is past every bound")
    if lo is not None and number < lo:
        raise ValueError(f"{name}={number}: must be at least {lo}")
    return number


def flag(name: str, value, *, none: bool = False) -> bool | None:
    """A True/False argument (a numpy boolean too); None too when `none` (the scenario's say)."""
    np = _numpy()
    if value is None and none:
        return None
    if isinstance(value, bool) or (np is not None and isinstance(value, np.bool_)):
        return bool(value)
    said = " (or None: as the scenario says)" if none else ""
    raise TypeError(f"{name}={brief(value)}: expected True or False{said}, not {_kind(value)}")


def model(value) -> str | None:
    """The `model` argument: a model's name (the reader judges whether it is one)."""
    if value is None or isinstance(value, str):
        return None if value is None else str(value)
    raise TypeError(f"model={brief(value)}: expected a model name (text), not {_kind(value)}")


def folder(name: str, value):
    """A folder argument (`out`, `root`, `report`): a str or os.PathLike naming one."""
    if value is None:
        return None
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name}={brief(value)}: expected a folder (str or os.PathLike)")
    if not os.fspath(value):
        raise ValueError(f"{name}={brief(value)}: names no folder")
    return value


def source(name: str, value):
    """A scenario to read: a file (str or os.PathLike) or a mapping (the scenario itself)."""
    if isinstance(value, (str, os.PathLike, Mapping)):
        return value
    raise TypeError(
        f"{name}={brief(value)}: expected a scenario file (str or os.PathLike) or the scenario "
        f"as a dict, not {_kind(value)}"
    )


def limits(value):
    """The `limits` argument: a collide2d.Limits."""
    from collide2d.runner.scenario.limits import Limits

    if value is None or isinstance(value, Limits):
        return value
    raise TypeError(f"limits={brief(value)}: expected a collide2d.Limits, not {_kind(value)}")


def defaults(value) -> dict | None:
    """The `defaults` argument: model settings under the rules of a project's
    `[tool.collide2d.model]` (docs/command-line.md)."""
    from collide2d.runner.command.settings import MODEL_CHOICES, MODEL_KEYS
    from collide2d.runner.scenario.load import MODEL_BOUNDS

    if value is None:
        return None
    if not isinstance(value, Mapping):
        raise TypeError(f"defaults={brief(value)}: expected a dict of model settings")
    out = {}
    for key, given in value.items():
        if key not in MODEL_KEYS:
            near = difflib.get_close_matches(str(key), MODEL_KEYS, n=1)
            hint = f"did you mean '{near[0]}'?" if near else "expected " + ", ".join(MODEL_KEYS)
            raise ValueError(f"defaults: no model setting {brief(key)}; {hint}")
        name = f"defaults[{key!r}]"
        if key in MODEL_CHOICES:
            if not isinstance(given, str) or given not in MODEL_CHOICES[key]:
                choices = " | ".join(MODEL_CHOICES[key])
                raise ValueError(f"{name}={brief(given)}: must be one of {choices}")
            out[key] = str(given)
            continue
        lo, hi = MODEL_BOUNDS[key]
        out[key] = whole(name, given, lo=lo)
        if hi is not None and out[key] > hi:
            raise ValueError(f"{name}={out[key]}: must be at most {hi}")
    return out


def overlay(value) -> tuple[str, ...] | None:
    """The `overlay` argument as `--overlay` takes it: names from OVERLAY_NAMES as a sequence or
    one comma-separated text, `none` (or an empty sequence) for none; in their fixed order."""
    from collide2d.runner.scenario.sections import OVERLAY_NAMES

    if value is None:
        return None
    if isinstance(value, str):
        names = [n.strip() for n in value.split(",") if n.strip()]
    elif _is_sequence(value) and all(isinstance(n, str) for n in _items(value)):
        names = [str(n).strip() for n in _items(value)]
    else:
        raise TypeError(
            f"overlay={brief(value)}: expected overlay names (a list of text, or one text "
            "separated by commas)"
        )
    if names == ["none"] or (not names and not isinstance(value, str)):
        return ()
    bad = [n for n in names if n not in OVERLAY_NAMES]
    if bad or not names:
        raise ValueError(
            f"overlay={brief(value)}: unknown overlay {', '.join(bad) or repr(value)}; choose "
            f"from {', '.join(OVERLAY_NAMES)} or none"
        )
    return tuple(n for n in OVERLAY_NAMES if n in names)


def frames(value) -> str | list[int] | None:
    """The `frames` argument of `run`: None, one of FRAME_WORDS, or whole frame numbers (their
    range is the run's, checked with it)."""
    if value is None:
        return None
    if isinstance(value, str):
        if value not in FRAME_WORDS:
            raise ValueError(
                f"frames={brief(value)}: expected frame numbers or one of {FRAME_WORDS}"
            )
        return value
    if not _is_sequence(value) and not _is_iterator(value):
        raise TypeError(
            f"frames={brief(value)}: expected frame numbers (a list of whole numbers) or one of "
            f"{FRAME_WORDS}, not {_kind(value)}"
        )
    numbers = []
    for k, item in enumerate(_items(value)):
        number = _integer(item)
        if number is None:
            raise TypeError(f"frames: item {k} ({brief(item)}) is not a whole number")
        numbers.append(number)
    return numbers


def scenarios(value) -> list | None:
    """The `scenarios` argument of `check`: one scenario (a Scenario, a file or a name, a dict) or
    a sequence of them, as a list; None: every scenario of the project."""
    from collide2d.runner.scenario.load import Scenario

    if value is None:
        return None
    one = (Scenario, str, os.PathLike, Mapping)
    expected = "expected a Scenario, a scenario file or name, or the scenario as a dict"
    if isinstance(value, one):
        return [value]
    if not (_is_sequence(value) or _is_iterator(value)):
        raise TypeError(f"scenarios={brief(value)}: {expected}, or a list of them")
    items = list(_items(value))
    for k, item in enumerate(items):
        if not isinstance(item, one):
            raise TypeError(f"scenarios[{k}]={brief(item)}: {expected}, not {_kind(item)}")
    if not items:
        raise ValueError(
            f"scenarios={brief(value)}: no scenario to check (None checks every scenario of the "
            "project)"
        )
    return items


# The arguments of `run` that only a run written to a folder takes, and their defaults.
WITH_OUT = {"png": None, "gif": None, "viewer": None, "overlay": None, "scale": 1, "quiet": True}


def with_out(out, given: dict) -> None:
    """Refuse an argument of `run` that is not for the run asked: one of WITH_OUT given to a run
    in memory (`out` None), `frames` to a run written to a folder. `given`: name -> (the value as
    given, as checked)."""
    if out is None:
        for name, default in WITH_OUT.items():
            value, checked = given[name]
            if checked != default:
                raise ValueError(
                    f"{name}={brief(value)}: applies to a run written to a folder (out=DIR); a "
                    "run in memory keeps the frames asked for by frames="
                )
    elif given["frames"][1] is not None:
        raise ValueError(
            f"frames={brief(given['frames'][0])}: frames are kept in memory only; with out=DIR, "
            "png=True writes them (the scenario's output.frames)"
        )


def _printable(number: int) -> bool:
    """Whether Python writes `number` out (at most sys.get_int_max_str_digits() digits), as
    every message that shows it does."""
    try:
        str(number)
    except ValueError:
        return False
    return True


def _kind(value) -> str:
    return type(value).__name__


def _is_sequence(value) -> bool:
    """A list, a tuple, a numpy array (of one dimension or more) or another Sequence; not text,
    not bytes."""
    np = _numpy()
    if np is not None and isinstance(value, np.ndarray):
        return value.ndim >= 1
    return isinstance(value, Sequence) and not isinstance(value, (str, bytes, bytearray))


def _is_iterator(value) -> bool:
    """A generator or another one-pass iterator (read once, into a list)."""
    return hasattr(value, "__next__") and hasattr(value, "__iter__")


def _items(value):
    np = _numpy()
    if np is not None and isinstance(value, np.ndarray):
        return value.tolist()
    return value


# --- a scenario dict as YAML text ---------------------------------------------------------------


def scenario_text(scenario: Mapping, path: str = "<string>") -> str:
    """The YAML text of the scenario `scenario` (a mapping), as the reader reads it under `path`;
    a ScenarioError at the first value YAML would not give, naming its place in the dict."""
    import yaml

    from collide2d.runner.scenario.parse import ScenarioError

    plain = _Plain()
    value = plain.value(scenario, "", 1)
    text = yaml.safe_dump(value, sort_keys=False, allow_unicode=True, default_flow_style=None)
    if plain.refused is not None:
        at = text.find(plain.marker)
        line = text.count("\n", 0, at) + 1
        col = at - text.rfind("\n", 0, at)
        raise ScenarioError(path, line, col, plain.refused)
    return text


class _Plain:
    """One conversion of a scenario dict into the plain values yaml.safe_dump writes: the first
    value refused is written as `marker` (to be found in the text) and its message kept."""

    def __init__(self):
        from collide2d.runner.scenario.parse import MAX_YAML_DEPTH

        self.depth = MAX_YAML_DEPTH
        self.np = _numpy()
        self.marker = "collide2d-refused-" + secrets.token_hex(8)
        self.refused: str | None = None
        self.done: dict = {}  # id -> (the value, its conversion): kept alive, so ids stay apart
        self.open: set = set()  # ids of the lists and mappings being converted

    def refuse(self, at: str, message: str):
        """What stands in the text for a refused value: the marker for the first."""
        if self.refused is not None:
            return None
        self.refused = f"{at or 'the scenario'}: {message}"
        return self.marker

    def value(self, value, at: str, depth: int):
        np = self.np
        if np is not None and isinstance(value, np.generic):
            value = value.item()  # a Python number, bool, text (or bytes, a date: refused)
        if value is None or isinstance(value, bool):
            return value
        if isinstance(value, int):
            if not _printable(value):  # YAML would hold its digits; the reader refuses >100
                return self.refuse(at, "a whole number too long to write out")
            return int(value)
        if isinstance(value, float):
            return float(value)
        if isinstance(value, str):
            return str(value)
        if isinstance(value, Mapping) or _is_sequence(value):
            return self.collection(value, at, depth)
        if np is not None and isinstance(value, np.ndarray):  # of no dimension: its one value
            return self.value(value.item(), at, depth)
        return self.refuse(
            at,
            "a scenario holds numbers, text, true/false, lists and mappings (as YAML gives "
            f"them), not {_kind(value)}",
        )

    def collection(self, value, at: str, depth: int):
        key = id(value)
        if key in self.open:
            return self.refuse(at, "the value holds itself")
        if key in self.done:
            return self.done[key][1]  # the same object: one YAML value, referred to again
        if depth > self.depth:
            return self.refuse(at, f"nested more than {self.depth} levels deep")
        self.open.add(key)
        if isinstance(value, Mapping):
            out = {}
            for k, item in value.items():
                name = self.key(k, at)
                shown = k if isinstance(k, str) else brief(k)
                out[name] = self.value(item, f"{at}.{shown}" if at else str(shown), depth + 1)
        else:
            items = enumerate(_items(value))
            out = [self.value(item, f"{at}[{i}]", depth + 1) for i, item in items]
        self.open.discard(key)
        self.done[key] = (value, out)
        return out

    def key(self, key, at: str):
        """A mapping's key as YAML writes it: text; a number, bool or None is left for the reader
        to refuse at its place; any other is refused here."""
        if self.np is not None and isinstance(key, self.np.generic):
            key = key.item()
        if isinstance(key, str):
            return str(key)
        if key is None or isinstance(key, (bool, int, float)):
            return key
        marker = self.refuse(at, f"keys are names (text), not {_kind(key)}")
        return marker if marker is not None else f"{self.marker}-{len(self.done)}-{id(key)}"
