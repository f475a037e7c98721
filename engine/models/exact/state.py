"""The exact model's state layout: its records, the columns of its arrays, its scalar state, its
statuses.

The exact model (model.py) keeps its objects in two arrays, floats F (n, 8) and ints N (n, 8),
what only gravity and impacts read in P (n, 4) and R (n,), what the storm check counts in
`instants` (jam.py), and its counters in `st` (int64) and `stf` (float64); the event queue
(heap.py), the grid lists (cells.py) and the predictions (prediction.py) all read them by the
names below.
Its kernels share one record, `State`, read by field, which holds the others: `World` (the
world's sides, fps and grid), `Cores` (the exact shapes) and `Horizons` (the horizon queue,
horizonqueue.py); a heap entry travels as an `Entry`.

numba takes a named tuple as it takes a tuple, but reads the type of one handed to it from Python
field by field (microseconds a call, against a fraction of one for a plain tuple): Python hands
the kernel `model._run` the state as plain tuples (`plain`), and the kernel names them again
(`named`). The `hot` and `kernel` decorators the exact model's kernels are compiled with live
here too.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from collide2d.engine.jit import njit


class World(NamedTuple):
    """The world the kernels see: its sides, its frame rate and its grid (cells.py)."""

    width: float  # px
    height: float  # px
    fps: float  # ticks per second
    cell: float  # the grid's cell side, px
    gnx: int  # the grid's columns
    gny: int  # the grid's rows
    restitution: float  # the walls' e
    friction: float  # the walls' mu
    gx: float  # gravity, px/s²
    gy: float
    rest_height: float  # px: a bounce on a wall that would rise less comes to rest on it
    elastic: bool  # no gravity, and every restitution 1 and friction 0: P is never read


class Cores(NamedTuple):
    """The objects' exact shapes (shapes.build_cores): the circles' radii, and each polygon's
    vertices and edge normals, object i's rows start[i]:start[i + 1]."""

    radius: np.ndarray  # (n,) float64, px
    start: np.ndarray  # (n + 1,) int64
    verts: np.ndarray  # (m, 2) float64, px
    normals: np.ndarray  # (m, 2) float64


class Horizons(NamedTuple):
    """The horizon queue (horizonqueue.py): each moving object's horizon, filed by its time in the
    buckets of a calendar queue."""

    time: np.ndarray  # (n,) float64 each object's horizon time, s (inf: none)
    code: np.ndarray  # (n,) int8 what it is: rank × 4 + side or direction
    links: np.ndarray  # (n, 2) int32 next and previous object in its bucket's list, Q_NEXT/Q_PREV
    heads: np.ndarray  # (slots,) int32 the first object of each ring slot (-1: empty)
    state: np.ndarray  # (3,) int64 scalar state, slots QS_* (horizonqueue.py)
    rate: float  # one over the bucket width, 1/s


class Entry(NamedTuple):
    """A heap entry (heap.py): a predicted event."""

    t: float  # its time, s
    key: int  # rank, a, b, code (heap.make_key)
    ca: int  # a's invalidation counter when it was predicted
    cb: int  # b's
    nx: float  # the contact normal (contact.py)
    ny: float


class State(NamedTuple):
    """The arrays the exact model's kernels share, handed to them as one argument."""

    F: np.ndarray  # (n, 8) float64, columns below
    N: np.ndarray  # (n, 8) int64, columns below
    P: np.ndarray  # (n, 4) float64, columns below: acceleration, restitution, friction
    R: np.ndarray  # (n,) int64: the wall side each object rests on (-1: none)
    instants: np.ndarray  # (n, 5) float64: each object's events at one instant (jam.py)
    C: Cores  # exact shapes
    cells: np.ndarray  # the grid's per-cell lists of movers (cells.py)
    s_start: np.ndarray  # each cell's first entry in s_items (static objects)
    s_items: np.ndarray  # the static objects filed in each cell
    HT: np.ndarray  # heap: event times
    HI: np.ndarray  # heap: event ids and counters
    HN: np.ndarray  # heap: contact normals
    Q: Horizons  # horizon queue: each object's horizon, filed in buckets (horizonqueue.py)
    st: np.ndarray  # int64 scalar state, indices S_* below
    stf: np.ndarray  # float64 scalar state, indices SF_* below
    world: World


def plain(S: State) -> tuple:
    """S as plain tuples, as the kernel `model._run` takes it (see the module docstring)."""
    return tuple(S._replace(C=tuple(S.C), Q=tuple(S.Q), world=tuple(S.world)))


