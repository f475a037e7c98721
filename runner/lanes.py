"""Which lane a run's kernels take: compiled by numba, or interpreted as plain Python (engine.jit).

A compiled kernel runs 20 to 100 times faster per step, but numba takes about half a second to
start and load cached kernels, and tens of seconds to compile a model's kernels the first time
(from an empty cache: a CI job's). Mode `auto`, the default, decides from a measured model of both
costs, as the run goes: every run starts interpreted, and at the end of each chunk of ticks it
compares

- what the ticks left would take interpreted: the run's own pace so far (its ticks and the frames
  drawn between them, wall time) times the ticks left, with
- what they would take compiled: the seconds to get the kernels the run has called so far ready
  (runner.compilecost: numba's start, the cached ones loaded, each other one compiled, from a
  table of each kernel's measured compile CPU seconds, scaled to how fast a core of this machine
  runs Python and divided by the share of a core the run's ticks have had: a busy machine slows a
  compilation as it slows the ticks) plus the ticks left at COMPILED_SPEEDUP times the pace,

and goes on compiled, for good, between two ticks (the state is the same arrays; both lanes give
the same bytes) as soon as compiling pays, by SWITCH_MARGIN (the estimate's error on a busy
machine). So a run never pays for much more than its work: a small one, or a long one whose
kernels would take longer to compile than it takes to interpret, is done interpreted, numba never
loaded; a big one compiles after a short look (PROBE_S); one whose
kernels numba's cache holds goes compiled after a tick or two, for the cost of loading them. The
kernels a run needs are the ones it calls (engine.jit.recording), not every kernel. The first
chunks are short (1, 1, 2, 4, ... ticks) so that a slow scene is measured after a tick or two.
What no pace sees is estimated up front: the bounces of a huge mass ratio within one tick of the
exact model (a run whose bounces would take longer interpreted, EVENT_INTERPRETED_S each, than
compiling the exact model's kernels starts compiled), and the ticks of a run whose model's
kernels the wheel ships (engine.kernelstore): a run whose ticks would take longer interpreted, at
the least (TICK_INTERPRETED_S an object a tick), than starting numba and loading them starts
compiled (a big scene, whose first tick alone would cost seconds, or a small one run for many
ticks), as `--jit on` would run it.

Mode `on` compiles every run and `off` interprets every run (slow for big scenes); the command
line's `--jit MODE` sets it (`set_mode`), else `COLLIDE2D_JIT` in the environment, else `auto`.

Loading a scenario runs kernels too (the start-overlap check, `generate` blocks, the starting
room check): interpreted up to LOAD_INTERPRETED_MAX_OBJECTS objects (`objects(n)`), counting the
objects of every load of a `loads(k)` block (a sweep's check draws one scene for each seed), and
above that from an empty kernel cache while interpreting them costs less than compiling the
loading kernels would; compiled otherwise.
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from contextvars import ContextVar

import numpy as np

from collide2d.engine import jit, kernelstore
from collide2d.runner import compilecost, compiling

MODES = ("auto", "on", "off")
# How many times faster compiled kernels run a tick than interpreted ones, at the least (measured
# on the bench's standard scene: 25x for 1,000 boxes under paper, more for bigger scenes).
COMPILED_SPEEDUP = 20
# Seconds of interpreted ticks an `auto` run measures before it pays more than that to compile
# (going on with kernels this process has ready needs no such look).
PROBE_S = 0.1
# The least share of a core a run is taken to get (a compile estimate is divided by its share).
MIN_SHARE = 0.1
# A switch must save this many times the compile estimate: on a busy machine (load 15 on 2 cores)
# the paper model's kernels for 1,000 boxes took 1.6 to 2 times their estimate to compile, while
# interpreting went at the measured pace; past the margin, compiling wins even then.
SWITCH_MARGIN = 1.5
# Seconds a switch must save, at the least, to be looked at (a tiny run never looks).
MIN_SAVED_S = 0.05
# Seconds an interpreted exact-model event takes (about 0.4 ms on this project's machine), for
# the bounces a mass ratio makes within one tick, which the pace of the ticks before cannot see.
EVENT_INTERPRETED_S = 4e-4
# Objects up to which loading a scenario runs its kernels interpreted under `auto`; above, from an
# empty kernel cache, while interpreting them (LOAD_INTERPRETED_S an object: 0.65 s for the
# standard scene's 5,000 boxes) takes less than compiling the loading kernels.
LOAD_INTERPRETED_MAX_OBJECTS = 2_000
LOAD_INTERPRETED_S = 1.3e-4
# Seconds an interpreted tick takes per object, at the least (the bench's standard scene of
# 20,000 boxes: 28 us under stepped, 38 under paper, 42 under exact; the gravity pile, 36), and
# the seconds to load a model's kernels from the kernels the wheel ships once numba has started:
# a run whose ticks would take longer interpreted than numba's start and that load (40,000
# objects for a tick, 10 objects for 4,000 ticks) starts compiled.
TICK_INTERPRETED_S = 2.5e-5
STORED_LOAD_S = 0.5

_clock = time.perf_counter
_cpu = time.process_time
_mode: str | None = None  # set by the command line; None: the environment's, else auto
_loads: ContextVar[int] = ContextVar("collide2d_loads", default=1)


def check_mode(mode: str) -> str:
    """`mode` if it is one of MODES (case-insensitive, on/off also as 1/0); else ValueError."""
    value = {"1": "on", "0": "off"}.get(str(mode).strip().lower(), str(mode).strip().lower())
    if value not in MODES:
        raise ValueError(f"unknown kernel mode {mode!r}; expected one of {', '.join(MODES)}")
    return value


def set_mode(mode: str | None) -> None:
    """Put `mode` (one of MODES) in force for this process; None: the environment's again."""
    global _mode
    _mode = None if mode is None else check_mode(mode)


