"""What rests on what, tick by tick, for the `rests` overlay (`runner.output.overlay`).

Under gravity the `exact` model logs when an object starts and stops resting
(docs/outputs.md#event-log): `rest` starts a rest (the object `id`, the `side` it presses into, its
support: the object `on`, or the wall that side), `stop` keeps it (it stops sliding), `wake` and
`leave` end it. `Rests` takes a run's event chunks as they come and replays them in order up to
each drawn tick, the ticks between drawn frames included. An object that starts still on a wall
gravity pulls it into rests on it from tick 0 without an event (docs/models.md#exact-under-gravity):
`Rests` starts from the rests the model reports before it runs (its `rests()`, when it has one).
The other models log no such events and report no rests: nothing rests.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.events import EV_LEAVE, EV_REST, EV_STOP, EV_WAKE

# The wall a rest is on: its support, where an object's support is its id.
WALL = -1


class Rests:
    """The rests of one run: `events(chunk)` takes each event chunk in order, `at(tick)` replays
    those up to `tick` and returns {object: (side, support)}, support an object's id or WALL."""

    def __init__(self):
        self._on: dict[int, tuple[int, int]] = {}
        self._pending: list[np.ndarray] = []

    def start(self, model) -> None:
        """Start from the rests of `model` before it runs (none for a model without `rests()`)."""
        rests = getattr(model, "rests", None)
        self._on = dict(rests()) if callable(rests) else {}

    def events(self, events: np.ndarray) -> None:
        """Take an event chunk (only its rest, stop, wake and leave events are kept)."""
        if len(events):
            self._pending.append(events[events["type"] >= EV_REST])

    def at(self, tick: int) -> dict[int, tuple[int, int]]:
        """The rests at the end of `tick`: every event taken up to it applied, in order."""
        if self._pending:
            ev = np.concatenate(self._pending)
            later = ev["tick"] > tick
            self._pending = [ev[later]] if later.any() else []
            for rec in ev[~later]:
                self._apply(rec)
        return dict(self._on)

    def _apply(self, rec) -> None:
        i, kind = int(rec["a"]), int(rec["type"])
        if kind in (EV_REST, EV_STOP):  # a stop names the rest it keeps
            self._on[i] = (int(rec["code"]), int(rec["b"]) if rec["b"] >= 0 else WALL)
        elif kind in (EV_WAKE, EV_LEAVE):
            self._on.pop(i, None)
