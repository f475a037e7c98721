"""The exact model's event queue: a 4-ary heap of predicted events in preallocated arrays.

The model keeps its predicted contacts here (each object's horizon, its next wall contact or cell
crossing, is filed in horizonqueue.py, keyed the same way). An entry is a time (HT,
float64), a key and the two invalidation counters its objects had when it was predicted (HI,
int64), and a contact normal (HN, float64). Keys pack (rank, a, b, code) into one int64, so ties in
time go as cell crossings, then walls by (id, side), then pairs by (a, b). An entry is stale once
either object's counter (column CNT of N) has changed; stale entries are skipped when popped and
dropped by `compact` when the heap is full. The heap's size is st[S_HEAP_N]. Events closer in time
than `instant(t)` are one instant (rounding, not physics, parts them) and `first_of_instant` takes
them in key order. The caller makes sure there is room before a push (`has_room`); `grown` doubles
an array between kernel calls.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit
from collide2d.engine.models.exact.state import CNT, S_HEAP_N, Entry, hot

# Children per heap node: a 4-ary heap is half as deep as a binary one, and its four children
# share a cache line.
ARITY = 4


# the contact normal (code and normal as contact.py gives them).
HKEY, HCA, HCB = range(3)

# Heap keys: rank, a, b (or a wall side / crossing direction) and contact code in one int64, so that
# ties in time resolve as crossings, then walls by (id, side), then pairs by (a, b).
RANK_CROSS = 0
RANK_WALL = 1
RANK_PAIR = 2
ID_BITS = 25  # ids below 2**25 (33 million objects)
ID_MASK = (1 << ID_BITS) - 1
B_SHIFT = 4
A_SHIFT = B_SHIFT + ID_BITS
RANK_SHIFT = A_SHIFT + ID_BITS
MAX_OBJECTS = 1 << ID_BITS


# Events closer in time than max(INSTANT_S, INSTANT_REL·t) are one instant: what parts them is
# rounding (a few units in the last place of t, or of a pixel coordinate over a speed), not
# physics, so they go in key order. At most INSTANT_STACK entries of one instant are compared.
INSTANT_S = 1e-12
INSTANT_REL = 2.0**-46
INSTANT_STACK = 1024

# --- heap keys and entries ---------------------------------------------------------------------


@hot
def make_key(rank, a, b, code):
    return (rank << RANK_SHIFT) | (a << A_SHIFT) | (b << B_SHIFT) | code


@hot
def split_key(key):
    """(rank, a, b, code) of a heap key."""
    return (
        key >> RANK_SHIFT,
        (key >> A_SHIFT) & ID_MASK,
        (key >> B_SHIFT) & ID_MASK,
        key & 15,
    )


@hot
def is_valid(HI, i, N):
    """Entry i is valid while its objects' counters are those it was predicted with."""
    rank, a, b, _ = split_key(HI[i, HKEY])
    if N[a, CNT] != HI[i, HCA]:
        return False
    return rank != RANK_PAIR or N[b, CNT] == HI[i, HCB]


# --- the heap; the caller makes sure there is room before an event -----------------------------


@hot
def _earlier(HT, HI, i, t, key):
    """Entry i comes strictly before (t, key)."""
    return HT[i] < t or (HT[i] == t and HI[i, HKEY] < key)


@hot
def entry(HT, HI, HN, i):
    """The entry in slot i."""
    return Entry(HT[i], HI[i, HKEY], HI[i, HCA], HI[i, HCB], HN[i, 0], HN[i, 1])


@hot
def _put(HT, HI, HN, i, e):
    HT[i] = e.t
    HI[i, HKEY], HI[i, HCA], HI[i, HCB] = e.key, e.ca, e.cb
    HN[i, 0], HN[i, 1] = e.nx, e.ny


@hot
def _move(HT, HI, HN, i, j):
    """Entry j moves to slot i."""
    _put(HT, HI, HN, i, entry(HT, HI, HN, j))


@hot
def _sift_up(HT, HI, HN, i, e):
    """Place entry e at hole i, moving it up past later parents."""
    while i > 0:
        p = (i - 1) // ARITY
        if _earlier(HT, HI, p, e.t, e.key) or (HT[p] == e.t and HI[p, HKEY] == e.key):
            break
        _move(HT, HI, HN, i, p)
        i = p
    _put(HT, HI, HN, i, e)


