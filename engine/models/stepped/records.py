"""The stepped model's state records, read by field in every kernel: `State` (the objects),
`Lists` (the candidate list kept between steps, the broad phase's state and the stages'
scratch), `Step` (what one step is run with), and the groups the candidate list and the narrow
phase hand their kernels: `Sweep` (what the narrow phase tests and writes), `Move` (what the move
run with it needs besides) and `Scratch` (the reorder's scratch).

numba takes a named tuple as it takes a tuple, but reads the type of one handed to it from Python
field by field (microseconds a call, against a fraction of one for a plain tuple): the kernels
that Python calls (step.run, step.step) take each record as a plain tuple of its fields and name
it again inside (`State(*state)`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class State(NamedTuple):
    """The stepped model's state arrays, every row in the broad phase's order."""

    body: np.ndarray  # (n, 6) float64 per object x, y (top-left corner, px), vx, vy (px/s),
    # w, h (px): move.B_*
    inv_mass: np.ndarray  # (n,) float64, 0 for static objects
    static: np.ndarray  # (n,) bool
    movable: np.ndarray  # (n,) bool: what the broad phase pairs
    ext: np.ndarray  # (n,) int64 the id of each row
    rank: np.ndarray  # (n,) int64 the row of each id
    anchor: np.ndarray  # (n, 2) float64 where each was when the candidate list was made, px


class Lists(NamedTuple):
    """The candidate list kept between calls (sorted by bucket, candidates.py), the broad
    phase's state and the stages' scratch. `keys`, `near`, `when` and `spare` can grow: a step
    hands the four back (step.run), and the kernels keep them apart from the record meanwhile."""

    keys: np.ndarray  # int64 the candidate list
    near: np.ndarray  # int64 this step's pairs in contact
    order: np.ndarray  # (n,) int64 the broad phase's order
    lo: np.ndarray  # (n, 2) float64 grown boxes, low corners
    hi: np.ndarray  # (n, 2) float64 grown boxes, high corners
    folds: np.ndarray  # (2n, 4) int64 the move's fold rows
    state: np.ndarray  # int64 scalar state, slots candidates.ST_*
    params: np.ndarray  # float64 scalar state, slots candidates.P_*
    ws: tuple  # the pair finders' scratch (broadphase.workspace)
    when: np.ndarray  # float64 the times this step's contacts began
    finder: np.ndarray  # the method's marker (broadphase.marker: only that finder compiles)
    scratch: tuple  # the reorder's scratch (candidates._reorder)
    spare: np.ndarray  # int64 a second key buffer the relist sorts into


class Step(NamedTuple):
    """What one step is run with."""

    dt: float  # its length, s
    width: float  # the world's sides, px
    height: float
    exact: bool  # whether objects collide by their real shapes (shapes.py), not their boxes
    tick: int  # the tick it belongs to
    t: float  # the time of that tick's end, s (the events' time)
    log: bool  # whether events are logged


class Sweep(NamedTuple):
    """What the narrow phase (narrow.py) tests the candidate list with, and writes its pairs in
    contact to. (No tuple among its fields: numba hands a record to the threads of a parallel
    loop only when it holds none.)"""

    body: np.ndarray  # State.body
    ext: np.ndarray  # State.ext
    keys: np.ndarray  # the candidate list (Lists.keys)
    state: np.ndarray  # Lists.state: where each bucket of the list begins (candidates.ST_BANDS)
    near: np.ndarray  # out: the pairs in contact (Lists.near)
    when: np.ndarray  # out: the times their contacts began (Lists.when)
    dt: float  # the step, s
    width: float  # the world's sides, px
    height: float


class Move(NamedTuple):
    """What the move run together with the narrow phase (narrow.move_narrow) needs besides a
    `Sweep`."""

    static: np.ndarray  # State.static
    anchor: np.ndarray  # State.anchor
    folds: np.ndarray  # Lists.folds
    params: np.ndarray  # Lists.params (candidates.P_*), as the last step left them


class Scratch(NamedTuple):
    """The reorder's scratch (candidates._reorder), one row per slot: the state's rows gathered
    in the new order."""

    rows: np.ndarray  # (n, 6) float64 the body rows
    ids: np.ndarray  # (n,) int64 the ids (then, old index to new)
    flags: np.ndarray  # (n,) uint8 static | movable << 1
    masses: np.ndarray  # (n,) float64 the inverse masses


# --- the settling path: gravity, restitution, friction and sleep (settle.py) -------------------


class Fall(NamedTuple):
    """The state of the settling path (settle.py), every row in id order."""

    body: np.ndarray  # (n, 6) float64 x, y, vx, vy, w, h: move.B_*
    inv_mass: np.ndarray  # (n,) float64, 0 for static objects
    mass: np.ndarray  # (n,) float64, 0 for static objects (their energy is not counted)
    static: np.ndarray  # (n,) bool
    restitution: np.ndarray  # (n,) float64 e in [0, 1]
    friction: np.ndarray  # (n,) float64 mu >= 0
    awake: np.ndarray  # (n,) bool: moved and paired (not static, not asleep)
    asleep: np.ndarray  # (n,) bool
    quiet: np.ndarray  # (n,) float64 seconds it has been slower than the rest speed
    anchor: np.ndarray  # (n, 2) float64 where each was when the candidate list was made, px
    saved: np.ndarray  # (n, 2) float64 scratch: velocities or positions before a pass


class Physics(NamedTuple):
    """The settling path's constants (docs/models.md#stepped-gravity-restitution-and-friction)."""

    gx: float  # gravity, px/s^2 (y down)
    gy: float
    restitution: float  # the walls' e
    friction: float  # the walls' mu
    rest: float  # the rest speed, px/s (0 without gravity: no rest rule)
    slop: float  # the overlap left in place, px
    iterations: int  # velocity passes (and position passes) per step
    sleep_after: float  # seconds below the rest speed before sleeping (inf: never)
    half: float  # half the candidate list's margin, px


