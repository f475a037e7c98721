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
wraps it and checks every answer (shapes, dtypes, finite numbers, event order and ids, ticks
advanced); anything else it does wrong, or any exception it raises, becomes a `ModelError`
naming the model. `collide2d.testing.check_model` runs the whole conformance kit on a model.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

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


class Checked:
    """A plugin model, every answer checked against the protocol (`ModelError` otherwise).

    Built as `Checked(name, factory, world, bodies, options)`: `factory(world, bodies,
    **options)` builds the plugin (its exceptions are told as the model's). Runaways it raises
    pass through as they are."""

    def __init__(self, name: str, factory, world: WorldSpec, bodies: Bodies, options: dict):
        self.name = name
        self.world = world
        self.n = bodies.n
        self._inner = self._call("failed to build", factory, world, bodies, **options)
        self.tick = self._tick()
        if self.tick != 0:
            raise ModelError(name, f"starts at tick {self.tick}, not 0")

    def _call(self, doing: str, fn, *args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except (Runaway, ModelError):
            raise
        except Exception as exc:
            detail = " ".join(str(exc).split())[:300]
            raise ModelError(
                self.name, f"{doing}: {type(exc).__name__}{': ' + detail if detail else ''}"
            ) from exc

    def _tick(self) -> int:
        tick = getattr(self._inner, "tick", None)
        if isinstance(tick, (bool, np.bool_)) or not isinstance(tick, (int, np.integer)):
            raise ModelError(self.name, f"has a tick that is not a whole number: {tick!r}")
        return int(tick)

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        before = self.tick
        where = f"in ticks {before + 1}-{before + ticks}" if ticks > 1 else f"in tick {before + 1}"
        events = self._call(f"raised {where}", self._inner.advance, ticks, log)
        self.tick = self._tick()
        if self.tick != before + ticks:
            raise ModelError(
                self.name, f"was asked to advance {ticks} ticks from tick {before} and is at "
                f"tick {self.tick}",
            )  # fmt: skip
        return self._events(events, before, where)

    def _events(self, events, before: int, where: str) -> np.ndarray:
        """The events, checked: EVENT_DTYPE records in order, of these ticks, of real objects."""
        if not isinstance(events, np.ndarray) or events.dtype != EVENT_DTYPE or events.ndim != 1:
            shown = getattr(events, "dtype", type(events).__name__)
            raise ModelError(
                self.name, f"returned events {where} that are not a 1-d EVENT_DTYPE array ({shown})"
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
        got = self._call(f"raised in {which}() at tick {self.tick}", getattr(self._inner, which))
        if not isinstance(got, np.ndarray) or got.shape != (self.n, 2) or got.dtype.kind != "f":
            shape = getattr(got, "shape", type(got).__name__)
            raise ModelError(
                self.name,
                f"returned {which}() of shape {shape} at tick {self.tick}; the protocol asks "
                f"for an ({self.n}, 2) float64 array",
            )
        if not np.isfinite(got).all():
            raise ModelError(
                self.name, f"returned {which}() with NaN or infinity at tick {self.tick}"
            )
        return np.asarray(got, np.float64)

    def positions(self) -> np.ndarray:
        return self._state("positions")

    def velocities(self) -> np.ndarray:
        return self._state("velocities")

    def event_counts(self) -> tuple[int, int]:
        got = self._call("raised in event_counts()", self._inner.event_counts)
        try:
            walls, pairs = (int(c) for c in got)
        except (TypeError, ValueError):
            walls = pairs = -1
        if walls < 0 or pairs < 0:
            raise ModelError(self.name, f"returned event_counts() {got!r}, not two counts >= 0")
        return walls, pairs
