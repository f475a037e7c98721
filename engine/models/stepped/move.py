"""The stepped model's first stage: every object moves for one step and folds back at the walls.

Input: the model's state (`model.State`: one row of `body` per object, x, y, vx, vy, w, h, in
the broad phase's order), the step dt and the world's sides. Output: the state moved
in place, the wall folds as rows (object id and axis, folds at the low and the high wall, which
came first) logged in id order, and how far any object now is from where the candidate list was
made (its anchor), which tells the candidate list when to be made anew.

Each object's row is read and written once, in order: a stream through memory. Scenes of many
objects cut the objects into contiguous runs, one per thread (`engine.threads`), whose fold rows
are joined in run order: the same rows, drift and state, to the bit, on any number of threads.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.broadphase import index
from collide2d.engine.events import EV_WALL, SIDE_BOTTOM, SIDE_LEFT, SIDE_RIGHT, SIDE_TOP, log_event
from collide2d.engine.jit import njit, prange
from collide2d.engine.response import fold
from collide2d.engine.sort import heap_argsort

# The columns of a row of the state's `body` (n, 6) float64: the top-left corner (px), the
# velocity (px/s) and the box's size (px). The room it has on each axis, the world's side less
# the box's, is worked out where it is needed: a step costs less arithmetic than memory.
B_X, B_Y, B_VX, B_VY, B_W, B_H = range(6)
BODY_COLUMNS = 6


@njit(cache=True, inline="always")
def _fold_row(folds, n_folds, e, axis, low, high, first_low):
    """Note that object e folded on `axis` (low, high folds; the low wall first)."""
    if low + high == 0:
        return n_folds
    folds[n_folds, 0] = 2 * e + axis  # the order of the events: by id, x before y
    folds[n_folds, 1] = low
    folds[n_folds, 2] = high
    folds[n_folds, 3] = first_low
    return n_folds + 1


@njit(cache=True)
def move_range(body, static, ext, anchor, first, last, dt, sides, folds, n_folds):
    """Move objects first ... last-1 (inside) for dt seconds and reflect each back into the
    world of `sides` (width, height) px; their fold rows go to folds from row n_folds. Returns
    (rows now, the farthest any of them is from its anchor on an axis, px)."""
    drift = 0.0
    for i in range(index(first), index(last)):  # unsigned indices: broadphase.index
        if static[i]:
            continue
        x = body[i, B_X] + body[i, B_VX] * dt
        y = body[i, B_Y] + body[i, B_VY] * dt
        sx = sides[0] - body[i, B_W]
        if not (sx > 0.0 and 0.0 <= x and x <= sx):  # inside, fold would change nothing
            x, vx, low, high, first_low = fold(x, body[i, B_VX], sx)
            body[i, B_VX] = vx
            n_folds = _fold_row(folds, n_folds, ext[i], 0, low, high, first_low)
        sy = sides[1] - body[i, B_H]
        if not (sy > 0.0 and 0.0 <= y and y <= sy):
            y, vy, low, high, first_low = fold(y, body[i, B_VY], sy)
            body[i, B_VY] = vy
            n_folds = _fold_row(folds, n_folds, ext[i], 1, low, high, first_low)
        body[i, B_X] = x
        body[i, B_Y] = y
        drift = max(drift, abs(x - anchor[i, 0]), abs(y - anchor[i, 1]))
    return n_folds, drift


@njit(cache=True)
def move_walls(body, static, ext, anchor, dt, sides, folds, chunks):
    """Move every object for dt seconds, then reflect it back into the world, split among
    `chunks` threads when more than one (`_move_chunks`). folds (2n, 4) int64 receives a row per
    object and axis that folded. Returns (how many rows, the farthest any object now is from its
    anchor on an axis, px)."""
    if chunks > 1:
        return _move_chunks(body, static, ext, anchor, dt, sides, folds, chunks)
    return move_range(body, static, ext, anchor, 0, body.shape[0], dt, sides, folds, 0)


@njit(cache=True, parallel=True)
def _move_chunks(body, static, ext, anchor, dt, sides, folds, chunks):
    """Run c of `chunks` writes its fold rows from row 2 x its first object (each object folds
    on two axes at most); then the runs' rows are moved together in run order."""
    n = body.shape[0]
    rows = np.zeros(chunks, np.int64)
    firsts = np.zeros(chunks, np.int64)
    drifts = np.zeros(chunks)
    for c in prange(chunks):
        first = c * n // chunks
        k, drifts[c] = move_range(
            body, static, ext, anchor, first, (c + 1) * n // chunks, dt, sides, folds, 2 * first
        )
        rows[c] = k - 2 * first
        firsts[c] = first
    return join_folds(folds, rows, firsts), drifts.max()


@njit(cache=True)
def join_folds(folds, rows, firsts):
    """Move the fold rows of runs of objects together in run order (run c wrote rows[c] rows from
    row 2 x firsts[c], its first object); returns how many rows."""
    n_folds = 0
    for c in range(rows.shape[0]):
        first = 2 * firsts[c]
        for r in range(rows[c]):
            for col in range(4):
                folds[n_folds + r, col] = folds[first + r, col]
        n_folds += rows[c]
    return n_folds


@njit(cache=True)
def _log_folds(rows, times, n_ev, tick, t, i, low, high, first_low, side_low, side_high):
    """Log one wall event per fold, alternating from the wall hit first."""
    at_low = first_low
    for _ in range(low + high):
        rows, times = log_event(
            rows, times, n_ev, tick, t, EV_WALL, i, -1, side_low if at_low else side_high
        )
        n_ev += 1
        at_low = not at_low
    return rows, times, n_ev


@njit(cache=True)
def log_walls(folds, n_folds, tick, t, rows, times, n_ev):
    """Log the wall events of the fold rows in id order (x before y): one per fold, alternating
    from the wall hit first."""
    order = heap_argsort(folds[:n_folds, 0].copy())
    for r in range(n_folds):
        row = order[r]
        e, axis = folds[row, 0] // 2, folds[row, 0] % 2
        side_low = SIDE_LEFT if axis == 0 else SIDE_TOP
        side_high = SIDE_RIGHT if axis == 0 else SIDE_BOTTOM
        rows, times, n_ev = _log_folds(
            rows,
            times,
            n_ev,
            tick,
            t,
            e,
            folds[row, 1],
            folds[row, 2],
            folds[row, 3] != 0,
            side_low,
            side_high,
        )
    return rows, times, n_ev