class Touch(NamedTuple):
    """The settling path's candidate list, its contacts and their scratch. `keys`, `pairs`,
    `floats`, `last_keys` and `last` can grow: `settle.run` hands them back."""

    keys: np.ndarray  # int64 the candidate list (sorted keys of ids, broadphase.KEY_SHIFT)
    pairs: np.ndarray  # (m,) int64 this step's contacts as keys (touch.py), sorted
    floats: np.ndarray  # (m, C_COLUMNS) float64 this step's contacts (touch.C_*)
    last_keys: np.ndarray  # (m,) int64 last step's contacts' keys
    last: np.ndarray  # (m, 4) float64 their normal and friction impulses and their normals
    counts: np.ndarray  # int64 scalar state, slots touch.N_*
    lo: np.ndarray  # (n, 2) float64 grown boxes, low corners
    hi: np.ndarray  # (n, 2) float64 grown boxes, high corners
    order: np.ndarray  # (n,) int64 the broad phase's order
    ws: tuple  # the pair finder's scratch (broadphase.workspace)
    finder: np.ndarray  # the method's marker (broadphase.marker)
    cell: float  # the grid's cell, px
    cores: tuple  # the exact shapes (shapes.build_cores) when colliding by them
    exact: bool  # whether objects collide by their real shapes
    hits: np.ndarray  # int64 scratch: one object's bounces in a step (fall.fall_one)
    capped: np.ndarray  # (n,) bool scratch (touch.cap_goals; sleep.doze marks who fell asleep)
    heads: np.ndarray  # (2n + 1,) int64 scratch: the candidate list's sort (sort.sort_pair_keys)
    bank: np.ndarray  # (1,) float64 energy given up so far and not yet spent on pushes (solver)
    sunk: np.ndarray  # (4,) float64 a body asleep inside a static object (sunk.py): its id, the
    # static object's, the tick, the depth (px); id -1 while there is none