def mode() -> str:
    """The mode in force: set_mode's, else COLLIDE2D_JIT's, else auto (numba's
    NUMBA_DISABLE_JIT=1 means off)."""
    if _mode is not None:
        return _mode
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return "off"
    try:
        return check_mode(os.environ.get("COLLIDE2D_JIT", "auto") or "auto")
    except ValueError:
        return "auto"


def compiled_for_run(scenario, frames: int) -> bool:
    """Whether a run of `scenario` drawing `frames` frames starts with its kernels compiled: under
    `auto` no run does (RunLane decides as it goes)."""
    return mode() == "on"


def bursts_past_compiling(scenario) -> bool:
    """Whether the bounces the exact model makes within its first tick would take longer
    interpreted than compiling the exact model's kernels from an empty cache: those of the
    largest mass ratio (a light object between a wall and a heavy one bounces about
    pi * sqrt(ratio) times, most of them within one tick), or the wall bounces of objects so fast
    that they cross their room many times a tick (`_wall_bounces`)."""
    if scenario.model != "exact" or not scenario.bodies.n:
        return False
    bounces = math.pi * math.sqrt(_mass_ratio(scenario.bodies))
    bounces = max(bounces, _wall_bounces(scenario))
    return bounces * EVENT_INTERPRETED_S > compilecost.model_seconds("exact")


def big_and_stored(scenario) -> bool:
    """Whether the interpreted ticks of a run of `scenario` would take longer, at the least, than
    starting numba and loading its model's kernels from the kernels the wheel ships
    (engine.kernelstore), which hold them: such a run starts compiled, as `--jit on` runs it,
    without the look (PROBE_S) and the switch a run in `auto` pays otherwise."""
    if not kernelstore.holds_model(scenario.model):
        return False
    ticks = scenario.bodies.n * scenario.ticks * TICK_INTERPRETED_S
    return ticks > compilecost.start_seconds() + STORED_LOAD_S


def _wall_bounces(scenario) -> float:
    """About how many wall bounces the objects make in one tick: each axis's distance travelled
    over the room the object has on it (at least a pixel), summed over the moving objects."""
    bodies, world = scenario.bodies, scenario.world
    moving = ~bodies.static
    room = np.array([world.width, world.height], dtype=np.float64) - bodies.size[moving]
    travel = np.abs(bodies.vel[moving]) / world.fps
    return float(np.sum(travel / np.maximum(room, 1.0)))


def _mass_ratio(bodies) -> float:
    mass = bodies.mass[np.isfinite(bodies.mass) & (bodies.mass > 0)]
    return float(mass.max() / mass.min()) if mass.size else 1.0