@hot
def _first_child(HT, HI, first, last):
    """(slot, time) of the earliest of entries first..last-1 (the first one on a tie)."""
    c = first
    tc = HT[first]
    for m in range(first + 1, last):
        tm = HT[m]
        if tm < tc or (tm == tc and HI[m, HKEY] < HI[c, HKEY]):
            c = m
            tc = tm
    return c, tc


@hot
def _sift_down(HT, HI, HN, n, i, e):
    """Place entry e at hole i of a heap of n, moving it down past earlier children."""
    t, key = e.t, e.key
    while True:
        first = ARITY * i + 1
        if first + ARITY <= n:  # a full family: a loop of constant length, unrolled
            c, tc = _first_child(HT, HI, first, first + ARITY)
        elif first < n:
            c, tc = _first_child(HT, HI, first, n)
        else:
            break
        if not (tc < t or (tc == t and HI[c, HKEY] < key)):
            break
        _move(HT, HI, HN, i, c)
        i = c
    _put(HT, HI, HN, i, e)


@hot
def push(HT, HI, HN, st, e):
    """Add entry e (there is room)."""
    n = st[S_HEAP_N]
    st[S_HEAP_N] = n + 1
    _sift_up(HT, HI, HN, n, e)


@hot
def pop(HT, HI, HN, st):
    """Remove and return the earliest entry."""
    top = entry(HT, HI, HN, 0)
    n = st[S_HEAP_N] - 1
    st[S_HEAP_N] = n
    if n > 0:
        _sift_down(HT, HI, HN, n, 0, entry(HT, HI, HN, n))
    return top


@hot
def remove(HT, HI, HN, st, k):
    """Remove and return entry k; the last entry takes its place."""
    taken = entry(HT, HI, HN, k)
    n = st[S_HEAP_N] - 1
    st[S_HEAP_N] = n
    if k < n:
        last = entry(HT, HI, HN, n)
        if k > 0 and not _earlier(HT, HI, (k - 1) // ARITY, last.t, last.key):
            _sift_up(HT, HI, HN, k, last)
        else:
            _sift_down(HT, HI, HN, n, k, last)
    return taken


@hot
def instant(t):
    """Events closer to t than this (s) happen at one instant: rounding, not physics, parts them."""
    return max(INSTANT_S, abs(t) * INSTANT_REL)


@hot
def first_of_instant(HT, HI, st, N, stack):
    """The entry to take next: of the valid entries at the top's instant, the one with the
    smallest key, so that simultaneous events go walls first, then pairs in (a, b) order,
    whatever rounding did to their times. Those entries are the heap's top subtree of times
    within the instant; `stack` is scratch for walking it."""
    n = st[S_HEAP_N]
    bound = HT[0] + instant(HT[0])
    best = 0
    sp = 0
    for c in range(1, min(1 + ARITY, n)):
        if HT[c] <= bound:
            stack[sp] = c
            sp += 1
    while sp > 0:
        sp -= 1
        k = stack[sp]
        if HI[k, HKEY] < HI[best, HKEY] and is_valid(HI, k, N):
            best = k
        for c in range(ARITY * k + 1, min(ARITY * k + 1 + ARITY, n)):
            if HT[c] <= bound and sp < stack.shape[0]:
                stack[sp] = c
                sp += 1
    return best


@njit(cache=True)
def compact(HT, HI, HN, st, N):
    """Drop stale entries and rebuild the heap in place; returns the free room."""
    keep = 0
    for i in range(st[S_HEAP_N]):
        if is_valid(HI, i, N):
            _move(HT, HI, HN, keep, i)
            keep += 1
    for i in range((keep - 2) // ARITY, -1, -1):
        _sift_down(HT, HI, HN, keep, i, entry(HT, HI, HN, i))
    st[S_HEAP_N] = keep
    return HT.shape[0] - keep


@hot
def has_room(room, HT, HI, HN, st, N):
    """Whether `room` more entries fit, dropping stale entries first if they would not."""
    return HT.shape[0] - st[S_HEAP_N] >= room or compact(HT, HI, HN, st, N) >= room


def grown(a: np.ndarray) -> np.ndarray:
    """a with twice the rows, the old rows kept."""
    out = np.empty((2 * a.shape[0],) + a.shape[1:], a.dtype)
    out[: a.shape[0]] = a
    return out
