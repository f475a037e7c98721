"""The stepped model's step and run loop: one kernel, `step`, whose stages run in the order of
STAGES (move, broad, narrow, response), and `run`, which runs every stage of every step of a
number of ticks in one call.

Input: the world (width, height, fps), the substeps, the state (`records.State`), the geometry,
the exact shapes' cores, the event log's buffers and the broad phase's state and scratch
(`records.Lists`). Output: the state advanced in place, the events logged, and the buffers that
grew, which replace the caller's.

While the candidate list holds, a step runs its move and narrow stages together, block by block
(narrow.move_narrow: the same pairs, tested while their rows are in the cache); a step
that may make the list anew runs them apart, as `model.Model.profile` always does.

`run` takes any number of ticks per call (the runner asks for thousands at once), so the cost of
entering the kernel from Python is paid once per call, not once per step. `model.Model.profile`
runs the same `step` one stage at a time to time each.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.candidates import (
    P_DRIFT,
    P_GROWTH,
    P_MARGIN,
    P_REACH,
    P_SLACK,
    ST_CHUNKS,
    ST_FUSED,
    ST_KEYS,
    ST_NEAR,
    ST_POSSIBLE,
    ST_WALLS,
    relist,
    start_reach,
    within_reach,
)
from collide2d.engine.models.stepped.move import log_walls, move_walls
from collide2d.engine.models.stepped.narrow import move_narrow, narrow
from collide2d.engine.models.stepped.pairs import respond
from collide2d.engine.models.stepped.records import Lists, Move, State, Step, Sweep

# The stages of one step, in the order `step` runs them; `Model.profile` times each by name
# through the same kernel.
STAGES = ("move", "broad", "narrow", "response")
_MOVE, _BROAD, _NARROW, _RESPONSE = range(len(STAGES))
# `run` passes the stages to `step` as these literal numbers: numba then compiles a `step` for
# exactly all of them, with no stage test left (about a sixth faster at 1,000 objects than with
# `len(STAGES)`, which it passes as a number known only when run).
_FIRST, _LAST = 0, 4
assert _LAST == len(STAGES)
# A step runs its move and narrow stages together when the drift, grown by this many times what
# it grew in the last step, stays short of the margin (a step that then finds the margin reached
# after all makes the list anew and tests again: the time of one narrow phase lost).
AHEAD_STEPS = 1.25


@njit(cache=True)
def _holds(state, params):
    """Whether the candidate list will hold for the coming step: there is one, and its drift,
    grown by AHEAD_STEPS x what it grew in the last step, stays short of the margin."""
    if state[ST_KEYS] < 0:
        return False
    ahead = params[P_DRIFT] + AHEAD_STEPS * params[P_GROWTH]
    return ahead < params[P_MARGIN] - params[P_SLACK]


@njit(cache=True)
def step(first, last, state, at, cores, rows, times, n_ev, lists):
    """Run the stages first ... last-1 (of STAGES) of one step; returns (event buffers, how many
    events, (keys, spare, near, when)): the buffers that grew replace the caller's. state, at and
    lists are the fields of a `State`, a `Step` and a `Lists` (records.py), as plain tuples. What a
    stage hands the next waits in the lists between calls: the drift in params[P_DRIFT], the
    overlapping pairs in state[ST_NEAR]."""
    L = Lists(*lists)
    return _stages(first, last, State(*state), Step(*at), cores, rows, times, n_ev, L, _growing(L))


@njit(cache=True, inline="always")
def _growing(L):
    """The buffers of `L` that can grow, in the order `_stages` keeps them."""
    return L.keys, L.spare, L.near, L.when


@njit(cache=True)
def _stages(first, last, S, at, cores, rows, times, n_ev, L, lists):
    """`step` on the records themselves, with the buffers that can grow apart from L: lists =
    (keys, spare, near, when) (L's own fields for them are not read); returns (event buffers, how
    many events, lists). `run` keeps them apart from L between steps, so that a step hands back
    these four arrays and not all of L's (each array handed back costs two atomic reference
    counts: handing back all of the record took a step's fixed cost, measured on two objects,
    from 0.6 to 1.0 us)."""
    body, anchor = S.body, S.anchor
    folds, state, params = L.folds, L.state, L.params
    keys, spare, near, when = lists
    dt = at.dt
    chunks = state[ST_CHUNKS]
    sides = (at.width, at.height)
    # the move and the narrow phase block by block, while the list will hold for this step
    fused = first == _MOVE and last == _LAST and state[ST_POSSIBLE] != 0 and _holds(state, params)
    if first <= _MOVE < last:
        # move, walls: every object; the walls' events in id order; how far anything drifted
        # from where the candidate list was made, and how far its path reached
        if fused:
            swept = Sweep(body, S.ext, keys, state, near, when, dt, at.width, at.height)
            moved = Move(S.static, anchor, folds, params)
            n_folds, drift, state[ST_NEAR] = move_narrow(swept, moved, chunks)
            state[ST_FUSED] += 1
        else:
            n_folds, drift = move_walls(body, S.static, S.ext, anchor, dt, sides, folds, chunks)
        params[P_REACH] = max(drift, start_reach(params))
        params[P_GROWTH] = max(drift - params[P_DRIFT], 0.0)
        params[P_DRIFT] = drift
        if n_folds:
            for r in range(n_folds):  # one wall event per fold
                state[ST_WALLS] += folds[r, 1] + folds[r, 2]
            if at.log:
                rows, times, n_ev = log_walls(folds, n_folds, at.tick, at.t, rows, times, n_ev)
    if state[ST_POSSIBLE] == 0:  # no pair can happen
        return rows, times, n_ev, lists
    tested = fused
    if first <= _BROAD < last:
        # the candidate list made anew once an object drifted its margin (what the step tested
        # on the old list then does not count)
        if state[ST_KEYS] < 0 or params[P_DRIFT] >= params[P_MARGIN] - params[P_SLACK]:
            keys, spare, state[ST_KEYS] = relist(S, dt, L, keys, spare)
            lists = (keys, spare, near, when)
            tested = False
    if first <= _NARROW < last and not (tested and state[ST_NEAR] <= near.shape[0]):
        # the listed pairs in contact this step, in the order their contacts began, from the
        # bands near enough to touch by now
        bands = within_reach(params)
        ext = S.ext
        state[ST_NEAR] = narrow(body, ext, keys, state, bands, near, when, dt, sides, chunks)
        while state[ST_NEAR] > near.shape[0]:
            near = np.empty(2 * state[ST_NEAR], np.int64)
            when = np.empty(2 * state[ST_NEAR])
            lists = (keys, spare, near, when)
            state[ST_NEAR] = narrow(body, ext, keys, state, bands, near, when, dt, sides, chunks)
    if first <= _RESPONSE < last:
        rows, times, n_ev = respond(S, at, cores, near, state[ST_NEAR], rows, times, n_ev, L)
    return rows, times, n_ev, lists


@njit(cache=True)
def run(world, substeps, tick0, ticks, log, state, exact, cores, rows, times, lists):
    """Run ticks tick0+1 ... tick0+ticks, every step all of `step`; returns (event buffers, how
    many events, (keys, spare, near, when)): the buffers that grew replace the caller's.

    world = (width, height, fps); state: the fields of a `State`, lists those of a `Lists`
    (records.py), as plain tuples.
    """
    width, height, fps = world
    dt = 1.0 / (fps * substeps)
    n_ev = np.int64(0)  # not the literal 0, which would compile step once more for it
    S, L = State(*state), Lists(*lists)
    grows = _growing(L)
    for tick in range(tick0 + 1, tick0 + ticks + 1):
        t = tick / fps
        at = Step(dt, width, height, exact, tick, t, log)
        for _ in range(substeps):
            rows, times, n_ev, grows = _stages(
                _FIRST, _LAST, S, at, cores, rows, times, n_ev, L, grows
            )
    return rows, times, n_ev, grows
