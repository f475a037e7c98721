"""A model plugin's misbehaviour, told safely: what it raised, its values shown, its inputs copied.

A plugin is another package's code run inside collide2d (docs/how-to/plugins.md#when-a-plugin-
misbehaves). Whatever it raises, `sys.exit` and every other BaseException but Ctrl-C's
KeyboardInterrupt included, is its error, and telling it must not run more of its code that could
fail: `did` says what it did in one line (`called sys.exit(0) in advance() at tick 1`, `raised
ValueError when built: ...`), with `text` and `shown` as the str() and repr() of its objects that
never raise (`<str() failed>`). `runaway` remakes a Runaway it raised as a plain one whose message
and object ids are checked. `own_bodies` is the copy of the scene's Bodies a plugin is built with,
so that editing its arrays in place changes nothing collide2d draws or writes.

`protocol.Checked` and `engine.models.plugin_class` use these; nothing here imports a plugin.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from collide2d.engine.errors import Runaway
from collide2d.engine.world import Bodies, Looks

# The most characters of a plugin's own text (an exception's message, a value) shown in a line.
TEXT_CHARS = 300
SHOWN_CHARS = 80


def text(obj, limit: int = TEXT_CHARS) -> str:
    """str(obj) on one line, at most `limit` characters; "<str() failed>" when str() raises."""
    return _one_line(str, obj, limit)


def shown(obj, limit: int = SHOWN_CHARS) -> str:
    """repr(obj) on one line, at most `limit` characters; "<repr() failed>" when repr() raises."""
    return _one_line(repr, obj, limit)


def _one_line(say, obj, limit: int) -> str:
    """say(obj) (str or repr) on one line, at most `limit` characters, whatever it raises."""
    try:
        said = say(obj)
        if not isinstance(said, str):
            raise TypeError
        return " ".join(said[: limit * 4].split())[:limit]
    except KeyboardInterrupt:
        raise
    except BaseException:
        return f"<{say.__name__}() failed>"


def class_name(cls: type) -> str:
    """The name of class `cls`, read as `type` keeps it (never through a metaclass of its own)."""
    name = type.__dict__["__name__"].__get__(cls)
    return name if type(name) is str else "?"


def type_name(obj) -> str:
    """The name of obj's class (read from the class itself, never through obj)."""
    return class_name(type(obj))


def did(exc: BaseException, call: str) -> str:
    """What a plugin did in `call` ("in advance() at tick 1", "when built"): `called sys.exit(0)
    in advance() at tick 1`, `raised ValueError in positions() at tick 3: its message`."""
    if isinstance(exc, SystemExit):
        code = SystemExit.__dict__["code"].__get__(exc)  # never a subclass's own `code`
        return f"called sys.exit({'' if code is None else shown(code)}) {call}"
    detail = text(exc)
    return f"raised {type_name(exc)} {call}{': ' + detail if detail else ''}"


def runaway(exc: Runaway, n: int) -> Runaway:
    """A plain Runaway telling what the plugin's `exc` says, with its `objects` kept only when
    they are ids of the scene's n objects."""
    clean = Runaway(text(exc))
    try:
        ids = tuple(getattr(exc, "objects", ()))[:n]
        if all(type(i) is int or isinstance(i, np.integer) for i in ids) and all(
            0 <= int(i) < n for i in ids
        ):
            clean.objects = tuple(int(i) for i in ids)
    except KeyboardInterrupt:
        raise
    except BaseException:
        pass
    return clean


def own_bodies(bodies: Bodies) -> Bodies:
    """A copy of `bodies`, every array its own: what a plugin is built with."""

    def copied(record):
        return dataclasses.replace(
            record,
            **{
                f.name: np.array(getattr(record, f.name), copy=True)
                for f in dataclasses.fields(record)
                if isinstance(getattr(record, f.name), np.ndarray)
            },
        )

    looks: Looks = copied(bodies.looks)
    return dataclasses.replace(copied(bodies), looks=looks)
