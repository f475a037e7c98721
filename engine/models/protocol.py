"""The model protocol: what every model meets, built-in or plugin (docs/how-to/plugins.md).

A model is a class built as `Model(world, bodies, **options)` from the scenario's `WorldSpec`
and `Bodies` (`engine.world`) and the model options it takes, with:

    tick                  int, ticks run so far (0 when built)
    advance(ticks, log)   run that many ticks (>= 1); returns the events of those ticks as an
                          `engine.events.EVENT_DTYPE` array in the order they happened (tick
                          non-decreasing, within a tick `t` non-decreasing; walls: `a` the
                          object, `b` -1, `code` a SIDE_*; pairs: a < b, `code` an AXIS_*);
                          empty when `log` is False
    positions()           (n, 2) float64, every object's top-left corner now, px
    velocities()          (n, 2) float64, every object's velocity now, px/s
    event_counts()        (wall events, pair events) so far, counted whether logged or not

and, for a plugin, two class attributes saying what it supports: `SHAPES`, the object shapes it
takes (of `engine.world.KIND_NAMES`; default all), and `OPTIONS`, the scenario's model settings
it takes as keyword arguments (of `PLUGIN_OPTIONS`; default none). The results must not depend
on how the ticks are split among calls (the runner advances in chunks of its own choosing), and
the same scene must give the same bytes. A model that cannot carry a scene on raises
`engine.errors.Runaway` (the run stops with its message).

The built-in models meet this by construction. A plugin is held to it at run time: `Checked`
wraps it, builds it from its own copy of the bodies, and checks every answer, made collide2d's own
copy first (shapes, dtypes, finite numbers, positions within a world's size of the world, event
order and ids, no events with the log off, event counts that agree with the events, ticks
advanced); anything else it does wrong, or anything it raises (`sys.exit` and every other
BaseException but Ctrl-C's KeyboardInterrupt), becomes a `ModelError` naming the model and the
call (`guard`). `collide2d.testing.check_model` runs the whole conformance kit on a model.
"""

from __future__ import annotations

import itertools
from typing import Protocol, runtime_checkable

import numpy as np

import collide2d.engine.models.guard as guard
from collide2d.engine.errors import Runaway
from collide2d.engine.events import AXIS_NAMES, EV_PAIR, EV_WALL, EVENT_DTYPE, SIDE_NAMES
from collide2d.engine.world import Bodies, WorldSpec

# The scenario's model settings a plugin may take (its `OPTIONS`): the shape geometry.
PLUGIN_OPTIONS = ("geometry",)
# How far past its tick's end an event's time may be, s: rounding in a model's own time sums.
TIME_SLACK_S = 1e-9


@runtime_checkable
class Model(Protocol):
    """The surface of a model (see the module docstring for the contract of each member)."""

    tick: int

    def advance(self, ticks: int, log: bool = True) -> np.ndarray: ...

    def positions(self) -> np.ndarray: ...

    def velocities(self) -> np.ndarray: ...

    def event_counts(self) -> tuple[int, int]: ...


class ModelError(Exception):
    """A model plugin raised, or broke the model protocol; `str(err)` names the model and says
    what it did. `model` is its name."""

    def __init__(self, model: str, message: str):
        super().__init__(f"the model '{model}' {message}")
        self.model = model
        self.said = message

    def __reduce__(self):  # whole across processes (a check's runs on Dask workers)
        return type(self), (self.model, self.said)