class RunLane:
    """The lane of one run as it goes: `compiled`, and whether it may still switch (an `auto` run,
    until it has switched). `opened()` is the `with` block of the whole run (it records the
    kernels called); `step(ticks)` caps a model call's ticks while it may switch; `timed(ticks)`
    wraps each call of that many ticks and, after it, switches to compiled for good when that
    pays, as the module docstring says."""

    def __init__(self, scenario, frames: int):
        chosen = mode()
        self.compiled = self.started_compiled = chosen == "on"
        self.may_switch = chosen == "auto"
        self.ticks = scenario.ticks
        self.done = 0
        self.began: float | None = None
        self.began_cpu = 0.0
        self.called = jit.Called()
        self._ready: dict = {}  # kernel -> seconds to get it ready, once asked
        self._empty: bool | None = None
        self._cold = 0.0  # table seconds of compiling the kernels called so far, once asked
        self._needed: set = set()  # the kernels to get ready then
        if self.may_switch and (bursts_past_compiling(scenario) or big_and_stored(scenario)):
            self.compiled = self.started_compiled = True
            self.may_switch = False

    @contextlib.contextmanager
    def opened(self):
        with jit.lane(self.compiled):
            if not self.may_switch:
                yield self
                return
            with jit.recording() as called:
                self.called = called
                yield self

    def step(self, ticks: int) -> int:
        return min(ticks, max(1, self.done)) if self.may_switch else ticks

    @contextlib.contextmanager
    def timed(self, ticks: int):
        if self.began is None:
            self.began, self.began_cpu = _clock(), _cpu()
        with jit.lane(self.compiled):
            yield
        self.done += ticks
        if self.may_switch and self.done < self.ticks:
            self._decide()

    def _decide(self) -> None:
        spent = _clock() - self.began
        left = spent / self.done * (self.ticks - self.done)
        saved = left * (1 - 1 / COMPILED_SPEEDUP)  # by going on compiled, once ready
        share = self.share(spent)
        if saved <= max(MIN_SAVED_S, compilecost.lower_bound(self.called, share)):
            return
        if spent < PROBE_S and not jit.loaded():
            return  # measure longer before looking at numba's cache (which loads numba)
        cost = self.ready_seconds(share)
        if spent < PROBE_S and cost > spent:
            return  # measure longer before paying more than has been measured
        if saved > SWITCH_MARGIN * cost:
            self.compiled, self.may_switch = True, False
            # for the compile notice (runner.command.compilenotice)
            compiling.expect(self._cold, {compilecost.name(k) for k in self._needed})

    def share(self, spent: float) -> float:
        """The share of a core this run's ticks have had (its CPU time over its wall time): a
        compilation, and numba's start, get about as much."""
        cpu = _cpu() - self.began_cpu
        return min(max(cpu / max(spent, 1e-9), MIN_SHARE), 1.0)

    def ready_seconds(self, share: float = 1.0) -> float:
        """Wall seconds to get the kernels called so far ready to run compiled, getting `share`
        of a core (runner.compilecost); each kernel is looked up once per run. A kernel the run
        calls from Python (jit.Called.entries) that would not compile has the kernels it calls
        compiled into it: they cost nothing more (a second run in a process that compiled or
        loaded the first run's kernels goes on compiled after a tick)."""
        if self._empty is None:
            self._empty = not jit.loaded() and jit.cache_empty()
        for kernel in [k for k in self.called if k not in self._ready]:
            self._ready[kernel] = compilecost.parts(kernel, self._empty)
        needed = set()
        for entry, under in self.called.entries.items():
            needed |= {entry} if self._ready[entry][1] == 0.0 else under
        load = sum(self._ready[k][0] for k in needed)
        self._needed = needed
        cold = self._cold = sum(self._ready[k][1] for k in needed)
        scaled = cold * compilecost.speed_factor() if cold else 0.0
        return compilecost.start_seconds(share) + (load + scaled) / share

    def name(self) -> str:
        """How the summary names the lanes the run took."""
        if self.compiled and not self.started_compiled:
            return "interpreted, then compiled"
        return name(self.compiled)


def run(scenario, frames: int):
    """The lane of a run of `scenario` drawing `frames` frames, for a `with` block."""
    return jit.lane(compiled_for_run(scenario, frames))


def objects(n: int):
    """The lane of loading a scenario of `n` objects, for a `with` block."""
    chosen = mode()
    if chosen != "auto":
        return jit.lane(chosen == "on")
    count = n * _loads.get()
    if count <= LOAD_INTERPRETED_MAX_OBJECTS:
        return jit.lane(False)
    if not jit.loaded() and jit.cache_empty():  # compiled, the loading kernels would compile
        return jit.lane(count * LOAD_INTERPRETED_S > compilecost.model_seconds("load"))
    return jit.lane(True)


@contextlib.contextmanager
def loads(k: int):
    """A `with` block of about `k` loads of one scene: each load's kernels take the lane of
    all their objects together (`objects`)."""
    token = _loads.set(max(1, int(k)))
    try:
        yield
    finally:
        _loads.reset(token)


def name(compiled: bool) -> str:
    """How the summary names a lane."""
    return "compiled" if compiled else "interpreted"
