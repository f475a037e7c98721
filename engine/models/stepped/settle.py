"""The stepped model's settling path (docs/models.md#stepped-gravity-restitution-and-friction):
gravity, restitution, friction and sleep, taken only by a world that has gravity, or an e below 1,
or a mu above 0 (an object's or the walls'). Any other world takes the elastic path of step.py,
unchanged.

`Settle` is the model's state on this path: built from the world, the bodies and the options
(`iterations`, `slop`, `rest_speed`, `sleep`, `sleep_after`, besides `substeps` and `geometry`),
it runs ticks with `run` and answers the model's surface (positions, velocities, event counts).
Every array is in id order and every loop runs on one thread, in id order: the same bytes on any
number of threads.

A step (`step`) reads as its table of contents: move (fall.py: exact motion, wall bounces), the
candidate list when due, the landing of a body the move took far into a static object (land.py),
the contacts (touch.py: walls, then pairs, waking the sleeping that a moving object touches), the
velocities of all contacts together, the overlap past slop (solver.py), and sleep (sleep.py),
a body falling asleep inside a static object stopping the run (sunk.py: `advance` raises
`sunk.Sunk`, a runaway, naming it). With no object awake a step does nothing.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.broadphase import choose, marker, workspace
from collide2d.engine.events import event_records, new_log
from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.fall import MAX_HITS_PER_STEP, fall
from collide2d.engine.models.stepped.land import land
from collide2d.engine.models.stepped.move import BODY_COLUMNS
from collide2d.engine.models.stepped.records import Fall, Physics, Step, Touch
from collide2d.engine.models.stepped.sleep import doze
from collide2d.engine.models.stepped.solver import correct, energy, kinetic, solve
from collide2d.engine.models.stepped.sunk import inside, sunk_error
from collide2d.engine.models.stepped.touch import (
    C_COLUMNS,
    CONTACTS_PER_OBJECT,
    N_AWAKE,
    N_CONTACTS,
    N_KEYS,
    N_PAIRS,
    N_RELIST,
    N_SIZE,
    N_WALLS,
    cap_goals,
    keep,
    pair_contacts,
    relist,
    walls,
    warm,
)
from collide2d.engine.shapes import build_cores
from collide2d.engine.sort import median

# The defaults of the options (docs/scenario-format.md#model).
ITERATIONS = 8
SLOP_PX = 0.1
SLEEP_AFTER_S = 0.5
# The rest speed when not given: this many times |g|·dt of a substep (what a step of gravity
# adds, twice over: a body at rest gains |g|·dt each step and gives it back to its support).
REST_STEPS = 2.0
# The candidate list's margin: each box grown by this share of the median box side, at least
# HALF_MIN_PX (px). Wider: fewer new lists, more pairs listed.
HALF_SIDES = 0.2
HALF_MIN_PX = 0.5
# The list is made anew once an awake object is within this of half the margin (px).
DRIFT_SLACK_PX = 1e-9


def settles(world, bodies) -> bool:
    """Whether a scene takes the settling path: gravity, or some e < 1 or mu > 0."""
    return (
        world.has_gravity
        or world.restitution < 1.0
        or world.friction > 0.0
        or bool(np.any(bodies.restitution < 1.0))
        or bool(np.any(bodies.friction > 0.0))
    )


@njit(cache=True)
def step(F, P, T, at, sides, bufs, log):
    """One step (module docstring). bufs = (keys, pairs, floats, last_keys, last), the buffers
    that can grow; log = (rows, times, n_ev). Returns both, as they are now."""
    keys, pairs, floats, last_keys, last = bufs
    counts = T.counts
    if counts[N_AWAKE] == 0:  # everything static or asleep
        return bufs, log
    # move: exact motion under gravity, bounces off the walls (what they take noted)
    before = energy(F, P)
    drift, bounces, log = fall(F, P, at, sides, T.hits, log)
    counts[N_WALLS] += bounces
    # the candidate list anew once an awake object drifted half the margin, or one woke
    if counts[N_KEYS] < 0 or counts[N_RELIST] != 0 or drift >= P.half - DRIFT_SLACK_PX:
        keys = relist(F, P, T, keys)
    # landing: a body the move took far into a static object, back where it met it
    keys, _ = land(F, P, T, keys, at.dt)
    taken = max(before - energy(F, P), 0.0)
    # contacts: walls, then pairs by ids; starting from last step's impulses
    pairs, floats, m = walls(F, P, sides, pairs, floats, at.dt)
    pairs, floats, m, log = pair_contacts(
        F, P, T, keys, pairs, floats, m, at, log, (last_keys, last)
    )
    cap_goals(F, P, pairs, floats, m, T.capped)
    warm(T, pairs, floats, m, last_keys, last)
    counts[N_CONTACTS] = m
    # velocities: every contact together, then restitution; never more energy than the step began
    # with
    limit = solve(F, P, pairs, floats, m, taken, at.dt)
    # positions: overlap past slop, within the energy given up so far
    T.bank[0] += limit - kinetic(F)
    T.bank[0] -= correct(F, P, pairs, floats, m, T.bank[0], sides)
    last_keys, last = keep(T, pairs, floats, m, last_keys, last)
    # sleep: objects slow for sleep_after s; one asleep inside a static object stops the run
    counts[N_AWAKE], fell = doze(F, P, at.dt, T.capped)
    if fell:
        inside(F, P, T, keys, at.tick, T.capped)
    return (keys, pairs, floats, last_keys, last), log


@njit(cache=True)
def run(F, P, T, bufs, world, tick0, ticks, log_on, log):
    """Run ticks tick0+1 ... tick0+ticks; world = (width, height, fps, substeps). Returns (bufs,
    log) as `step`."""
    width, height, fps, substeps = world
    dt = 1.0 / (fps * substeps)
    sides = (width, height)
    for tick in range(tick0 + 1, tick0 + ticks + 1):
        at = Step(dt, width, height, T.exact, tick, tick / fps, log_on)
        for _ in range(substeps):
            bufs, log = step(F, P, T, at, sides, bufs, log)
            if T.sunk[0] >= 0.0:  # a body asleep inside a static object: the run stops here
                return bufs, log
    return bufs, log


def rest_speed_for(world, substeps: int, rest_speed) -> float:
    """The rest speed in force, px/s: none (0) without gravity; else `rest_speed`, by default
    REST_STEPS x |g|·dt of a substep."""
    if not world.has_gravity:
        return 0.0
    if rest_speed is None:
        g = math.hypot(*world.gravity)
        return REST_STEPS * g / (world.fps * substeps)
    return float(rest_speed)


def check_options(iterations, slop, rest_speed, sleep, sleep_after) -> None:
    """ValueError naming the first option out of range."""
    if isinstance(iterations, bool) or int(iterations) != iterations or iterations < 1:
        raise ValueError(f"iterations must be a whole number >= 1, got {iterations!r}")
    if not (math.isfinite(slop) and slop >= 0.0):
        raise ValueError(f"slop must be a number >= 0, got {slop!r}")
    if rest_speed is not None and not (math.isfinite(rest_speed) and rest_speed >= 0.0):
        raise ValueError(f"rest_speed must be a number >= 0, got {rest_speed!r}")
    if not isinstance(sleep, (bool, np.bool_)):
        raise ValueError(f"sleep must be true or false, got {sleep!r}")
    if not (sleep_after >= 0.0):
        raise ValueError(f"sleep_after must be a number of seconds >= 0, got {sleep_after!r}")


class Settle:
    """The settling path's state and its run (module docstring)."""

    def __init__(self, world, bodies, substeps, geometry, iterations, slop, rest_speed, sleep,
                 sleep_after):  # fmt: skip
        check_options(iterations, slop, rest_speed, sleep, sleep_after)
        self.world = world
        self.substeps = int(substeps)
        n = bodies.n
        static = np.ascontiguousarray(bodies.static, bool).copy()
        body = np.empty((n, BODY_COLUMNS))
        body[:, 0:2] = bodies.pos
        body[:, 2:4] = np.where(static[:, None], 0.0, bodies.vel)
        body[:, 4:6] = bodies.size
        inv_mass = np.array(bodies.inv_mass, np.float64)
        self._F = Fall(
            body=body,
            inv_mass=inv_mass,
            mass=np.where(static, 0.0, bodies.mass).astype(np.float64),
            static=static,
            restitution=np.ascontiguousarray(bodies.restitution, np.float64).copy(),
            friction=np.ascontiguousarray(bodies.friction, np.float64).copy(),
            awake=~static,
            asleep=np.zeros(n, bool),
            quiet=np.zeros(n),
            anchor=body[:, 0:2].copy(),
            saved=np.zeros((n, 2)),
        )
        side = median(bodies.size.max(axis=1)) if n else 1.0
        half = max(HALF_SIDES * side, HALF_MIN_PX)
        self._P = Physics(
            gx=float(world.gravity[0]),
            gy=float(world.gravity[1]),
            restitution=float(world.restitution),
            friction=float(world.friction),
            rest=rest_speed_for(world, self.substeps, rest_speed),
            slop=float(slop),
            iterations=int(iterations),
            sleep_after=float(sleep_after) if sleep else math.inf,
            half=half,
        )
        method, cell = choose(world.width, world.height, bodies.size + 2.0 * half, None)
        cores = build_cores(bodies, "exact" if geometry == "exact" else "box")
        counts = np.zeros(N_SIZE, np.int64)
        counts[N_KEYS] = -1
        counts[N_AWAKE] = int((~static).sum())
        room = max(16, CONTACTS_PER_OBJECT * n)
        self._T = Touch(
            keys=np.empty(room, np.int64),
            pairs=np.empty(room, np.int64),
            floats=np.empty((room, C_COLUMNS)),
            last_keys=np.empty(room, np.int64),
            last=np.empty((room, 4)),
            counts=counts,
            lo=np.empty((n, 2)),
            hi=np.empty((n, 2)),
            order=np.arange(n, dtype=np.int64),
            ws=workspace(n),
            finder=marker(method),
            cell=float(cell),
            cores=(cores.shape, cores.radius, cores.start, cores.verts, cores.normals),
            exact=geometry == "exact",
            hits=np.zeros(MAX_HITS_PER_STEP + 1, np.int64),
            capped=np.zeros(n, bool),
            heads=np.zeros(2 * n + 1, np.int64),
            bank=np.zeros(1),
            sunk=np.array([-1.0, -1.0, 0.0, 0.0]),
        )
        self.tick = 0

    def advance(self, ticks: int, log: bool) -> np.ndarray:
        """Run `ticks` ticks; the events in order (empty when log is False). Raises sunk.Sunk
        (a runaway) when a body falls asleep inside a static object."""
        T = self._T
        world = (float(self.world.width), float(self.world.height), float(self.world.fps),
                 self.substeps)  # fmt: skip
        rows, times = new_log(log)
        bufs = (T.keys, T.pairs, T.floats, T.last_keys, T.last)
        bufs, (rows, times, n) = run(
            self._F, self._P, T, bufs, world, self.tick, int(ticks), bool(log),
            (rows, times, np.int64(0)),
        )  # fmt: skip
        keys, pairs, floats, last_keys, last = bufs
        self._T = T._replace(keys=keys, pairs=pairs, floats=floats, last_keys=last_keys, last=last)
        if T.sunk[0] >= 0.0:
            self.tick = int(T.sunk[2])
            raise sunk_error(T.sunk, self.world.gravity, 1.0 / (self.world.fps * self.substeps))
        self.tick += int(ticks)
        return event_records(rows, times, int(n))

    def positions(self) -> np.ndarray:
        return self._F.body[:, 0:2].copy()

    def velocities(self) -> np.ndarray:
        return self._F.body[:, 2:4].copy()

    def asleep(self) -> np.ndarray:
        """(n,) bool: which objects sleep."""
        return self._F.asleep.copy()

    def event_counts(self) -> tuple[int, int]:
        counts = self._T.counts
        return int(counts[N_WALLS]), int(counts[N_PAIRS])
