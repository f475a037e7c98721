"""The stepped model's step and run loop: one kernel, `step`, whose stages run in the order of
STAGES (move, broad, narrow, response), and `run`, which runs every stage of every step of a
number of ticks in one call.

Input: the world (width, height, fps), the substeps, the state (`stepped.State`), the geometry,
the exact shapes' cores, the event log's buffers and the broad phase's state and scratch (`bp`,
below). Output: the state advanced in place, the events logged, and the buffers that grew, which
replace the caller's.

`run` takes any number of ticks per call (the runner asks for thousands at once), so the cost of
entering the kernel from Python is paid once per call, not once per step. `stepped.Model.profile`
runs the same `step` one stage at a time to time each.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit
from collide2d.engine.models.stepped_list import (
    P_DRIFT,
    P_MARGIN,
    P_SLACK,
    ST_CHUNKS,
    ST_KEYS,
    ST_NEAR,
    ST_POSSIBLE,
    ST_WALLS,
    relist,
    within_reach,
)
from collide2d.engine.models.stepped_motion import log_walls, move_walls
from collide2d.engine.models.stepped_narrow import narrow
from collide2d.engine.models.stepped_pairs import respond

# The stages of one step, in the order `step` runs them; `Model.profile` times each by name
# through the same kernel.
STAGES = ("move", "broad", "narrow", "response")
_MOVE, _BROAD, _NARROW, _RESPONSE = range(len(STAGES))
# `run` passes the stages to `step` as these literal numbers: numba then compiles a `step` for
# exactly all of them, with no stage test left (about a sixth faster at 1,000 objects than with
# `len(STAGES)`, which it passes as a number known only when run).
_FIRST, _LAST = 0, 4
assert _LAST == len(STAGES)


@njit(cache=True)
def step(first, last, S, dt, width, height, exact, cores, tick, t, log, rows, times, n_ev, bp):
    """Run the stages first ... last-1 (of STAGES) of one step; returns (event buffers, how many
    events, bp): the buffers that grew replace the caller's. What a stage hands the next waits
    in bp between calls: the drift in params[P_DRIFT], the overlapping pairs in state[ST_NEAR]."""
    keys, near, order, lo, hi, folds, state, params, ws, when, finder, scratch, spare = bp
    rows, times, n_ev, lists = _stages(
        first, last, S, dt, width, height, exact, cores, tick, t, log, rows, times, n_ev, bp,
        (keys, spare, near, when),
    )
    keys, spare, near, when = lists
    return rows, times, n_ev, (
        keys, near, order, lo, hi, folds, state, params, ws, when, finder, scratch, spare
    )


@njit(cache=True)
def _stages(first, last, S, dt, width, height, exact, cores, tick, t, log, rows, times, n_ev, bp,
            lists):
    """`step`, with the buffers that can grow apart from bp: lists = (keys, spare, near, when)
    (bp's own slots for them are not read); returns (event buffers, how many events, lists).
    `run` keeps them apart from bp between steps, so that a step hands back these four arrays
    and not all of bp's (each array handed back costs two atomic reference counts: handing back
    all of bp took a step's fixed cost, measured on two objects, from 0.6 to 1.0 us)."""
    body, inv_mass, static, movable, ext, rank, anchor = S
    _, _, order, lo, hi, folds, state, params, ws, _, finder, scratch, _ = bp
    keys, spare, near, when = lists
    chunks = state[ST_CHUNKS]
    if first <= _MOVE < last:
        # move, walls: every object; the walls' events in id order; how far anything drifted
        # from where the candidate list was made
        n_folds, params[P_DRIFT] = move_walls(body, static, ext, anchor, dt, folds, chunks)
        if n_folds:
            for r in range(n_folds):  # one wall event per fold
                state[ST_WALLS] += folds[r, 1] + folds[r, 2]
            if log:
                rows, times, n_ev = log_walls(folds, n_folds, tick, t, rows, times, n_ev)
    if state[ST_POSSIBLE] == 0:  # no pair can happen
        return rows, times, n_ev, lists
    if first <= _BROAD < last:
        # the candidate list made anew once an object drifted its margin
        if state[ST_KEYS] < 0 or params[P_DRIFT] >= params[P_MARGIN] - params[P_SLACK]:
            keys, spare, state[ST_KEYS] = relist(
                S, dt,
                (keys, near, order, lo, hi, folds, state, params, ws, when, finder, scratch, spare),
            )  # fmt: skip
            lists = (keys, spare, near, when)
    if first <= _NARROW < last:
        # the listed pairs in contact this step, in the order their contacts began, from the
        # bands near enough to touch by now
        n_keys = within_reach(state, params)
        state[ST_NEAR] = narrow(body, ext, keys, n_keys, near, when, dt, chunks)
        while state[ST_NEAR] > near.shape[0]:
            near = np.empty(2 * state[ST_NEAR], np.int64)
            when = np.empty(2 * state[ST_NEAR])
            lists = (keys, spare, near, when)
            state[ST_NEAR] = narrow(body, ext, keys, n_keys, near, when, dt, chunks)
    if first <= _RESPONSE < last:
        rows, times, n_ev = respond(
            S,
            dt,
            width,
            height,
            exact,
            cores,
            near,
            state[ST_NEAR],
            folds,
            tick,
            t,
            log,
            rows,
            times,
            n_ev,
            state,
        )
    return rows, times, n_ev, lists


@njit(cache=True)
def run(world, substeps, tick0, ticks, log, S, exact, cores, rows, times, bp):
    """Run ticks tick0+1 ... tick0+ticks, every step all of `step`; returns (event buffers, how
    many events, bp): the buffers that grew replace the caller's.

    S: the state arrays (a `stepped.State`). bp = (keys, near, order, lo, hi, folds, state,
    params, ws, when, finder, scratch, spare): the candidate list kept between calls (sorted by
    band, stepped_list.within_reach) and scratch
    (`near`, `when`: this step's pairs in contact and the times their contacts began; `order`,
    `lo`, `hi`, `ws`: the broad phase's; `folds`: the move's fold rows; `finder`: the marker of
    the method, broadphase.marker, so that a kernel compiles only that pair finder; `scratch`:
    the reorder's, stepped_list; `spare`: a second key buffer the relist sorts into); state and
    params as stepped_list names their slots (ST_*,
    P_*).
    """
    width, height, fps = world
    dt = 1.0 / (fps * substeps)
    n_ev = np.int64(0)  # not the literal 0, which would compile step once more for it
    keys, near, order, lo, hi, folds, state, params, ws, when, finder, scratch, spare = bp
    lists = (keys, spare, near, when)
    for tick in range(tick0 + 1, tick0 + ticks + 1):
        t = tick / fps
        for _ in range(substeps):
            rows, times, n_ev, lists = _stages(
                _FIRST,
                _LAST,
                S,
                dt,
                width,
                height,
                exact,
                cores,
                tick,
                t,
                log,
                rows,
                times,
                n_ev,
                bp,
                lists,
            )
    keys, spare, near, when = lists
    return rows, times, n_ev, (
        keys, near, order, lo, hi, folds, state, params, ws, when, finder, scratch, spare
    )
