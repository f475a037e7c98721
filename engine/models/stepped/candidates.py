"""The stepped model's candidate list (a Verlet list): the pairs that could touch until some
object has drifted its margin, made anew only then, kept by block and band, and the order the
objects are kept in.

Input: the state (`model.State`), the step just taken, the margin (px) and the broad phase's
method, cell and scratch (the `bp` tuple the model keeps, see `step.run`). Output: the
candidate keys (pairs of indices inside, `broadphase.KEY_SHIFT`) sorted by bucket, where each
bucket begins (in the model's `state`), each object anchored where it is, and the state put back
in the broad phase's order when it strayed from it.

The broad phase (broadphase.py) lists the pairs whose boxes, each grown by the margin over the
step just taken, overlap. The objects inside come in blocks of consecutive rows (`blocks_for`:
about BLOCK_ROWS rows, a share of one core's cache), and the list is sorted into buckets: by the
block of the pair's higher index; in it, the pairs whose objects are both in that block before
those reaching into an earlier block (`cross`); in each, BANDS bands by how far apart the pair's
boxes were (nearest first, each band in the broad phase's order). A pair farther apart than twice
the largest drift since cannot touch yet, so a step tests only a prefix of each bucket
(`reach_bands`); and the narrow phase can test a block's own pairs right after its move, while
its rows are still in the cache (narrow.move_narrow). When the objects have strayed from
the order the broad phase found them in
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
from collide2d.engine.models.stepped.move import B_H, B_VX, B_VY, B_W, B_X, B_Y
from collide2d.engine.models.stepped.records import Scratch
from collide2d.engine.threads import PARALLEL_MIN_OBJECTS

# Where the model's `state` array keeps the keys listed (-1: no list yet), the method, whether
# pairs can happen at all, the wall and pair event counters, this step's overlapping pairs, how
# many chunks (threads) the move and narrow stages split into (1: none), how many steps ran the
# move and the narrow phase together (narrow.move_narrow), and from ST_BANDS on where
# each bucket of the list begins (`bucket_count` + 1 entries; see the module docstring).
ST_KEYS, ST_METHOD, ST_POSSIBLE, ST_WALLS, ST_PAIRS, ST_NEAR, ST_CHUNKS, ST_FUSED, ST_BANDS = (
    range(9)
)
# The listed pairs come in this many bands by how far apart their boxes were when the list was
# made, nearest first: a band whose pairs were farther apart than any two objects have drifted
# since cannot touch yet, and the narrow phase skips it.
BANDS = 16
# The objects inside come in blocks of about this many rows (6 floats each: 384 KiB, under half
# of the second-level cache of a core here), so that a block moved is still in the cache when its
# pairs are tested. Scenes large enough to split among threads have a multiple of SPLIT_BLOCKS
# blocks, so that 2 or 4 threads get even shares.
BLOCK_ROWS = 8192
SPLIT_BLOCKS = 4
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
# Where its `params` array keeps the margin, the grid's cell, the drift slack (px), this step's
# drift (px: the farthest any object is from its anchor on an axis), its reach (px: the same over
# each object's whole path in the step, where it began too: `reach`), how much the drift grew in
# the last step (px) and the farthest from its anchor an object pushed apart in the last response
# ended (px, pairs.py).
P_MARGIN, P_CELL, P_SLACK, P_DRIFT, P_REACH, P_GROWTH, P_PUSHED = range(7)
PARAMS_SIZE = 7


def blocks_for(n: int) -> int:
    """How many blocks n objects inside come in (see BLOCK_ROWS)."""
    blocks = max(1, -(-n // BLOCK_ROWS))
    if n >= PARALLEL_MIN_OBJECTS:
        blocks = -(-blocks // SPLIT_BLOCKS) * SPLIT_BLOCKS
    return blocks


def state_size(blocks: int) -> int:
    """The length of the model's `state` for a list in this many blocks."""
    return ST_BANDS + 2 * blocks * BANDS + 1


@njit(cache=True)
def block_count(state):
    """How many blocks the objects inside come in (from the length of `state`, `state_size`)."""
    return (state.shape[0] - ST_BANDS - 1) // (2 * BANDS)


@njit(cache=True)
def block_rows(n, blocks):
    """The rows of every block but the last (which holds the rest)."""
    return (n + blocks - 1) // blocks


@njit(cache=True, inline="always")
def _bucket(key, rows):
    """The bucket of a key whose band is in its top bits: (the block of its higher index, then 1
    when its lower index is in an earlier block), then the band."""
    pair = key & PAIR_MASK
    block_a = (pair >> KEY_SHIFT) // rows
    block_b = (pair & KEY_MASK) // rows
    return (2 * block_b + (block_a != block_b)) * BANDS + (key >> BAND_SHIFT)


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
    """Slots first ... last-1 of the state put in `order`, into the scratch (a Scratch as a plain
    tuple: the body rows, the ids, static | movable << 1, the inverse masses)."""
    R = Scratch(*scratch)
    rows, flags = R.rows, R.flags
    for s in range(first, last):
        o = order[s]
        for c in range(body.shape[1]):
            rows[s, c] = body[o, c]
        R.masses[s] = inv_mass[o]
        R.ids[s] = ext[o]
        flags[s] = static[o] | (movable[o] << 1)


