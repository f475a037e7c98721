"""The stepped model's candidate list (a Verlet list): the pairs that could touch until some
object has drifted its margin, made anew only then, kept in bands by distance, and the order the
objects are kept in.

Input: the state (`stepped.State`), the step just taken, the margin (px) and the broad phase's
method, cell and scratch (the `bp` tuple the model keeps, see `stepped_step.run`). Output: the
candidate keys (pairs of indices inside, `broadphase.KEY_SHIFT`) sorted by band, where each band
begins (in the model's `state`), each object anchored where it is, and the state put back in the
broad phase's order when it strayed from it.

The broad phase (broadphase.py) lists the pairs whose boxes, each grown by the margin over the
step just taken, overlap. The list is sorted into BANDS bands by how far apart each pair's boxes
were (nearest first, each band in the broad phase's order): a pair farther apart than twice the
largest drift since cannot touch yet, so a step tests only a prefix of the list
(`within_reach`). When the objects have strayed from the order the broad phase found them in
(the cells' row-by-row order, or the sweep's order on x) by more than REORDER_ROWS rows on
average, they are put back in it and the keys renamed to match: objects near in space are then
near in memory, so the pair tests that follow read streams of rows instead of scattered ones,
which keeps a large scene in the cache. The grid method (mixed sizes) keeps the order it has.
Nothing that reaches the outside depends on the order inside: events, their order and the pairs'
order go by object id.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.broadphase import (
    KEY_MASK,
    KEY_SHIFT,
    METHOD_GRID,
    find_split,
    index,
)
from collide2d.engine.jit import njit, prange
from collide2d.engine.models.stepped_motion import B_H, B_VX, B_VY, B_W, B_X, B_Y

# Where the model's `state` array keeps the keys listed (-1: no list yet), the method, whether
# pairs can happen at all, the wall and pair event counters, this step's overlapping pairs, how
# many chunks (threads) the move and narrow stages split into (1: none), and from ST_BANDS on
# where each band of the list begins (BANDS + 1 entries; see `within_reach`).
ST_KEYS, ST_METHOD, ST_POSSIBLE, ST_WALLS, ST_PAIRS, ST_NEAR, ST_CHUNKS, ST_BANDS = range(8)
# The listed pairs come in this many bands by how far apart their boxes were when the list was
# made, nearest first: a band whose pairs were farther apart than any two objects have drifted
# since cannot touch yet, and the narrow phase skips it.
BANDS = 16
STATE_SIZE = ST_BANDS + BANDS + 1
# A pair's distance is taken this much (px) short when its band is chosen: room for rounding.
BAND_SLACK_PX = 1e-6
# While the list is sorted by band, a key holds its band above BAND_SHIFT.
BAND_SHIFT = 59
PAIR_MASK = (1 << BAND_SHIFT) - 1
# The objects inside are put back in the broad phase's order once they have strayed from it by
# more than this many rows of the grid on average (a row holds about sqrt(n) objects in a
# squarish world): a few rows apart still share the cache, and a reorder costs a pass over the
# state.
REORDER_ROWS = 0.5
# Where its `params` array keeps the margin, the grid's cell, the drift slack (px) and this
# step's drift (px).
P_MARGIN, P_CELL, P_SLACK, P_DRIFT = range(4)


@njit(cache=True)
def _grow_range(body, lo, hi, margin, dt, first, last):
    """The boxes of objects first ... last-1 over the step of dt s just taken (swept back on a
    straight line), grown by margin px, into lo, hi."""
    for i in range(index(first), index(last)):  # unsigned indices: broadphase.index
        x = body[i, B_X]
        y = body[i, B_Y]
        bx = x - body[i, B_VX] * dt
        by = y - body[i, B_VY] * dt
        lo[i, 0] = min(x, bx) - margin
        lo[i, 1] = min(y, by) - margin
        hi[i, 0] = max(x, bx) + body[i, B_W] + margin
        hi[i, 1] = max(y, by) + body[i, B_H] + margin


@njit(cache=True)
def _gather_range(body, inv_mass, static, movable, ext, order, scratch, first, last):
    """Slots first ... last-1 of the state put in `order`, into the scratch (rows, ids, flags,
    masses: the body rows, the ids, static | movable << 1, the inverse masses)."""
    rows, inv, flags, masses = scratch
    for s in range(first, last):
        o = order[s]
        for c in range(body.shape[1]):
            rows[s, c] = body[o, c]
        masses[s] = inv_mass[o]
        inv[s] = ext[o]
        flags[s] = static[o] | (movable[o] << 1)


@njit(cache=True)
def _place_range(body, inv_mass, static, movable, ext, rank, anchor, order, scratch, first, last):
    """Slots first ... last-1 copied back from the scratch; each anchored where it is."""
    rows, inv, flags, masses = scratch
    for s in range(first, last):
        for c in range(body.shape[1]):
            body[s, c] = rows[s, c]
        inv_mass[s] = masses[s]
        ext[s] = inv[s]
        static[s] = flags[s] & 1
        movable[s] = flags[s] >> 1
        rank[inv[s]] = s
        anchor[s, 0] = rows[s, B_X]
        anchor[s, 1] = rows[s, B_Y]


@njit(cache=True)
def _rename_range(keys, order, inv, first, last):
    """Keys first ... last-1 renamed from the old indices inside to the new (inv: old to new),
    each as low index, high index."""
    for c in range(first, last):
        a = inv[keys[c] >> KEY_SHIFT]
        b = inv[keys[c] & KEY_MASK]
        keys[c] = (min(a, b) << KEY_SHIFT) | max(a, b)


@njit(cache=True)
def _reorder(S, order, scratch, keys, n_keys, chunks):
    """Put the objects inside in `order` (a permutation of the indices inside), anchor each where
    it is and rename the n_keys keys to match; then order is the identity. The work is cut into
    `chunks` contiguous runs, on threads when more than one (`_reorder_split`)."""
    if chunks > 1:
        _reorder_split(S, order, scratch, keys, n_keys, chunks)
        return
    body, inv_mass, static, movable, ext, rank, anchor = S
    n = order.shape[0]
    _gather_range(body, inv_mass, static, movable, ext, order, scratch, 0, n)
    _place_range(body, inv_mass, static, movable, ext, rank, anchor, order, scratch, 0, n)
    inv = scratch[1]
    for s in range(n):
        inv[order[s]] = s
        order[s] = s
    _rename_range(keys, order, inv, 0, n_keys)


@njit(cache=True, parallel=True)
def _reorder_split(S, order, scratch, keys, n_keys, chunks):
    """`_reorder` on `chunks` threads: the same state and keys."""
    body, inv_mass, static, movable, ext, rank, anchor = S
    n = order.shape[0]
    for c in prange(chunks):
        _gather_range(
            body, inv_mass, static, movable, ext, order, scratch, c * n // chunks,
            (c + 1) * n // chunks,
        )
    for c in prange(chunks):
        _place_range(
            body, inv_mass, static, movable, ext, rank, anchor, order, scratch, c * n // chunks,
            (c + 1) * n // chunks,
        )
    inv = scratch[1]
    for c in prange(chunks):
        for s in range(c * n // chunks, (c + 1) * n // chunks):
            inv[order[s]] = s
    for c in prange(chunks):
        for s in range(c * n // chunks, (c + 1) * n // chunks):
            order[s] = s
    for c in prange(chunks):
        _rename_range(keys, order, inv, c * n_keys // chunks, (c + 1) * n_keys // chunks)


@njit(cache=True, parallel=True)
def _grow_split(body, lo, hi, margin, dt, chunks):
    """`_grow_range` over every object, on `chunks` threads."""
    n = body.shape[0]
    for c in prange(chunks):
        _grow_range(body, lo, hi, margin, dt, c * n // chunks, (c + 1) * n // chunks)


@njit(cache=True, inline="always")
def _band(lo, hi, key, margin):
    """The band of a listed pair (keys of indices into lo, hi: the boxes grown by margin): how
    far apart the boxes were on the axis they were farthest apart on, in steps of 2 x margin /
    BANDS (band 0 for boxes that overlap), after BAND_SLACK_PX taken off."""
    a = index(key >> KEY_SHIFT)
    b = index(key & KEY_MASK)
    gap = max(lo[b, 0] - hi[a, 0], lo[a, 0] - hi[b, 0], lo[b, 1] - hi[a, 1], lo[a, 1] - hi[b, 1])
    apart = (gap + 2.0 * margin - BAND_SLACK_PX) * (BANDS / (2.0 * margin))
    return min(max(int(apart), 0), BANDS - 1) if apart > 0.0 else 0


@njit(cache=True)
def _band_range(lo, hi, keys, first, last, margin, counts):
    """Keys first ... last-1: each one's band kept in its top bits (indices stay below 2**28)
    and counted in counts (BANDS,)."""
    for c in range(index(first), index(last)):
        j = _band(lo, hi, keys[c], margin)
        counts[j] += 1
        keys[c] |= j << BAND_SHIFT


@njit(cache=True)
def _place_by_band(keys, spare, first, last, at):
    """Keys first ... last-1 into spare, band j's from at[j] on (at advances), the band bits
    taken off."""
    for c in range(index(first), index(last)):
        j = keys[c] >> BAND_SHIFT
        spare[index(at[j])] = keys[c] & PAIR_MASK
        at[j] += 1


@njit(cache=True)
def _band_starts(counts, state):
    """From each run's count per band (runs, BANDS): where each band begins
    (state[ST_BANDS + j], and state[ST_BANDS + BANDS] the end), and counts made each run's first
    slot in each band (bands in order, each band's runs in run order)."""
    start = 0
    for j in range(BANDS):
        state[ST_BANDS + j] = start
        for c in range(counts.shape[0]):
            here = counts[c, j]
            counts[c, j] = start
            start += here
    state[ST_BANDS + BANDS] = start


@njit(cache=True)
def _by_band(lo, hi, keys, spare, k, margin, state, chunks):
    """Put keys[:k] into spare by band, nearest band first, each band in the order it had (a
    counting sort); state[ST_BANDS + j] is where band j begins. With chunks > 1 the keys are cut
    into that many contiguous runs, on threads (`_by_band_split`): the same order."""
    if chunks > 1:
        _by_band_split(lo, hi, keys, spare, k, margin, state, chunks)
        return
    counts = np.zeros((1, BANDS), np.int64)
    _band_range(lo, hi, keys, 0, k, margin, counts[0])
    _band_starts(counts, state)
    _place_by_band(keys, spare, 0, k, counts[0])


@njit(cache=True, parallel=True)
def _by_band_split(lo, hi, keys, spare, k, margin, state, chunks):
    """`_by_band` on `chunks` threads: each run counts its keys' bands, then places them from
    its own first slot in each band."""
    counts = np.zeros((chunks, BANDS), np.int64)
    for c in prange(chunks):
        _band_range(lo, hi, keys, c * k // chunks, (c + 1) * k // chunks, margin, counts[c])
    _band_starts(counts, state)
    for c in prange(chunks):
        _place_by_band(keys, spare, c * k // chunks, (c + 1) * k // chunks, counts[c])


@njit(cache=True)
def within_reach(state, params):
    """How many of the listed pairs (a prefix, by band) the narrow phase tests this step: the
    bands whose pairs were at most twice the drift (plus slack) apart when the list was made.
    Any other pair was farther apart than two objects can have closed by drifting since, so it
    cannot touch yet (the argument that lets the list stand while the drift is below the
    margin, pair by pair)."""
    reach = 2.0 * (params[P_DRIFT] + params[P_SLACK])
    step = 2.0 * params[P_MARGIN] / BANDS
    j = BANDS
    for b in range(BANDS):
        if b * step > reach:
            j = b
            break
    return state[ST_BANDS + j]


@njit(cache=True)
def _strayed(order):
    """Whether the objects inside have strayed from the broad phase's `order` by more than
    REORDER_ROWS rows of a square grid on average (a row holds about sqrt(n) objects)."""
    n = order.shape[0]
    stray = 0
    for s in range(n):
        stray += abs(order[s] - s)
    return stray > REORDER_ROWS * math.sqrt(n) * n


@njit(cache=True)
def relist(S, dt, bp):
    """Make the candidate list anew from the boxes grown by the margin, each over the step of dt
    s just taken (so that a pair that cut a corner within it is listed), sort it by band, put
    the objects inside in the broad phase's order (sweep and cells) and anchor every object where
    it is. Returns (the key buffers, possibly grown: the list and a spare; how many keys)."""
    body, inv_mass, static, movable, ext, rank, anchor = S
    keys, near, order, lo, hi, folds, state, params, ws, when, finder, scratch, spare = bp
    margin = params[P_MARGIN]
    chunks = state[ST_CHUNKS]
    n = body.shape[0]
    if chunks > 1:
        _grow_split(body, lo, hi, margin, dt, chunks)
    else:
        _grow_range(body, lo, hi, margin, dt, 0, n)
    cell = params[P_CELL]
    found = np.zeros(chunks, np.int64)
    k = find_split(finder, lo, hi, movable, cell, order, keys, ws, found)
    while k > keys.shape[0]:
        keys = np.empty(2 * k, np.int64)
        k = find_split(finder, lo, hi, movable, cell, order, keys, ws, found)
    if spare.shape[0] < keys.shape[0]:
        spare = np.empty(keys.shape[0], np.int64)
    _by_band(lo, hi, keys, spare, k, margin, state, chunks)
    keys, spare = spare, keys
    if state[ST_METHOD] != METHOD_GRID and _strayed(order):
        _reorder(S, order, scratch, keys, k, chunks)
    else:
        for i in range(n):
            anchor[i, 0] = body[i, B_X]
            anchor[i, 1] = body[i, B_Y]
    params[P_DRIFT] = 0.0  # every object is at its anchor
    return keys, spare, k


