"""The stepped model's candidate list (a Verlet list): the pairs that could touch until some
object has drifted its margin, made anew only then, and the order the objects are kept in.

Input: the state (`stepped.State`), the step just taken, the margin (px) and the broad phase's
method, cell and scratch (the `bp` tuple the model keeps, see `stepped_step.run`). Output: the
candidate keys (pairs of indices inside, `broadphase.KEY_SHIFT`), each object anchored where it
is, and the state put in the broad phase's order.

The broad phase (broadphase.py) lists the pairs whose boxes, each grown by the margin over the
step just taken, overlap. Each time the list is made the objects are put in the order the broad
phase found them in (the cells' row-by-row order, or the sweep's order on x), and the keys are
renamed to match: objects near in space are then near in memory, so the pair tests that follow
read two streams of rows instead of scattered ones, which keeps a large scene in the cache. The
grid method (mixed sizes) keeps the order it has. Nothing that reaches the outside depends on the
order inside: events, their order and the pairs' order go by object id.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.broadphase import (
    KEY_MASK,
    KEY_SHIFT,
    METHOD_CELLS,
    METHOD_GRID,
    cell_candidates_split,
    find,
    marker,
)
from collide2d.engine.jit import njit, overload
from collide2d.engine.models.stepped_motion import B_H, B_VX, B_VY, B_W, B_X, B_Y

# Where the model's `state` array keeps the keys listed (-1: no list yet), the method, whether
# pairs can happen at all, the wall and pair event counters, this step's overlapping pairs and
# how many chunks (threads) the move and narrow stages split into (1: none).
ST_KEYS, ST_METHOD, ST_POSSIBLE, ST_WALLS, ST_PAIRS, ST_NEAR, ST_CHUNKS = range(7)
# Where its `params` array keeps the margin, the grid's cell, the drift slack (px) and this
# step's drift (px).
P_MARGIN, P_CELL, P_SLACK, P_DRIFT = range(4)


@njit(cache=True)
def _gather_rows(a, order, tmp):
    """a[:] = a[order] along the first axis, through the scratch tmp (at least a's shape)."""
    n = order.shape[0]
    for s in range(n):
        for c in range(a.shape[1]):
            tmp[s, c] = a[order[s], c]
    for s in range(n):
        for c in range(a.shape[1]):
            a[s, c] = tmp[s, c]


@njit(cache=True)
def _gather(a, order, tmp):
    """a[:] = a[order], through the scratch tmp (a's shape)."""
    for s in range(order.shape[0]):
        tmp[s] = a[order[s]]
    for s in range(order.shape[0]):
        a[s] = tmp[s]


@njit(cache=True)
def _reorder(body, inv_mass, static, movable, ext, rank, order, scratch, keys, n_keys):
    """Put the objects inside in `order` (a permutation of the indices inside) and rename the
    n_keys keys to match (each as low index, high index); then order is the identity.
    scratch = (rows (n, 8) float64, inv (n,) int64, flags (n,) bool)."""
    rows, inv, flags = scratch
    n = order.shape[0]
    identity = True
    for s in range(n):
        if order[s] != s:
            identity = False
            break
    if identity:
        return
    _gather_rows(body, order, rows)
    for s in range(n):
        rows[s, 0] = inv_mass[order[s]]
    for s in range(n):
        inv_mass[s] = rows[s, 0]
    _gather(static, order, flags)
    _gather(movable, order, flags)
    _gather(ext, order, inv)
    for s in range(n):
        inv[order[s]] = s
        rank[ext[s]] = s
        order[s] = s
    for c in range(n_keys):
        a = inv[keys[c] >> KEY_SHIFT]
        b = inv[keys[c] & KEY_MASK]
        keys[c] = (min(a, b) << KEY_SHIFT) | max(a, b)


@njit(cache=True)
def relist(S, dt, bp):
    """Make the candidate list anew from the boxes grown by the margin, each over the step of dt
    s just taken (so that a pair that cut a corner within it is listed), put the objects inside
    in the broad phase's order (sweep and cells) and anchor every object where it is. Returns
    (the key buffer, possibly grown; how many keys)."""
    body, inv_mass, static, movable, ext, rank, anchor = S
    keys, near, order, lo, hi, folds, state, params, ws, when, finder, scratch = bp
    margin = params[P_MARGIN]
    n = body.shape[0]
    for i in range(n):
        # the box over the step just taken (swept back on a straight line), grown by margin
        x = body[i, B_X]
        y = body[i, B_Y]
        bx = x - body[i, B_VX] * dt
        by = y - body[i, B_VY] * dt
        lo[i, 0] = min(x, bx) - margin
        lo[i, 1] = min(y, by) - margin
        hi[i, 0] = max(x, bx) + body[i, B_W] + margin
        hi[i, 1] = max(y, by) + body[i, B_H] + margin
    cell = params[P_CELL]
    chunks = state[ST_CHUNKS]
    k = _candidates(finder, lo, hi, movable, cell, order, keys, ws, chunks)
    while k > keys.shape[0]:
        keys = np.empty(2 * k, np.int64)
        k = _candidates(finder, lo, hi, movable, cell, order, keys, ws, chunks)
    if state[ST_METHOD] != METHOD_GRID:
        _reorder(body, inv_mass, static, movable, ext, rank, order, scratch, keys, k)
    for i in range(n):
        anchor[i, 0] = body[i, B_X]
        anchor[i, 1] = body[i, B_Y]
    return keys, k


def _candidates(finder, lo, hi, movable, cell, order, keys, ws, chunks):
    """broadphase.find by the method the marker `finder` names, its pair tests split among
    `chunks` threads for the cells method when more than one (the same keys in the same order).
    A kernel compiles only the finder its marker names (this body runs only without the JIT)."""
    if chunks > 1 and finder.dtype == marker(METHOD_CELLS).dtype:
        return cell_candidates_split(lo, hi, movable, cell, order, keys, ws, chunks)
    return find(finder, lo, hi, movable, cell, order, keys, ws)


@overload(_candidates)
def _candidates_of(finder, lo, hi, movable, cell, order, keys, ws, chunks):
    if finder.dtype.bitwidth == 32:  # the cells method's marker (broadphase.marker)

        def cells(finder, lo, hi, movable, cell, order, keys, ws, chunks):
            if chunks > 1:
                return cell_candidates_split(lo, hi, movable, cell, order, keys, ws, chunks)
            return find(finder, lo, hi, movable, cell, order, keys, ws)

        return cells

    def one(finder, lo, hi, movable, cell, order, keys, ws, chunks):
        return find(finder, lo, hi, movable, cell, order, keys, ws)

    return one