@njit(cache=True)
def _place_range(body, inv_mass, static, movable, ext, rank, anchor, scratch, first, last):
    """Slots first ... last-1 copied back from the scratch; each anchored where it is.

    (The reorder's threads call the range kernels with the state's arrays themselves, not a
    State: numba fuses two parallel loops whose calls take no array argument, not seeing those
    a record holds, and the loops of `_reorder_split` must each end before the next begins.)"""
    R = Scratch(*scratch)
    rows, ids, flags = R.rows, R.ids, R.flags
    for s in range(first, last):
        for c in range(body.shape[1]):
            body[s, c] = rows[s, c]
        inv_mass[s] = R.masses[s]
        ext[s] = ids[s]
        static[s] = flags[s] & 1
        movable[s] = flags[s] >> 1
        rank[ids[s]] = s
        anchor[s, 0] = rows[s, B_X]
        anchor[s, 1] = rows[s, B_Y]


@njit(cache=True)
def _rename_range(keys, order, inv, first, last):
    """Keys first ... last-1 renamed from the old indices inside to the new (inv: old to new),
    each as low index, high index, the band in the top bits kept."""
    for c in range(first, last):
        band = keys[c] >> BAND_SHIFT
        a = inv[(keys[c] & PAIR_MASK) >> KEY_SHIFT]
        b = inv[keys[c] & KEY_MASK]
        keys[c] = (band << BAND_SHIFT) | (min(a, b) << KEY_SHIFT) | max(a, b)


@njit(cache=True)
def _reorder(S, order, scratch, keys, n_keys, chunks):
    """Put the objects inside in `order` (a permutation of the indices inside), anchor each where
    it is and rename the n_keys keys to match; then order is the identity. The work is cut into
    `chunks` contiguous runs, on threads when more than one (`_reorder_split`)."""
    if chunks > 1:
        _reorder_split(S, order, scratch, keys, n_keys, chunks)
        return
    body, inv_mass, static, movable = S.body, S.inv_mass, S.static, S.movable
    ext, rank, anchor = S.ext, S.rank, S.anchor
    n = order.shape[0]
    _gather_range(body, inv_mass, static, movable, ext, order, scratch, 0, n)
    _place_range(body, inv_mass, static, movable, ext, rank, anchor, scratch, 0, n)
    inv = Scratch(*scratch).ids
    for s in range(n):
        inv[order[s]] = s
        order[s] = s
    _rename_range(keys, order, inv, 0, n_keys)


@njit(cache=True, parallel=True)
def _reorder_split(S, order, scratch, keys, n_keys, chunks):
    """`_reorder` on `chunks` threads: the same state and keys."""
    body, inv_mass, static, movable = S.body, S.inv_mass, S.static, S.movable
    ext, rank, anchor = S.ext, S.rank, S.anchor
    n = order.shape[0]
    for c in prange(chunks):
        _gather_range(
            body, inv_mass, static, movable, ext, order, scratch, c * n // chunks,
            (c + 1) * n // chunks,
        )
    for c in prange(chunks):
        _place_range(
            body, inv_mass, static, movable, ext, rank, anchor, scratch, c * n // chunks,
            (c + 1) * n // chunks,
        )
    inv = Scratch(*scratch).ids
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
def _band_range(lo, hi, keys, first, last, margin):
    """Keys first ... last-1: each one's band kept in its top bits (indices stay below 2**27)."""
    for c in range(index(first), index(last)):
        keys[c] |= _band(lo, hi, keys[c], margin) << BAND_SHIFT


