"""Whether a big scene's split stages run on threads or on one, chosen by the clock as a run goes.

A stage split among threads (engine.threads) pays only while its threads have cores to
themselves. Waiting threads spin briefly for their next task (engine.threads), which is what makes
a split stage cheap on a free machine, and costly on a busy one: a split stage waits for its
slowest thread, and a spinning thread holds a core the others need. Measured on a 2-core machine
with the stepped model at 100,000 objects: two threads cut a step from 20 to 15 ns per object on
the free machine and doubled it (21 to 43 ns) beside one other busy process.

So a model whose scene splits (`threads.chunks_for` > 1) runs its ticks through a `SplitChoice`:
in phases of about PHASE_S seconds (at least PHASE_MIN_TICKS ticks, across calls), split or not,
each phase timed. Phases go the way that was faster per tick when last timed; the other way is
timed again on a phase of PROBE_S every few phases (after the first phase, then every PROBE_EVERY
phases, twice as many each time it loses, up to PROBE_MAX). A model's state after any tick is the
same bytes split or not, so the choice changes only how long a run takes, never what it gives.
"""

from __future__ import annotations

import math
import time

# Seconds of ticks per phase of the way in use, and per phase timing the other way.
PHASE_S = 0.1
PROBE_S = 0.03
# Ticks a phase holds at least (a stepped model remakes its list every few ticks: a phase holds
# several).
PHASE_MIN_TICKS = 12
# Phases of the way in use before the other way is timed again: PROBE_EVERY after it wins,
# doubling each time it loses, at most PROBE_MAX.
PROBE_EVERY = 4
PROBE_MAX = 64


class SplitChoice:
    """Runs a model's ticks split into `chunks` or on one thread, whichever the clock says is
    faster (see the module docstring). `clock` is for tests."""

    def __init__(self, chunks: int, clock=time.perf_counter):
        self.chunks = int(chunks)
        self.way = self.chunks  # the chunks phases use: split to begin with
        self.per_tick: dict[int, float] = {}  # seconds per tick of each way, when last timed
        self._trying = False  # this phase times the other way
        self._wait = 1  # phases of `way` left before the other is timed
        self._every = PROBE_EVERY
        self._warm = False  # the first call (it loads or compiles the kernels) is not timed
        self._spent = 0.0  # this phase so far: seconds, ticks
        self._ticks = 0
        self._clock = clock

    def run(self, ticks: int, go) -> list:
        """Run `ticks` ticks as calls go(k, chunks) of k ticks each, in order; returns their
        results. A scene that does not split runs as one call."""
        if self.chunks <= 1 or ticks <= 0:
            return [go(ticks, self.way)]
        done = []
        while ticks > 0:
            way = self._phase_way()
            k = min(ticks, self._ticks_for(way))
            began = self._clock()
            done.append(go(k, way))
            self._timed(way, k, self._clock() - began)
            ticks -= k
        return done

    def _phase_way(self) -> int:
        if not self._trying:
            return self.way
        return 1 if self.way == self.chunks else self.chunks

    def _ticks_for(self, way: int) -> int:
        """Ticks of the next call: what this phase still needs by the last pace known."""
        if not self._warm:
            return 1
        pace = self.per_tick.get(way, self.per_tick.get(self.way))
        if pace is None:  # nothing timed yet: double until the phase is long enough
            return max(1, self._ticks)
        target = PROBE_S if self._trying else PHASE_S
        wanted = math.ceil((target - self._spent) / max(pace, 1e-12))
        return max(1, PHASE_MIN_TICKS - self._ticks, min(wanted, 1 << 20))

    def _timed(self, way: int, ticks: int, seconds: float) -> None:
        if not self._warm:
            self._warm = True
            return
        self._spent += seconds
        self._ticks += ticks
        target = PROBE_S if self._trying else PHASE_S
        if self._spent < target or self._ticks < PHASE_MIN_TICKS:
            return
        self.per_tick[way] = self._spent / self._ticks
        self._spent, self._ticks = 0.0, 0
        if not self._trying:
            self._wait -= 1
            self._trying = self._wait <= 0
            return
        self._trying = False
        if self.per_tick[way] < self.per_tick[self.way]:
            self.way = way
            self._every = PROBE_EVERY
        else:
            self._every = min(2 * self._every, PROBE_MAX)
        self._wait = self._every
