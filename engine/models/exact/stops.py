"""What the exact model raises once its kernel has stopped (docs/limits.md#runaways).

The kernel (model._run) stops, and returns a status, at the event cap (STATUS_CAP), at an event
storm (STATUS_STORM: the object it was seen on in the first row of the jobs) and where it cannot
follow a rest (STATUS_REST, STATUS_CARRIED: the pair in that row). `Stops`, a part of the model's
class, turns the status into the error the model raises, named in words by jam.py: for a cap or a
storm the model, stopped for good, first runs up to RECENT more events of that tick with the log
on and looks at them, so the hot loop keeps no record of its own.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine import events
from collide2d.engine.errors import Runaway
from collide2d.engine.models.exact.jam import carried_error, jam_error, rest_error, storm_error
from collide2d.engine.models.exact.state import (
    J_OBJ,
    J_SKIP,
    S_LOGGED,
    S_PAIRS,
    S_TICK,
    S_TICK_EVENTS,
    S_WALLS,
    SF_T_NOW,
    STATUS_CAP,
    STATUS_HEAP_FULL,
    STATUS_REST,
    STATUS_STORM,
)

# Who a runaway or a storm involves: the events the stopped model runs on, with the log on.
RECENT = 64


class Stops:
    """The errors of a stopped exact model (model.Model, whose state and kernel it reads)."""

    def _stopped(self, status: int) -> Runaway:
        """The error of a kernel stopped with `status`; the model is stopped for good."""
        if status == STATUS_CAP:
            return self._runaway()
        if status == STATUS_STORM:
            return self._storm()
        return self._resting(status)

    def _runaway(self) -> Runaway:
        """The error of a tick stopped at the cap: NoRoom when the objects of the events that
        would come next, at the instant it stopped, are jammed on an axis (jam.jammed: they
        collide again and again with no time passing, having no room to move), naming them; else
        EventCapExceeded."""
        st, t = self._st, float(self._stf[SF_T_NOW])
        said = (
            f"tick {int(st[S_TICK]) + 1} needed more than {self.max_events_per_tick} events "
            f"(max_events_per_tick); stopped as a runaway at t = {t!r} s"
        )
        rows, times = self._recent()
        return jam_error(rows, times, float(self._stf[SF_T_NOW]), self._F, self._N, self._world,
                         said)  # fmt: skip

    def _storm(self) -> Runaway:
        """The error of a run stopped by an event storm (jam.storm_error: the objects of the
        contacts that recur, named), from the events of the storm, not counted for storms."""
        t, first = float(self._stf[SF_T_NOW]), int(self._jobs[0, J_OBJ])
        tick = int(self._st[S_TICK]) + 1
        rows, times = self._recent()
        return storm_error(first, rows, times, t, self._F, self._N, self._world, tick)

    def _recent(self) -> tuple[np.ndarray, np.ndarray]:
        """The rows and times of up to RECENT more events of the tick stopped in, logged; the
        event counts stay those of the events before the stop."""
        st = self._st
        counts = st[S_WALLS : S_PAIRS + 1].copy()
        st[S_LOGGED] = 0
        rows, times = events.new_log(True, RECENT)
        cap = int(st[S_TICK_EVENTS]) + RECENT
        while self._call(int(st[S_TICK]) + 1, True, cap, rows, times, 0) == STATUS_HEAP_FULL:
            self._grow_heap()
        st[S_WALLS : S_PAIRS + 1] = counts
        n = int(st[S_LOGGED])
        return rows[:n], times[:n]

    def _resting(self, status: int) -> Runaway:
        """The error of a run stopped where a falling body would come to rest on another, or a
        circle slide round a static box's corner (STATUS_REST), or a body another rests on is
        knocked into motion (STATUS_CARRIED): the pair is in the first row of the jobs."""
        a, b = int(self._jobs[0, J_OBJ]), int(self._jobs[0, J_SKIP])
        said = rest_error if status == STATUS_REST else carried_error
        return said(a, b, int(self._st[S_TICK]) + 1, float(self._stf[SF_T_NOW]))