@njit(cache=True, parallel=True)
def _band_split(lo, hi, keys, k, margin, chunks):
    """`_band_range` over keys[:k], on `chunks` threads."""
    for c in prange(chunks):
        _band_range(lo, hi, keys, c * k // chunks, (c + 1) * k // chunks, margin)


@njit(cache=True)
def _count_range(keys, first, last, rows, counts):
    """Keys first ... last-1 counted by bucket in counts."""
    for c in range(index(first), index(last)):
        counts[_bucket(keys[c], rows)] += 1


@njit(cache=True)
def _place_by_bucket(keys, spare, first, last, rows, at):
    """Keys first ... last-1 into spare, bucket j's from at[j] on (at advances), the band bits
    taken off."""
    for c in range(index(first), index(last)):
        j = _bucket(keys[c], rows)
        spare[index(at[j])] = keys[c] & PAIR_MASK
        at[j] += 1


@njit(cache=True)
def _bucket_starts(counts, state):
    """From each run's count per bucket (runs, buckets): where each bucket begins
    (state[ST_BANDS + j], and state[ST_BANDS + buckets] the end), and counts made each run's
    first slot in each bucket (buckets in order, each bucket's runs in run order)."""
    start = 0
    for j in range(counts.shape[1]):
        state[ST_BANDS + j] = start
        for c in range(counts.shape[0]):
            here = counts[c, j]
            counts[c, j] = start
            start += here
    state[ST_BANDS + counts.shape[1]] = start


@njit(cache=True)
def _by_bucket(keys, spare, k, n, state, chunks):
    """Put keys[:k] (each with its band in its top bits, over n objects inside) into spare by
    bucket, each bucket in the order it had (a counting sort); state[ST_BANDS + j] is where
    bucket j begins. With chunks > 1 the keys are cut into that many contiguous runs, on threads
    (`_by_bucket_split`): the same order."""
    rows = block_rows(n, block_count(state))
    buckets = 2 * block_count(state) * BANDS
    if chunks > 1:
        _by_bucket_split(keys, spare, k, rows, buckets, state, chunks)
        return
    counts = np.zeros((1, buckets), np.int64)
    _count_range(keys, 0, k, rows, counts[0])
    _bucket_starts(counts, state)
    _place_by_bucket(keys, spare, 0, k, rows, counts[0])


@njit(cache=True, parallel=True)
def _by_bucket_split(keys, spare, k, rows, buckets, state, chunks):
    """`_by_bucket` on `chunks` threads: each run counts its keys' buckets, then places them from
    its own first slot in each bucket."""
    counts = np.zeros((chunks, buckets), np.int64)
    for c in prange(chunks):
        _count_range(keys, c * k // chunks, (c + 1) * k // chunks, rows, counts[c])
    _bucket_starts(counts, state)
    for c in prange(chunks):
        _place_by_bucket(keys, spare, c * k // chunks, (c + 1) * k // chunks, rows, counts[c])


@njit(cache=True)
def reach_bands(reach, params):
    """How many bands (a prefix of each bucket) the narrow phase tests for pairs of objects that
    are, over the whole step, at most `reach` px from their anchors: the bands whose pairs were at
    most twice that (plus slack) apart when the list was made. Any other pair was farther apart
    than two such objects can have closed by drifting since, so it cannot touch yet (the argument
    that lets the list stand while the drift is below the margin, pair by pair)."""
    within = 2.0 * (reach + params[P_SLACK])
    step = 2.0 * params[P_MARGIN] / BANDS
    for b in range(BANDS):
        if b * step > within:
            return b
    return BANDS


@njit(cache=True)
def start_reach(params):
    """Before a step's move (params as the last step left them): the farthest any object is from
    its anchor where it begins the step, px, at most. The last move left none farther than its
    drift, and the response after it moved only the objects it pushed apart."""
    return max(params[P_DRIFT], params[P_PUSHED])


@njit(cache=True)
def within_reach(params):
    """`reach_bands` for this step's reach over every object (params[P_REACH])."""
    return reach_bands(params[P_REACH], params)


@njit(cache=True)
def keys_within(state, bands):
    """How many listed pairs the first `bands` bands of every bucket hold."""
    k = 0
    for j in range(0, state.shape[0] - ST_BANDS - 1, BANDS):
        k += state[ST_BANDS + j + bands] - state[ST_BANDS + j]
    return k


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
def relist(S, dt, L, keys, spare):
    """Make the candidate list anew from the boxes grown by the margin, each over the step of dt
    s just taken (so that a pair that cut a corner within it is listed), note each pair's band,
    put the objects inside in the broad phase's order (sweep and cells; the pairs renamed to
    match), anchor every object where it is and sort the list by bucket. S: a State, L: a Lists
    (records.py) but for its key buffers, keys and spare. Returns (the key buffers, possibly
    grown: the list and a spare; how many keys)."""
    body, anchor = S.body, S.anchor
    order, lo, hi, state, params = L.order, L.lo, L.hi, L.state, L.params
    margin = params[P_MARGIN]
    chunks = state[ST_CHUNKS]
    n = body.shape[0]
    if chunks > 1:
        _grow_split(body, lo, hi, margin, dt, chunks)
    else:
        _grow_range(body, lo, hi, margin, dt, 0, n)
    cell = params[P_CELL]
    found = np.zeros(chunks, np.int64)
    k = find_split(L.finder, lo, hi, S.movable, cell, order, keys, L.ws, found)
    while k > keys.shape[0]:
        keys = np.empty(2 * k, np.int64)
        k = find_split(L.finder, lo, hi, S.movable, cell, order, keys, L.ws, found)
    if spare.shape[0] < keys.shape[0]:
        spare = np.empty(keys.shape[0], np.int64)
    if chunks > 1:
        _band_split(lo, hi, keys, k, margin, chunks)
    else:
        _band_range(lo, hi, keys, 0, k, margin)
    if state[ST_METHOD] != METHOD_GRID and _strayed(order):
        _reorder(S, order, L.scratch, keys, k, chunks)
    else:
        for i in range(n):
            anchor[i, 0] = body[i, B_X]
            anchor[i, 1] = body[i, B_Y]
    _by_bucket(keys, spare, k, n, state, chunks)
    # every object is at its anchor, and the boxes listed were grown over the step just taken
    params[P_DRIFT] = 0.0
    params[P_REACH] = 0.0
    return spare, keys, k