# Columns of F (n, 8) float64: position (top-left, px) and velocity (px/s) valid at the object's
# own clock TLOC (s), box size (px), inverse mass (0 for static objects).
X, Y, VX, VY, TLOC, SW, SH, INV_MASS = range(8)
# Columns of N (n, 8) int64: invalidation counter, static flag, contact shape kind, grid cell,
# next / previous object in that cell's list (-1 for none), last query stamp (static objects),
# the partner of its last event if that was a pair (-1 otherwise).
CNT, STATIC, SHAPE, CELL, NEXT, PREV, STAMP, PARTNER = range(8)
# Columns of P (n, 4) float64, what only gravity and impacts read (apart from F and N, whose rows
# of 8 are one cache line each, as every event and prediction reads them: wider rows cost a
# scene without gravity up to 12 % of its steps/s): acceleration (px/s²: the world's gravity for
# a moving object, 0 for a static one, and along its wall only for a resting one), restitution
# and friction. R (n,) int64: what each object rests on: -1 nothing; a wall, its side (0-3); the
# face of a box j (static, or resting still), side + 4·(j + 1), the side being the one it presses
# into as it would a wall's (rest_side, rest_support).
AX, AY, E, MU = range(4)
# A horizon's `what` (besides wall sides 0-3 and directions 0-3): a resting object stops sliding,
# or slides past the edge of the static box it rests on.
STOP = 4
LEAVE = 5

# A prediction job (one row of `jobs`): the object, the partner to leave out (-1: none; for
# JOB_CROSS, the direction it crossed in), and its mode: JOB_EVENT (after an event of the object),
# JOB_FIRST (the first prediction: only static objects and higher ids, each pair once),
# JOB_CONTACTS (only contacts, no horizon: the extra predictions of `repredict="all"`), JOB_CROSS
# (after a cell crossing: its horizon, and contacts only with the cells it has just come next to).
J_OBJ, J_SKIP, J_HIGHER = range(3)
JOB_EVENT, JOB_FIRST, JOB_CONTACTS, JOB_CROSS = range(4)
# Rows of `jobs`: the (at most two) objects an event touched, and one for the extra predictions.
JOB_ROWS = 3
J_EXTRA = 2


# Cell-crossing directions.
DIR_LEFT, DIR_RIGHT, DIR_UP, DIR_DOWN = range(4)

# Scalar state st (int64): heap size, ticks done, events in the current tick, query stamp, event
# rows written in this `advance`, objects given their first prediction, wall events and pair
# events so far (logged or not), rests begun on a body that is not static (stacks), the repeats
# at one instant that make an event storm (jam.py; 0: none counted). stf (float64): the current
# time, s.
S_HEAP_N, S_TICK, S_TICK_EVENTS, S_STAMP, S_LOGGED, S_FIRST, S_WALLS, S_PAIRS, S_STACKED = range(9)
S_STORM = 9
ST_SIZE = 10
SF_T_NOW = 0


STATUS_DONE = 0
STATUS_CAP = 1
STATUS_HEAP_FULL = 2
STATUS_LOG_FULL = 3
STATUS_REST = 4  # a falling body would rest on another (the pair in jobs' first row)
STATUS_CARRIED = 5  # a body that carries another is knocked (it and the carried one, jobs' row 0)
STATUS_STORM = 6  # an event storm: the same contacts again and again at one instant (jam.py)

INF = np.inf
# Small helpers are inlined into the kernels (`hot`). The kernels (`kernel`) allocate nothing and
# only touch arrays handed to them, so they are compiled without numba's reference counting
# (`_nrt=False`, a private numba option; tests/engine/test_kernels.py compiles every kernel that
# uses it, so an upgrade that drops it fails loudly): counting references to those arrays at every
# inlined helper took ~85 % of the run time on event-heavy scenes.
hot = njit(cache=True, inline="always")
kernel = njit(cache=True, _nrt=False)
# What only gravity runs (a parabola's next wall, a slide, a rest) is compiled once on its own and
# called, not inlined (`cold`): inlined, it doubled the event loop's compile time (a cold kernel
# cache's minute) and its code, slowing the scenes without gravity that never run it.
cold = njit(cache=True)


@hot
def falls(world):
    """Whether the world has gravity: without it no object has an acceleration or rests, and the
    kernels read neither (a branch on the world, the same at every call)."""
    return world.gx != 0.0 or world.gy != 0.0


@hot
def rest_side(r):
    """The side a resting object presses into, of its R entry r (>= 0)."""
    return r & 3


@hot
def rest_support(r):
    """The box a resting object rests on, of its R entry r (-1: a wall, or no rest)."""
    return (r >> 2) - 1 if r >= 0 else -1


@hot
def named(state):
    """The State record of `state`, the plain tuples `plain` makes."""
    S = State(*state)
    return State(
        S.F,
        S.N,
        S.P,
        S.R,
        S.instants,
        Cores(*S.C),
        S.cells,
        S.s_start,
        S.s_items,
        S.HT,
        S.HI,
        S.HN,
        Horizons(*S.Q),
        S.st,
        S.stf,
        World(*S.world),
    )
