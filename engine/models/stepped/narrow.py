"""The stepped model's narrow phase: which listed pairs are in contact after a step, in the
order their contacts began.

Input: the state (`model.State`), the candidate keys (pairs of indices inside, from
`candidates`) and the step dt. Output: `near`, the pairs in contact as keys of object ids
ascending, sorted by `when`, the time each contact began (s from the step's start, swept back
along the pair's relative velocity; -inf when the motion cannot tell), then by key: a total
order, so the result is the same whatever order the objects are kept in inside.

A pair is in contact when its boxes overlap now with positive area, or overlapped during the step
(swept back on straight lines, both objects clear of the walls this step: a corner passed through
within it). Each bucket of the list (candidates.py) is tested only as far as its bands can touch
by now. Most listed pairs are far apart: a cheap reach test (contact.box_reach, without
branches) drops them before any sweep.

The kernels take what they test and write as one record, a `Sweep` (records.py), and the move's
own arrays as a `Move`.

`narrow` tests the list after the move; `move_narrow`, which a step runs while the list holds,
runs the move itself block by block and tests each block's own pairs right behind it, while the
block's rows are still in the cache (a large scene's rows are not once the whole move has passed:
at 100,000 objects that pass is 4.8 MB), then the pairs between blocks. Large scenes cut the
blocks into contiguous runs, one per thread, each writing its own share of `near`, joined in run
order before the sort.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.broadphase import KEY_MASK, KEY_SHIFT, index
from collide2d.engine.contact import axis_reach, box_sweep
from collide2d.engine.jit import njit, prange
from collide2d.engine.models.stepped.approach import box_clip
from collide2d.engine.models.stepped.candidates import (
    BANDS,
    ST_BANDS,
    block_count,
    block_rows,
    reach_bands,
    start_reach,
)
from collide2d.engine.models.stepped.move import (
    B_H,
    B_VX,
    B_VY,
    B_W,
    B_X,
    B_Y,
    join_folds,
    move_range,
)
from collide2d.engine.models.stepped.records import Sweep
from collide2d.engine.sort import sort_by_time
from collide2d.engine.threads import join_shares, shares_total


@njit(cache=True, inline="always")
def _swept_back(P, i):
    """Whether object i, moved back P.dt seconds on a straight line, is where it started the
    step: inside the world (an object that folded at a wall this step is not,
    docs/models.md#stepped-pairs)."""
    body, dt = P.body, P.dt
    x = body[i, B_X] - body[i, B_VX] * dt
    y = body[i, B_Y] - body[i, B_VY] * dt
    span_x = max(P.width - body[i, B_W], 0.0)
    span_y = max(P.height - body[i, B_H], 0.0)
    return 0.0 <= x <= span_x and 0.0 <= y <= span_y


@njit(cache=True)
def _contact_range(P, first, last, base, room):
    """The listed pairs P.keys[first:last] in contact during the step of P.dt s just taken,
    written to P.near[base:base + room] with the time each contact began in P.when while they
    fit; returns how many."""
    body, keys, ext, near, when, dt = P.body, P.keys, P.ext, P.near, P.when, P.dt
    k = 0
    for c in range(index(first), index(last)):  # unsigned indices: broadphase.index
        a = index(keys[c] >> KEY_SHIFT)
        b = index(keys[c] & KEY_MASK)
        qx = body[b, B_X] - body[a, B_X]
        qy = body[b, B_Y] - body[a, B_Y]
        wa, ha, wb, hb = body[a, B_W], body[a, B_H], body[b, B_W], body[b, B_H]
        now = (-wb < qx) & (qx < wa) & (-hb < qy) & (qy < ha)
        ux = body[b, B_VX] - body[a, B_VX]
        uy = body[b, B_VY] - body[a, B_VY]
        # box_reach, from where the pair was as the step began
        reach = axis_reach(qx - ux * dt, ux, -wb, wa, dt)
        reach = reach & axis_reach(qy - uy * dt, uy, -hb, ha, dt)
        if not (now | reach):  # most pairs: one branch, nearly always taken
            continue
        t_enter, _, _, _, _ = box_sweep(qx - ux * dt, qy - uy * dt, ux, uy, wa, ha, wb, hb)
        if not now and not (
            box_clip(qx, qy, ux, uy, wa, ha, wb, hb, dt)
            and _swept_back(P, a)
            and _swept_back(P, b)
        ):
            continue
        if k < room:
            ea = ext[a]
            eb = ext[b]
            near[index(base + k)] = (min(ea, eb) << KEY_SHIFT) | max(ea, eb)
            when[index(base + k)] = t_enter if -dt <= t_enter < dt else -math.inf
        k += 1
    return k


@njit(cache=True)
def _tested_range(P, bucket, bands, base, room):
    """`_contact_range` over the first `bands` bands of a bucket of the list (P.state[ST_BANDS +
    bucket] on, see candidates.py)."""
    at = ST_BANDS + bucket
    return _contact_range(P, P.state[at], P.state[at + bands], base, room)


@njit(cache=True)
def _blocks_range(P, first, last, bands, base, room):
    """`_tested_range` over both buckets (own pairs, then those reaching into earlier blocks) of
    blocks first ... last-1."""
    k = 0
    for block in range(first, last):
        for kind in range(2):
            k += _tested_range(P, (2 * block + kind) * BANDS, bands, base + k, room - k)
    return k


@njit(cache=True)
def narrow(body, ext, keys, state, bands, near, when, dt, sides, chunks):
    """The narrow phase: the pairs in the first `bands` bands of every bucket of the list that
    are in contact during the step, sorted by the time in `when`, then by key, when they fit;
    returns how many (the caller grows `near` and `when` and asks again). Split among `chunks`
    threads when more than one (`_narrow_split`)."""
    P = Sweep(body, ext, keys, state, near, when, dt, sides[0], sides[1])
    if chunks > 1:
        return _narrow_split(P, bands, chunks)
    room = near.shape[0]
    k = _blocks_range(P, 0, block_count(state), bands, 0, room)
    if k <= room:
        sort_by_time(when, near, k)
    return k


@njit(cache=True)
def _join_sorted(found, share, room, near, when):
    """The chunks' pairs in contact (chunk c's found[c] in its share of `share` slots) moved
    together and sorted by (time, key), a total order, so the result is the one of one thread;
    returns how many, or more than `room` when a share was too small."""
    total = shares_total(found, share, room)
    if total > room:
        return total
    k = join_shares(found, share, near)
    join_shares(found, share, when)
    sort_by_time(when, near, k)
    return k


@njit(cache=True, parallel=True)
def _narrow_split(P, bands, chunks):
    """`narrow` with the blocks cut into `chunks` contiguous runs, one per thread: run c writes
    its pairs into its own share of P.near and P.when, then the shares are joined
    (`_join_sorted`)."""
    room = P.near.shape[0]
    share = room // chunks
    blocks = block_count(P.state)
    found = np.zeros(chunks, np.int64)
    for c in prange(chunks):
        found[c] = _blocks_range(
            P, c * blocks // chunks, (c + 1) * blocks // chunks, bands, c * share, share
        )
    return _join_sorted(found, share, room, P.near, P.when)


@njit(cache=True)
def _move_blocks(P, M, n_folds, start, first, last, base, room):
    """Move blocks first ... last-1 one by one (fold rows from row n_folds), each block's own
    pairs tested right after its move, while its rows are in the cache: the bands that its own
    drift and `start` (where any object began the step, candidates.start_reach) allow, since
    both objects are in it. Returns (fold rows now, the blocks' drift, how many pairs in
    contact, written from P.near[base] while within room)."""
    body = P.body
    n = body.shape[0]
    rows = block_rows(n, block_count(P.state))
    drift = 0.0
    k = 0
    for block in range(first, last):
        n_folds, d = move_range(
            body, M.static, P.ext, M.anchor, min(n, block * rows), min(n, (block + 1) * rows),
            P.dt, (P.width, P.height), M.folds, n_folds,
        )
        drift = max(drift, d)
        bands = reach_bands(max(d, start), M.params)
        k += _tested_range(P, 2 * block * BANDS, bands, base + k, room - k)
    return n_folds, drift, k


@njit(cache=True)
def move_narrow(P, M, chunks):
    """The move (move.py) and the narrow phase (`narrow`) together, block by block: each
    block moved, then its own pairs tested while its rows are in the cache; then the pairs that
    reach into earlier blocks, with the drift of every object moved by then. The same pairs in
    contact as `narrow` after `move_walls` (the bands each pair needs are tested either way).
    Split among `chunks` threads when more than one (`_move_narrow_split`). P: a Sweep, M: a
    Move (records.py). Returns (fold rows and drift, as move_walls; how many pairs in contact,
    as narrow). The list must hold for this step: the caller makes it anew and tests again when
    the drift says it did not."""
    if chunks > 1:
        return _move_narrow_split(P, M, chunks)
    room = P.near.shape[0]
    start = start_reach(M.params)
    n_folds = 0
    drift = 0.0
    k = 0
    for block in range(block_count(P.state)):
        n_folds, d, found = _move_blocks(P, M, n_folds, start, block, block + 1, k, room - k)
        k += found
        drift = max(drift, d)
        bands = reach_bands(max(drift, start), M.params)
        k += _tested_range(P, (2 * block + 1) * BANDS, bands, k, room - k)
    if k <= room:
        sort_by_time(P.when, P.near, k)
    return n_folds, drift, k


@njit(cache=True, parallel=True)
def _move_narrow_split(P, M, chunks):
    """`move_narrow` with the blocks cut into `chunks` contiguous runs, one per thread: each run
    moves its blocks and tests their own pairs; once every block has moved, the pairs that reach
    into earlier blocks (perhaps another run's), with the reach of all. Fold rows and pairs in
    contact are joined in run order (move.join_folds, `_join_sorted`). (numba fuses two parallel
    loops whose calls take no array argument, not seeing those a record holds: these two stay
    apart as the second's bands need the first's drifts.)"""
    n = P.body.shape[0]
    room = P.near.shape[0]
    share = room // chunks
    blocks = block_count(P.state)
    rows = block_rows(n, blocks)
    start = start_reach(M.params)
    found = np.zeros(chunks, np.int64)
    fold_rows = np.zeros(chunks, np.int64)
    firsts = np.zeros(chunks, np.int64)
    drifts = np.zeros(chunks)
    for c in prange(chunks):
        first = min(n, (c * blocks // chunks) * rows)
        n_folds, drifts[c], found[c] = _move_blocks(
            P, M, 2 * first, start, c * blocks // chunks, (c + 1) * blocks // chunks, c * share,
            share,
        )
        fold_rows[c] = n_folds - 2 * first
        firsts[c] = first
    drift = drifts.max()
    bands = reach_bands(max(drift, start), M.params)
    for c in prange(chunks):
        for block in range(c * blocks // chunks, (c + 1) * blocks // chunks):
            found[c] += _tested_range(
                P, (2 * block + 1) * BANDS, bands, c * share + found[c], share - found[c]
            )
    n_folds = join_folds(M.folds, fold_rows, firsts)
    return n_folds, drift, _join_sorted(found, share, room, P.near, P.when)
