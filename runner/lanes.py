"""Which lane a run's kernels take: compiled by numba, or interpreted as plain Python (engine.jit).

A compiled kernel is a hundred times faster per step, but a process pays about half a second to
import numba and load its first cached kernel, and seconds per kernel the first time it compiles.
A small scene is done interpreted before numba has even started, so every run chooses (mode
`auto`, the default): interpreted while its work is at most INTERPRETED_MAX_WORK, compiled above.
Mode `on` compiles every run and `off` interprets every run (slow for big scenes); the command
line's `--jit MODE` sets it (`set_mode`), else `COLLIDE2D_JIT` in the environment, else `auto`.
Both lanes give the same bytes.

A run's work is counted in object-ticks (one object advanced one tick; a stepped substep counts as
a tick), plus its drawing: the frames drawn times the pixels of the objects' boxes (each at most
the world's area), PIXELS_PER_OBJECT_TICK pixels to an object-tick, plus, for the exact model,
its events at EVENT_WORK object-ticks each: wall events (each object's crossings of the room it
has, |v| / fps / room per tick per axis) and the bounces of its largest mass ratio (a light object
between a wall and a heavy one bounces about pi * sqrt(ratio) times).

What no estimate sees, a run that starts interpreted also watches: once its ticks have taken
INTERPRETED_BUDGET_S and the ticks left would take more than INTERPRETED_LEFT_S at the pace so far,
it goes on compiled (between two ticks: the state is the same arrays). A busy machine slows both
lanes alike, and a run near its end is not worth a compilation.

Measured interpreted on this project's 2-core machine: the paper model's section IV demo (50
boxes, 100 ticks, every frame drawn for the GIF) takes 0.19 s; a gas of 300 boxes over 120 ticks,
2.6 s (36,000 object-ticks), where numba loads its cached kernels in about 0.5 s.

Loading a scenario runs kernels too (the start-overlap check, `generate` blocks, the starting
room check): interpreted up to LOAD_INTERPRETED_MAX_OBJECTS objects (`objects(n)`), counting the
objects of every load of a `loads(k)` block (a sweep's check draws one scene for each seed).
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from contextvars import ContextVar

import numpy as np

from collide2d.engine import jit

MODES = ("auto", "on", "off")
# Work (object-ticks) up to which `auto` interprets a run (about a second interpreted).
INTERPRETED_MAX_WORK = 20_000
# Pixels drawn interpreted in about the time of one object-tick.
PIXELS_PER_OBJECT_TICK = 100
# Objects up to which loading a scenario runs its kernels interpreted under `auto`.
LOAD_INTERPRETED_MAX_OBJECTS = 2_000
# Object-ticks of work an exact-model event counts for (measured interpreted: about 0.4 ms an
# event, 40 us an object-tick).
EVENT_WORK = 10
# Seconds of interpreted ticks after which an `auto` run goes on compiled, if the ticks left would
# take more than INTERPRETED_LEFT_S more.
INTERPRETED_BUDGET_S = 1.0
INTERPRETED_LEFT_S = 3.0
# Ticks per model call while a run may still switch (how often the budget is looked at).
INTERPRETED_CHUNK_TICKS = 8

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


def work(scenario, frames: int) -> float:
    """The work of running `scenario` drawing `frames` frames, in object-ticks."""
    bodies = scenario.bodies
    world = scenario.world
    steps = scenario.ticks * (scenario.substeps if scenario.model == "stepped" else 1)
    area = (bodies.size[:, 0] * bodies.size[:, 1]).clip(0.0, float(world.width * world.height))
    drawn = float(frames) * float(area.sum()) if bodies.n else 0.0
    total = float(bodies.n) * steps + drawn / PIXELS_PER_OBJECT_TICK
    if scenario.model == "exact" and bodies.n:
        room = np.maximum(np.array([world.width, world.height], float) - bodies.size, 1.0)
        crossings = np.abs(np.nan_to_num(bodies.vel, posinf=0.0, neginf=0.0)) / room
        walls = float(crossings.sum()) / world.fps * scenario.ticks
        bounces = math.pi * math.sqrt(_mass_ratio(bodies))
        total += EVENT_WORK * (walls + bounces)
    return total


def compiled_for_run(scenario, frames: int) -> bool:
    """Whether a run of `scenario` drawing `frames` frames starts with its kernels compiled."""
    chosen = mode()
    if chosen != "auto":
        return chosen == "on"
    return work(scenario, frames) > INTERPRETED_MAX_WORK


def _mass_ratio(bodies) -> float:
    mass = bodies.mass[np.isfinite(bodies.mass) & (bodies.mass > 0)]
    return float(mass.max() / mass.min()) if mass.size else 1.0


class RunLane:
    """The lane of one run as it goes: `compiled`, and whether it may still switch (an `auto` run
    that starts interpreted). `step(ticks)` caps a model call's ticks while it may; `timed(ticks)`
    wraps each call of that many ticks and switches to compiled for good as the module docstring
    says."""

    def __init__(self, scenario, frames: int):
        self.compiled = compiled_for_run(scenario, frames)
        self.started_compiled = self.compiled
        self.may_switch = not self.compiled and mode() == "auto"
        self.spent = 0.0
        self.done = 0
        self.ticks = scenario.ticks

    def step(self, ticks: int) -> int:
        return min(ticks, INTERPRETED_CHUNK_TICKS) if self.may_switch else ticks

    @contextlib.contextmanager
    def timed(self, ticks: int):
        began = time.perf_counter()
        with jit.lane(self.compiled):
            yield
        if self.may_switch:
            self.spent += time.perf_counter() - began
            self.done += ticks
            left = self.spent / max(self.done, 1) * (self.ticks - self.done)
            if self.spent > INTERPRETED_BUDGET_S and left > INTERPRETED_LEFT_S:
                self.compiled, self.may_switch = True, False

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
    return jit.lane(n * _loads.get() > LOAD_INTERPRETED_MAX_OBJECTS)


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