class Checked:
    """A plugin model, every answer checked against the protocol (`ModelError` otherwise).

    Built as `Checked(name, factory, world, bodies, options)`: `factory(world, bodies,
    **options)` builds the plugin from its own copy of `bodies` (`guard.own_bodies`). Whatever
    the plugin raises in any call, `sys.exit` and every BaseException but KeyboardInterrupt
    included, becomes a `ModelError` saying what it did and in which call; a Runaway it raises
    passes on as a plain `Runaway` (`guard.runaway`). Every answer is made collide2d's own copy
    before it is checked, so nothing the plugin does later changes it."""

    def __init__(self, name: str, factory, world: WorldSpec, bodies: Bodies, options: dict):
        self.name = name
        self.world = world
        self.n = bodies.n
        self._size = np.array(bodies.size, np.float64)
        self._logged = (0, 0)  # the wall and pair events it returned so far
        self._all_logged = True  # every advance so far had the log on
        self._counted = (0, 0)  # what event_counts() said last
        mine = guard.own_bodies(bodies)
        self._inner = self._call("when built", factory, world, mine, **dict(options))
        self.tick = self._tick("after it was built")
        if self.tick != 0:
            raise ModelError(name, f"starts at tick {self.tick}, not 0")

    def _call(self, call: str, fn, *args, **kwargs):
        """fn(*args, **kwargs), the plugin's code: what it raises is told as its doing in `call`
        ("in advance() at tick 1"); KeyboardInterrupt (Ctrl-C) passes through as it is."""
        try:
            return fn(*args, **kwargs)
        except KeyboardInterrupt:
            raise
        except Runaway as exc:
            raise guard.runaway(exc, self.n) from exc
        except BaseException as exc:
            if type(exc) is ModelError:  # a Checked's own, of a model wrapped twice
                raise
            raise ModelError(self.name, guard.did(exc, call)) from exc

    def _tick(self, after: str) -> int:
        tick, shown = self._call(f"when its tick was read {after}", _whole, self._inner, "tick")
        if tick is None:
            raise ModelError(self.name, f"has a tick that is not a whole number: {shown}")
        return tick

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        before = self.tick
        where = f"at ticks {before + 1}-{before + ticks}" if ticks > 1 else f"at tick {before + 1}"
        events = self._call(f"in advance() {where}", _answer, self._inner, "advance", ticks, log)
        self.tick = self._tick(f"after advance() {where}")
        if self.tick != before + ticks:
            raise ModelError(
                self.name, f"was asked to advance {ticks} ticks from tick {before} and is at "
                f"tick {self.tick}",
            )  # fmt: skip
        events = self._events(events, before, f"in advance() {where}")
        if not log:
            self._all_logged = False
            if len(events):
                said = f"returned events in advance() {where} with the log off"
                raise ModelError(self.name, said)
        else:
            walls = int(np.count_nonzero(events["type"] == EV_WALL))
            self._logged = (self._logged[0] + walls, self._logged[1] + len(events) - walls)
        return events

    def _events(self, events, before: int, where: str) -> np.ndarray:
        """The events, checked: EVENT_DTYPE records in order, of these ticks, of real objects."""
        if not isinstance(events, np.ndarray) or events.dtype != EVENT_DTYPE or events.ndim != 1:
            what = f"dtype {events.dtype}" if isinstance(events, np.ndarray) else events
            raise ModelError(
                self.name, f"returned events {where} that are not a 1-d EVENT_DTYPE array ({what})"
            )
        if not len(events):
            return events
        fps, n = self.world.fps, self.n
        tick, t, kind, a, b, code = (events[k] for k in ("tick", "t", "type", "a", "b", "code"))
        walls, pairs = kind == EV_WALL, kind == EV_PAIR
        problems = (
            (((tick <= before) | (tick > self.tick)), "an event of another tick"),
            ((np.diff(tick) < 0), "events out of order (a tick before the one above it)"),
            (~np.isfinite(t), "an event time that is not a finite number"),
            ((np.diff(t) < 0), "events out of order (a time before the one above it)"),
            ((t > tick / fps + TIME_SLACK_S) | (t < (tick - 1) / fps - TIME_SLACK_S),
             "an event time outside its tick"),
            (~(walls | pairs), "an event type that is neither wall (0) nor pair (1)"),
            (walls & ((a < 0) | (a >= n) | (b != -1) | (code < 0) | (code >= len(SIDE_NAMES))),
             "a wall event without an object id, b = -1 and a side"),
            (pairs & ((a < 0) | (a >= b) | (b >= n) | (code < 0) | (code >= len(AXIS_NAMES))),
             "a pair event without ids a < b of the scene's objects and an axis"),
        )  # fmt: skip
        for bad, what in problems:
            if np.any(bad):
                raise ModelError(self.name, f"returned {what} {where}")
        return events

    def _state(self, which: str) -> np.ndarray:
        at = f"at tick {self.tick}"
        got = self._call(f"in {which}() {at}", _answer, self._inner, which)
        wanted = f"the protocol asks for an ({self.n}, 2) float64 array"
        if not isinstance(got, np.ndarray):
            raise ModelError(self.name, f"returned {which}() of type {got} {at}; {wanted}")
        if got.shape != (self.n, 2):
            raise ModelError(self.name, f"returned {which}() of shape {got.shape} {at}; {wanted}")
        if got.dtype.kind != "f":
            raise ModelError(self.name, f"returned {which}() of dtype {got.dtype} {at}; {wanted}")
        with np.errstate(over="ignore"):
            got = got.astype(np.float64)  # a longer float that overflows is infinite here
        if not np.isfinite(got).all():
            raise ModelError(self.name, f"returned {which}() with NaN or infinity {at}")
        return got

    def positions(self) -> np.ndarray:
        pos = self._state("positions")
        world = np.array([self.world.width, self.world.height], np.float64)
        far = ((pos + self._size < -world) | (pos > 2 * world)).any(axis=1)
        if far.any():
            i = int(np.flatnonzero(far)[0])
            raise ModelError(
                self.name, f"returned positions() at tick {self.tick} with object {i} at "
                f"({pos[i, 0]:g}, {pos[i, 1]:g}), outside the {world[0]:g}x{world[1]:g} world by "
                "more than the world's size",
            )  # fmt: skip
        return pos

    def velocities(self) -> np.ndarray:
        return self._state("velocities")

    def event_counts(self) -> tuple[int, int]:
        at = f"at tick {self.tick}"
        got, shown = self._call(f"in event_counts() {at}", _counts, self._inner)
        if got is None:
            raise ModelError(
                self.name, f"returned event_counts() {shown} {at}, not two whole counts >= 0"
            )
        logged = self._logged
        if (self._all_logged and got != logged) or got[0] < logged[0] or got[1] < logged[1]:
            raise ModelError(
                self.name, f"returned event_counts() {got} {at}, but the events it returned "
                f"so far are {logged} (wall, pair)",
            )  # fmt: skip
        if got[0] < self._counted[0] or got[1] < self._counted[1]:
            raise ModelError(
                self.name, f"returned event_counts() {got} {at}, fewer than {self._counted} before"
            )
        self._counted = got
        return got


def _answer(model, method: str, *args) -> np.ndarray | str:
    """model.method(*args) made collide2d's own: a fresh numpy array (never a subclass, never the
    plugin's buffer), or, when it is no array, the name of its type."""
    got = getattr(model, method)(*args)
    if not issubclass(type(got), np.ndarray):
        return guard.type_name(got)
    return np.array(got, copy=True, subok=False)


def _whole(model, attribute: str) -> tuple[int | None, str]:
    """(model.attribute as an int when it is a whole number (never a bool), else None; it shown)."""
    value = getattr(model, attribute, None)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        return None, guard.shown(value)
    return int(value), ""


# The most items of an event_counts() answer looked at: two, and one more to see it is not two.
_COUNT_ITEMS = 3


def _counts(model) -> tuple[tuple[int, int] | None, str]:
    """(model.event_counts()'s two counts as ints, or None when they are not two whole numbers
    >= 0; the answer shown)."""
    got = model.event_counts()
    shown = guard.shown(got)
    try:
        items = list(itertools.islice(iter(got), _COUNT_ITEMS))
    except TypeError:
        return None, shown
    whole = []
    for c in items:
        if isinstance(c, (bool, np.bool_)):
            return None, shown
        if isinstance(c, (float, np.floating)) and np.isfinite(c) and float(c).is_integer():
            c = int(c)
        if not isinstance(c, (int, np.integer)) or c < 0:
            return None, shown
        whole.append(int(c))
    return (tuple(whole) if len(whole) == 2 else None), shown
