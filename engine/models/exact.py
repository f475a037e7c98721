"""The `exact` model (SPEC 3.3): event-driven elastic collisions, the reference for every result.

Input: the world, the `Bodies` (copied) and the options `geometry` ("exact", the default, also
for None: circles and polygons by their real shapes; "box": every object as its box),
`max_events_per_tick`, `cell_size` (px; the grid's cell, chosen from the scene when not given)
and `repredict` ("touched", the default; "all" predicts every moving object again after each
event, the work the local re-prediction saves, for tests and `collide2d bench`). Output, per
`advance`: the wall and pair events in the order they happened, `t` = the exact contact time;
positions and velocities at the end of the last tick.

Objects fly on straight lines between events. Each keeps its own clock (TLOC: its position is
valid at that time) and an invalidation counter. A 4-ary heap, in preallocated arrays that grow
when full, holds predicted events keyed by (time, rank, a, b): cell crossings first (bookkeeping,
never logged), then walls by (id, side), then pairs in (a, b) order. An entry records the counters
of its objects when predicted and is skipped as stale if either has changed since.

Prediction stays local and short. Moving objects are filed in a uniform grid (broadphase.py) by
their box centre. Each moving object has one entry for its *horizon*: the first of its next wall
contact and its next cell crossing. Its contacts are predicted against the objects in the 3×3
cells around it, and pushed only when they come no later than its horizon: at the horizon it is
predicted again anyway (a wall changes its velocity, a crossing its neighbours), and a contact
between i and j is always pushed by whichever of the two last changed velocity or cell before it,
since that one's horizon lies beyond it. After an event only the objects it touched are moved,
counted and predicted again; a pair is swept from the later of its two clocks, so a predicted
time depends only on the pair's state, not on when (or on which grid) it was asked. Frames
sample each object at the tick's end from its own clock.

Robust rules (contact.next_contact): touching or overlapping and approaching collide now;
overlapping and separating make no event; nothing is scheduled in the past; a pair that has just
collided is not predicted against itself again (on straight lines it cannot meet again before one
of the two has another event), so a rounding error cannot make it collide twice. Zero-time chains
(a row of touching boxes hit at one end) then run as a sequence of events at one instant. A tick
that needs more than `max_events_per_tick` events raises EventCapExceeded: a runaway is an error,
never a hang.

An object with no room to move on an axis would collide again and again at one instant: one
that moves on an axis along which it touches (or overlaps) a wall or a static object on both
sides, as a box as wide as the world moving on x does. The model refuses such a scene when it is
built (`no_room` finds them; NoRoom names the object, the axis and what holds it). A jam it cannot
see up front (a row of moving objects wedged together) ends at the cap; the stopped model then
runs a few more events with the log on, and when the objects of those at the last instant are held
from both sides by a touching chain from wall or static object to wall or static object, the
error is NoRoom naming them (the hot loop keeps no record for this).

The kernel counts the wall and pair events as they happen, logged or not (`event_counts`).

State is packed in few arrays, floats F (n, 8) and ints N (n, 7), columns named below; the heap
is HT (time), HI (key, counters) and HN (contact normal). The small helpers are inlined into two
kernels, `_predict` and `_run`, which allocate nothing: growing the heap or the event log is
done in Python between calls (the kernel stops before an event it has no room for, and resumes).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from collide2d.engine.broadphase import choose, find_pairs, grid_cell, grid_dims, static_cells
from collide2d.engine.contact import box_next_contact, box_reach, next_contact
from collide2d.engine.errors import EventCapExceeded, NoRoom
from collide2d.engine.events import (
    AXIS_NAMES,
    AXIS_X,
    AXIS_Y,
    EV_PAIR,
    EV_WALL,
    SIDE_BOTTOM,
    SIDE_LEFT,
    SIDE_RIGHT,
    SIDE_TOP,
)
from collide2d.engine.models.stepped import event_records, new_log
from collide2d.engine.response import exchange
from collide2d.engine.shapes import GEOMETRIES, build_cores
from collide2d.engine.world import KIND_BOX, Bodies, WorldSpec

# Most wall and pair events one tick may take before the run is stopped as a runaway.
MAX_EVENTS_PER_TICK = 1_000_000
# After an event, predict again only the objects it touched ("touched", the model), or every
# moving object ("all": the same events at the same times up to rounding, at the cost the local
# re-prediction saves; its heap room grows with n^2, so only for small scenes: tests and
# `collide2d bench`).
REPREDICT = ("touched", "all")
# Heap entries to start with per object (the heap drops stale entries, or doubles, when full).
HEAP_PER_OBJECT = 4
# Children per heap node: a 4-ary heap is half as deep as a binary one, and its four children
# share a cache line.
ARITY = 4

# Columns of F (n, 8) float64: position (top-left, px) valid at the object's own clock TLOC (s),
# velocity (px/s), box size (px), inverse mass (0 for static objects).
X, Y, VX, VY, TLOC, SW, SH, INV_MASS = range(8)
# Columns of N (n, 8) int64: invalidation counter, static flag, contact shape kind, grid cell,
# next / previous object in that cell's list (-1 for none), last query stamp (static objects),
# the partner of its last event if that was a pair (-1 otherwise).
CNT, STATIC, SHAPE, CELL, NEXT, PREV, STAMP, PARTNER = range(8)
# Heap: HT (cap,) float64 times; HI (cap, 3) int64 key and the two counters; HN (cap, 2) float64
# the contact normal (code and normal as contact.py gives them).
HKEY, HCA, HCB = range(3)
# Grid cells (gnx·gny, 2) int64: the first moving object filed there (-1: none) and how many.
C_HEAD, C_COUNT = range(2)
# A prediction job (one row of `jobs`): the object, the partner to leave out (-1: none), and its
# mode: JOB_EVENT (after an event of the object), JOB_FIRST (the first prediction: only static
# objects and higher ids, each pair once), JOB_CONTACTS (only contacts, no horizon: the extra
# predictions of `repredict="all"`).
J_OBJ, J_SKIP, J_HIGHER = range(3)
JOB_EVENT, JOB_FIRST, JOB_CONTACTS = range(3)
# Rows of `jobs`: the (at most two) objects an event touched, and one for the extra predictions.
JOB_ROWS = 3
J_EXTRA = 2

# Heap keys: rank, a, b (or a wall side / crossing direction) and contact code in one int64, so that
# ties in time resolve as crossings, then walls by (id, side), then pairs by (a, b).
RANK_CROSS = 0
RANK_WALL = 1
RANK_PAIR = 2
_ID_BITS = 25  # ids below 2**25 (33 million objects)
_ID_MASK = (1 << _ID_BITS) - 1
_B_SHIFT = 4
_A_SHIFT = _B_SHIFT + _ID_BITS
_RANK_SHIFT = _A_SHIFT + _ID_BITS
MAX_OBJECTS = 1 << _ID_BITS

# Cell-crossing directions.
DIR_LEFT, DIR_RIGHT, DIR_UP, DIR_DOWN = range(4)

# Scalar state st (int64): heap size, ticks done, events in the current tick, query stamp, event
# rows written in this `advance`, objects given their first prediction, wall events and pair
# events so far (logged or not). stf (float64): the current time, s.
_HEAP_N, _TICK, _TICK_EVENTS, _STAMP, _LOGGED, _FIRST, _WALLS, _PAIRS = range(8)
_T_NOW = 0
# Who a runaway involves: once a tick stops at the cap, the model (stopped for good) runs up to
# RECENT more events with the log on and looks at them, so the hot loop keeps no record of its own.
RECENT = 64
# Static objects are searched for a wedge among the boxes grown by this much (px) along the axis.
WEDGE_REACH_PX = 0.5

# Events closer in time than max(INSTANT_S, INSTANT_REL·t) are one instant: what parts them is
# rounding (a few units in the last place of t, or of a pixel coordinate over a speed), not
# physics, so they go in key order. At most INSTANT_STACK entries of one instant are compared.
INSTANT_S = 1e-12
INSTANT_REL = 2.0**-46
INSTANT_STACK = 1024

STATUS_DONE = 0
STATUS_CAP = 1
STATUS_HEAP_FULL = 2
STATUS_LOG_FULL = 3

INF = np.inf
# Small helpers are inlined into the kernels. The kernels allocate nothing and only touch arrays
# handed to them, so they are compiled without reference counting (numba's `_nrt=False`):
# counting references to those arrays at every inlined helper took ~85 % of the run time.
_hot = njit(cache=True, inline="always")
_kernel = njit(cache=True, _nrt=False)


# --- heap keys and entries ---------------------------------------------------------------------


@_hot
def _key(rank, a, b, code):
    return (rank << _RANK_SHIFT) | (a << _A_SHIFT) | (b << _B_SHIFT) | code


@_hot
def _unkey(key):
    """(rank, a, b, code) of a heap key."""
    return (
        key >> _RANK_SHIFT,
        (key >> _A_SHIFT) & _ID_MASK,
        (key >> _B_SHIFT) & _ID_MASK,
        key & 15,
    )


@_hot
def _valid(HI, i, N):
    """Entry i is valid while its objects' counters are those it was predicted with."""
    rank, a, b, _ = _unkey(HI[i, HKEY])
    if N[a, CNT] != HI[i, HCA]:
        return False
    return rank != RANK_PAIR or N[b, CNT] == HI[i, HCB]


# --- the heap; the caller makes sure there is room before an event -----------------------------


@_hot
def _earlier(HT, HI, i, t, key):
    """Entry i comes strictly before (t, key)."""
    return HT[i] < t or (HT[i] == t and HI[i, HKEY] < key)


@_hot
def _put(HT, HI, HN, i, t, key, ca, cb, nx, ny):
    HT[i] = t
    HI[i, HKEY], HI[i, HCA], HI[i, HCB] = key, ca, cb
    HN[i, 0], HN[i, 1] = nx, ny


@_hot
def _move(HT, HI, HN, i, j):
    """Entry j moves to slot i."""
    _put(HT, HI, HN, i, HT[j], HI[j, HKEY], HI[j, HCA], HI[j, HCB], HN[j, 0], HN[j, 1])


@_hot
def _sift_up(HT, HI, HN, i, t, key, ca, cb, nx, ny):
    """Place an entry at hole i, moving it up past later parents."""
    while i > 0:
        p = (i - 1) // ARITY
        if _earlier(HT, HI, p, t, key) or (HT[p] == t and HI[p, HKEY] == key):
            break
        _move(HT, HI, HN, i, p)
        i = p
    _put(HT, HI, HN, i, t, key, ca, cb, nx, ny)


@_hot
def _sift_down(HT, HI, HN, n, i, t, key, ca, cb, nx, ny):
    """Place an entry at hole i of a heap of n, moving it down past earlier children."""
    while True:
        first = ARITY * i + 1
        if first >= n:
            break
        c = first
        for m in range(first + 1, min(first + ARITY, n)):
            if _earlier(HT, HI, m, HT[c], HI[c, HKEY]):
                c = m
        if not _earlier(HT, HI, c, t, key):
            break
        _move(HT, HI, HN, i, c)
        i = c
    _put(HT, HI, HN, i, t, key, ca, cb, nx, ny)


@_hot
def _push(HT, HI, HN, st, t, key, ca, cb, nx, ny):
    """Add an entry (there is room)."""
    n = st[_HEAP_N]
    st[_HEAP_N] = n + 1
    _sift_up(HT, HI, HN, n, t, key, ca, cb, nx, ny)


@_hot
def _pop(HT, HI, HN, st):
    """Remove and return the earliest entry (t, key, ca, cb, nx, ny)."""
    top = (HT[0], HI[0, HKEY], HI[0, HCA], HI[0, HCB], HN[0, 0], HN[0, 1])
    n = st[_HEAP_N] - 1
    st[_HEAP_N] = n
    if n > 0:
        _sift_down(HT, HI, HN, n, 0, HT[n], HI[n, HKEY], HI[n, HCA], HI[n, HCB], HN[n, 0], HN[n, 1])
    return top


@_hot
def _remove(HT, HI, HN, st, k):
    """Remove and return entry k (t, key, ca, cb, nx, ny); the last entry takes its place."""
    entry = (HT[k], HI[k, HKEY], HI[k, HCA], HI[k, HCB], HN[k, 0], HN[k, 1])
    n = st[_HEAP_N] - 1
    st[_HEAP_N] = n
    if k < n:
        t, key, ca, cb, nx, ny = HT[n], HI[n, HKEY], HI[n, HCA], HI[n, HCB], HN[n, 0], HN[n, 1]
        if k > 0 and not _earlier(HT, HI, (k - 1) // ARITY, t, key):
            _sift_up(HT, HI, HN, k, t, key, ca, cb, nx, ny)
        else:
            _sift_down(HT, HI, HN, n, k, t, key, ca, cb, nx, ny)
    return entry


@_hot
def _instant(t):
    """Events closer to t than this (s) happen at one instant: rounding, not physics, parts them."""
    return max(INSTANT_S, abs(t) * INSTANT_REL)


@_hot
def _first_of_instant(HT, HI, st, N, stack):
    """The entry to take next: of the valid entries at the top's instant, the one with the
    smallest key, so that simultaneous events go walls first, then pairs in (a, b) order,
    whatever rounding did to their times. Those entries are the heap's top subtree of times
    within the instant; `stack` is scratch for walking it."""
    n = st[_HEAP_N]
    bound = HT[0] + _instant(HT[0])
    best = 0
    sp = 0
    for c in range(1, min(1 + ARITY, n)):
        if HT[c] <= bound:
            stack[sp] = c
            sp += 1
    while sp > 0:
        sp -= 1
        k = stack[sp]
        if HI[k, HKEY] < HI[best, HKEY] and _valid(HI, k, N):
            best = k
        for c in range(ARITY * k + 1, min(ARITY * k + 1 + ARITY, n)):
            if HT[c] <= bound and sp < stack.shape[0]:
                stack[sp] = c
                sp += 1
    return best


@njit(cache=True)
def _compact(HT, HI, HN, st, N):
    """Drop stale entries and rebuild the heap in place; returns the free room."""
    keep = 0
    for i in range(st[_HEAP_N]):
        if _valid(HI, i, N):
            _move(HT, HI, HN, keep, i)
            keep += 1
    for i in range((keep - 2) // ARITY, -1, -1):
        _sift_down(
            HT, HI, HN, keep, i, HT[i], HI[i, HKEY], HI[i, HCA], HI[i, HCB], HN[i, 0], HN[i, 1]
        )
    st[_HEAP_N] = keep
    return HT.shape[0] - keep


@_hot
def _has_room(room, HT, HI, HN, st, N):
    """Whether `room` more entries fit, dropping stale entries first if they would not."""
    return HT.shape[0] - st[_HEAP_N] >= room or _compact(HT, HI, HN, st, N) >= room


def _grown(a: np.ndarray) -> np.ndarray:
    """a with twice the rows, the old rows kept."""
    out = np.empty((2 * a.shape[0],) + a.shape[1:], a.dtype)
    out[: a.shape[0]] = a
    return out


# --- grid cells: doubly linked lists of the moving objects in each cell -----------------------


@_hot
def _cell_insert(N, cells, i, c):
    N[i, CELL] = c
    N[i, PREV] = -1
    N[i, NEXT] = cells[c, C_HEAD]
    if cells[c, C_HEAD] >= 0:
        N[cells[c, C_HEAD], PREV] = i
    cells[c, C_HEAD] = i
    cells[c, C_COUNT] += 1


@_hot
def _cell_remove(N, cells, i):
    if N[i, PREV] >= 0:
        N[N[i, PREV], NEXT] = N[i, NEXT]
    else:
        cells[N[i, CELL], C_HEAD] = N[i, NEXT]
    if N[i, NEXT] >= 0:
        N[N[i, NEXT], PREV] = N[i, PREV]
    cells[N[i, CELL], C_COUNT] -= 1


@njit(cache=True)
def _build_grid(F, N, cell, gnx, gny):
    """Grid (cells, static_start, static_items); moving objects filed by their box centre."""
    cells = np.zeros((gnx * gny, 2), np.int64)
    cells[:, C_HEAD] = -1
    static = N[:, STATIC] != 0
    s_start, s_items = static_cells(
        F[:, X : Y + 1].copy(), F[:, SW : SH + 1].copy(), static, cell, gnx, gny
    )
    for i in range(F.shape[0] - 1, -1, -1):  # lists then run in id order
        N[i, CELL] = -1
        if not static[i]:
            cx = min(max(int((F[i, X] + 0.5 * F[i, SW]) // cell), 0), gnx - 1)
            cy = min(max(int((F[i, Y] + 0.5 * F[i, SH]) // cell), 0), gny - 1)
            _cell_insert(N, cells, i, cy * gnx + cx)
    return cells, s_start, s_items


@_hot
def _room_around(gx, gy, N, cells, s_start, world):
    """Heap entries a prediction in cell (gx, gy) may push: a horizon, and one contact per object
    filed in the 3×3 cells around it (moving and static)."""
    gnx, gny = world[4], world[5]
    room = 1
    for cy in range(max(gy - 1, 0), min(gy + 1, gny - 1) + 1):
        for cx in range(max(gx - 1, 0), min(gx + 1, gnx - 1) + 1):
            c = cy * gnx + cx
            room += cells[c, C_COUNT] + s_start[c + 1] - s_start[c]
    return room


@_hot
def _room_needed(rank, a, b, HT, st, N, cells, s_start, world):
    """Heap entries the event (rank, a, b) may push at most; when the heap has room for the worst
    case of any event (two predictions against everything), it is not counted."""
    if HT.shape[0] - st[_HEAP_N] >= 2 * (N.shape[0] + 1):
        return 0
    gnx = world[4]
    gx = N[a, CELL] % gnx
    gy = N[a, CELL] // gnx
    if rank == RANK_CROSS:
        gx += 1 if b == DIR_RIGHT else -1 if b == DIR_LEFT else 0
        gy += 1 if b == DIR_DOWN else -1 if b == DIR_UP else 0
        return _room_around(gx, gy, N, cells, s_start, world)
    room = _room_around(gx, gy, N, cells, s_start, world)
    if rank == RANK_PAIR:
        room += _room_around(N[b, CELL] % gnx, N[b, CELL] // gnx, N, cells, s_start, world)
    return room


# --- predictions -------------------------------------------------------------------------------


@_hot
def _wall_time(i, F, world):
    """(t, side) of i's next wall contact (its box touching a wall line), (inf, -1) if none."""
    t_best = INF
    side = -1
    if F[i, VX] > 0.0:
        t_best, side = F[i, TLOC] + (world[0] - F[i, SW] - F[i, X]) / F[i, VX], SIDE_RIGHT
    elif F[i, VX] < 0.0:
        t_best, side = F[i, TLOC] + F[i, X] / -F[i, VX], SIDE_LEFT
    if F[i, VY] > 0.0:
        t = F[i, TLOC] + (world[1] - F[i, SH] - F[i, Y]) / F[i, VY]
        if t < t_best:
            t_best, side = t, SIDE_BOTTOM
    elif F[i, VY] < 0.0:
        t = F[i, TLOC] + F[i, Y] / -F[i, VY]
        if t < t_best:
            t_best, side = t, SIDE_TOP
    return t_best, side


@_hot
def _cross_time(i, F, N, world):
    """(t, direction) when i's box centre next leaves its grid cell, (inf, -1) if never."""
    cell, gnx, gny = world[3], world[4], world[5]
    gx = N[i, CELL] % gnx
    gy = N[i, CELL] // gnx
    cx = F[i, X] + 0.5 * F[i, SW]
    cy = F[i, Y] + 0.5 * F[i, SH]
    t_best = INF
    d = -1
    if F[i, VX] > 0.0 and gx < gnx - 1:
        t_best, d = F[i, TLOC] + ((gx + 1) * cell - cx) / F[i, VX], DIR_RIGHT
    elif F[i, VX] < 0.0 and gx > 0:
        t_best, d = F[i, TLOC] + (gx * cell - cx) / F[i, VX], DIR_LEFT
    if F[i, VY] > 0.0 and gy < gny - 1:
        t = F[i, TLOC] + ((gy + 1) * cell - cy) / F[i, VY]
        if t < t_best:
            t_best, d = t, DIR_DOWN
    elif F[i, VY] < 0.0 and gy > 0:
        t = F[i, TLOC] + (gy * cell - cy) / F[i, VY]
        if t < t_best:
            t_best, d = t, DIR_UP
    return t_best, d


@njit(cache=True)
def _shape_contact(a, b, qx, qy, ux, uy, now, F, N, C):
    """next_contact for a pair with a circle or polygon; cores C = (radius, start, verts,
    normals)."""
    radius, start, verts, normals = C
    return next_contact(
        qx,
        qy,
        ux,
        uy,
        N[a, SHAPE],
        F[a, SW],
        F[a, SH],
        radius[a],
        verts[start[a] : start[a + 1]],
        normals[start[a] : start[a + 1]],
        N[b, SHAPE],
        F[b, SW],
        F[b, SH],
        radius[b],
        verts[start[b] : start[b + 1]],
        normals[start[b] : start[b + 1]],
        now,
    )


@_hot
def _predict_pair(i, j, t_now, horizon, F, N, C, HT, HI, HN, st):
    """Push the next contact of i and j if it comes no later than `horizon` (s).

    The pair is swept from the later of the two objects' clocks, so that only one position is
    carried forward and the predicted time does not depend on when the question is asked.
    """
    a = min(i, j)
    b = max(i, j)
    t0 = max(F[a, TLOC], F[b, TLOC])
    qx = (F[b, X] + F[b, VX] * (t0 - F[b, TLOC])) - (F[a, X] + F[a, VX] * (t0 - F[a, TLOC]))
    qy = (F[b, Y] + F[b, VY] * (t0 - F[b, TLOC])) - (F[a, Y] + F[a, VY] * (t0 - F[a, TLOC]))
    ux = F[b, VX] - F[a, VX]
    uy = F[b, VY] - F[a, VY]
    if not box_reach(qx, qy, ux, uy, F[a, SW], F[a, SH], F[b, SW], F[b, SH], horizon - t0):
        return
    now = t_now - t0
    if N[a, SHAPE] == KIND_BOX and N[b, SHAPE] == KIND_BOX:
        t, code, nx, ny = box_next_contact(
            qx, qy, ux, uy, F[a, SW], F[a, SH], F[b, SW], F[b, SH], now
        )
    else:
        t, code, nx, ny = _shape_contact(a, b, qx, qy, ux, uy, now, F, N, C)
    t = max(t0 + t, t_now)
    if t <= horizon:
        _push(HT, HI, HN, st, t, _key(RANK_PAIR, a, b, code), N[a, CNT], N[b, CNT], nx, ny)


@_kernel
def _predict(jobs, k, t_now, F, N, C, cells, s_start, s_items, HT, HI, HN, st, world):
    """Run prediction job k for object i: push its horizon (the first of its next wall contact
    and its next cell crossing) and its contacts with the objects in the 3×3 cells around it
    that come no later than that."""
    i, skip, mode = jobs[k, J_OBJ], jobs[k, J_SKIP], jobs[k, J_HIGHER]
    higher = mode == JOB_FIRST
    t_wall, side = _wall_time(i, F, world)
    t_cross, d = _cross_time(i, F, N, world)
    if mode == JOB_CONTACTS:
        pass
    elif t_cross <= t_wall and t_cross < INF:
        key = _key(RANK_CROSS, i, d, d)
        _push(HT, HI, HN, st, max(t_cross, t_now), key, N[i, CNT], 0, 0.0, 0.0)
    elif t_wall < INF:
        key = _key(RANK_WALL, i, side, side)
        _push(HT, HI, HN, st, max(t_wall, t_now), key, N[i, CNT], 0, 0.0, 0.0)
    horizon = max(min(t_wall, t_cross), t_now)
    gnx, gny = world[4], world[5]
    gx = N[i, CELL] % gnx
    gy = N[i, CELL] // gnx
    st[_STAMP] += 1
    for cy in range(max(gy - 1, 0), min(gy + 1, gny - 1) + 1):
        for cx in range(max(gx - 1, 0), min(gx + 1, gnx - 1) + 1):
            c = cy * gnx + cx
            j = cells[c, C_HEAD]
            while j >= 0:
                if j != i and j != skip and not (higher and j < i):
                    _predict_pair(i, j, t_now, horizon, F, N, C, HT, HI, HN, st)
                j = N[j, NEXT]
            for m in range(s_start[c], s_start[c + 1]):
                j = s_items[m]
                if N[j, STAMP] != st[_STAMP] and j != skip:
                    N[j, STAMP] = st[_STAMP]
                    _predict_pair(i, j, t_now, horizon, F, N, C, HT, HI, HN, st)


@_hot
def _job(jobs, k, i, skip, higher):
    jobs[k, J_OBJ], jobs[k, J_SKIP], jobs[k, J_HIGHER] = i, skip, higher


# --- events: each changes the state and says which objects to predict again --------------------


@_hot
def _move_to(i, t, F):
    """Bring object i's position to time t."""
    dt = t - F[i, TLOC]
    F[i, X] += F[i, VX] * dt
    F[i, Y] += F[i, VY] * dt
    F[i, TLOC] = t


@_hot
def _on_cross(i, d, N, cells, world, jobs):
    """i's centre enters the next cell: refile it. Returns the number of jobs (1)."""
    gnx = world[4]
    gx = N[i, CELL] % gnx + (1 if d == DIR_RIGHT else -1 if d == DIR_LEFT else 0)
    gy = N[i, CELL] // gnx + (1 if d == DIR_DOWN else -1 if d == DIR_UP else 0)
    _cell_remove(N, cells, i)
    _cell_insert(N, cells, i, gy * gnx + gx)
    N[i, PARTNER] = -1
    _job(jobs, 0, i, -1, JOB_EVENT)
    return 1


@_hot
def _on_wall(i, side, t, F, N, world, jobs):
    """i's box touches a wall: reflect that velocity component, set it exactly on the wall line.
    Returns the number of jobs (1)."""
    _move_to(i, t, F)
    if side == SIDE_LEFT or side == SIDE_RIGHT:
        F[i, VX] = -F[i, VX]
        F[i, X] = 0.0 if side == SIDE_LEFT else world[0] - F[i, SW]
    else:
        F[i, VY] = -F[i, VY]
        F[i, Y] = 0.0 if side == SIDE_TOP else world[1] - F[i, SH]
    N[i, CNT] += 1
    N[i, PARTNER] = -1
    _job(jobs, 0, i, -1, JOB_EVENT)
    return 1


@_hot
def _on_pair(a, b, code, nx, ny, t, F, N, jobs):
    """a and b touch: the elastic exchange; then each moving one is predicted again, but not
    against the other. Returns the number of jobs (0: they were not approaching, no event)."""
    _move_to(a, t, F)
    _move_to(b, t, F)
    vax, vay, vbx, vby, changed = exchange(
        F[a, VX], F[a, VY], F[b, VX], F[b, VY], F[a, INV_MASS], F[b, INV_MASS], code, nx, ny
    )
    if not changed:
        return 0
    F[a, VX], F[a, VY], F[b, VX], F[b, VY] = vax, vay, vbx, vby
    n_jobs = 0
    for i, other in ((a, b), (b, a)):
        if N[i, STATIC] == 0:
            N[i, CNT] += 1
            N[i, PARTNER] = other
            _job(jobs, n_jobs, i, other, JOB_EVENT)
            n_jobs += 1
    return n_jobs


@_hot
def _log_row(rows, times, n, tick, t, kind, a, b, code):
    rows[n, 0], rows[n, 1], rows[n, 2], rows[n, 3], rows[n, 4] = tick, kind, a, b, code
    times[n] = t


# --- the kernels ---------------------------------------------------------------------------------


@_kernel
def _run(
    jobs,
    stack,
    tick_to,
    log,
    cap,
    everyone,
    F,
    N,
    C,
    cells,
    s_start,
    s_items,
    HT,
    HI,
    HN,
    st,
    stf,
    world,
    rows,
    times,
):
    """Run ticks until tick_to: first (once) predict every object's first events; then take due
    events in order, apply each, predict again for the objects it touched. (Objects not touched
    keep their clocks; positions() moves them to the tick's end.)

    With `everyone` (the `repredict="all"` option) every other moving object is predicted again
    as well after each event (contacts only, against all but the partner of its last pair
    event): the work the local re-prediction saves. The events are the same; a time asked again
    may differ in its last bits, since an object's clock moves by one rounded step when a pair
    it is in turns out not to approach.

    Returns a status: STATUS_DONE; STATUS_HEAP_FULL / STATUS_LOG_FULL (grow, call again: nothing
    was lost); STATUS_CAP (a runaway; stops mid-tick, before the event past the cap, so that a call
    with a higher cap would resume). st[_LOGGED] counts the rows written, st[_WALLS] and st[_PAIRS]
    every event, logged or not.
    """
    extra_room = F.shape[0] * F.shape[0] if everyone else 0
    while st[_FIRST] < F.shape[0]:  # the first predictions, at time 0: each pair once
        i = st[_FIRST]
        if N[i, STATIC] == 0:
            room = _room_around(
                N[i, CELL] % world[4], N[i, CELL] // world[4], N, cells, s_start, world
            )
            if not _has_room(room, HT, HI, HN, st, N):
                return STATUS_HEAP_FULL
            _job(jobs, 0, i, -1, JOB_FIRST)
            for k in range(1):  # (as below: typed arguments, so that one compiled _predict serves)
                _predict(
                    jobs, k, stf[_T_NOW], F, N, C, cells, s_start, s_items, HT, HI, HN, st, world
                )
        st[_FIRST] += 1
    while st[_TICK] < tick_to:
        tick = st[_TICK] + 1
        t_end = tick / world[2]
        while st[_HEAP_N] > 0 and HT[0] <= t_end + _instant(t_end):  # t = k/fps is tick k's
            if not _valid(HI, 0, N):
                _pop(HT, HI, HN, st)
                continue
            k = _first_of_instant(HT, HI, st, N, stack)
            rank, a, b, code = _unkey(HI[k, HKEY])
            room = _room_needed(rank, a, b, HT, st, N, cells, s_start, world) + extra_room
            if HT.shape[0] - st[_HEAP_N] < room:
                if _compact(HT, HI, HN, st, N) < room:
                    return STATUS_HEAP_FULL
                continue  # the entries moved: pick again
            if log and st[_LOGGED] == rows.shape[0]:
                return STATUS_LOG_FULL
            t, key, ca, cb, nx, ny = _remove(HT, HI, HN, st, k)
            stf[_T_NOW] = t
            if rank == RANK_CROSS:
                n_jobs = _on_cross(a, b, N, cells, world, jobs)
            else:
                st[_TICK_EVENTS] += 1
                if st[_TICK_EVENTS] > cap:  # put it back: a call with a higher cap resumes
                    st[_TICK_EVENTS] -= 1
                    _push(HT, HI, HN, st, t, key, ca, cb, nx, ny)
                    return STATUS_CAP
                if rank == RANK_WALL:
                    n_jobs = _on_wall(a, b, t, F, N, world, jobs)
                    kind, b = EV_WALL, -1
                else:
                    n_jobs = _on_pair(a, b, code, nx, ny, t, F, N, jobs)
                    kind = EV_PAIR
                if n_jobs > 0:  # a pair that was not approaching is no event
                    st[_WALLS if kind == EV_WALL else _PAIRS] += 1
                    if log:
                        _log_row(rows, times, st[_LOGGED], tick, t, kind, a, b, code)
                        st[_LOGGED] += 1
            for k in range(n_jobs):
                _predict(jobs, k, t, F, N, C, cells, s_start, s_items, HT, HI, HN, st, world)
            if everyone and n_jobs > 0:
                for i in range(F.shape[0]):
                    if (
                        N[i, STATIC] == 0
                        and i != jobs[0, J_OBJ]
                        and (n_jobs < 2 or i != jobs[1, J_OBJ])
                    ):
                        _job(jobs, J_EXTRA, i, N[i, PARTNER], JOB_CONTACTS)
                        _predict(
                            jobs,
                            J_EXTRA,
                            t,
                            F,
                            N,
                            C,
                            cells,
                            s_start,
                            s_items,
                            HT,
                            HI,
                            HN,
                            st,
                            world,
                        )
        stf[_T_NOW] = t_end
        st[_TICK] = tick
        st[_TICK_EVENTS] = 0
    return STATUS_DONE


class Wedge(NamedTuple):
    """An object with no room to move on an axis: `obj` moves on `axis` (AXIS_X or AXIS_Y) and
    touches (or overlaps) `low` on its low side and `high` on its high side; each is a static
    object's id, or WALL for the world's wall on that side."""

    obj: int
    axis: int
    low: int
    high: int


WALL = -1
_NONE = -2


def no_room(world: WorldSpec, bodies: Bodies, geometry: str | None = "exact") -> list[Wedge]:
    """Every moving object with no room on an axis it moves on, in (id, axis) order: its velocity
    on the axis is not 0, and along that axis it touches or overlaps a wall or a static object
    on both sides (a static one only when its box overlaps the mover's box on the other axis with
    positive length). Under `geometry: exact` a static object holds a mover only when both are
    boxes (other shapes touch by their real outline); the walls hold every shape by its box.
    Such an object would collide again and again with no time passing. Linear work in n but for
    one broad-phase pass when there are static objects."""
    geometry = "exact" if geometry is None else geometry
    static = np.asarray(bodies.static, bool)
    pos = np.asarray(bodies.pos, np.float64).reshape(-1, 2)
    size = np.asarray(bodies.size, np.float64).reshape(-1, 2)
    vel = np.asarray(bodies.vel, np.float64).reshape(-1, 2)
    boxy = np.ones(len(static), bool) if geometry == "box" else bodies.kind == KIND_BOX
    found = []
    for axis, side in ((AXIS_X, float(world.width)), (AXIS_Y, float(world.height))):
        k = 0 if axis == AXIS_X else 1
        moving = ~static & (vel[:, k] != 0.0)
        if not moving.any():
            continue
        low = np.where(moving & (pos[:, k] <= 0.0), WALL, _NONE)
        high = np.where(moving & (pos[:, k] + size[:, k] >= side), WALL, _NONE)
        holders = static & boxy
        if holders.any() and (moving & boxy & ((low == _NONE) | (high == _NONE))).any():
            _static_holders(pos, size, moving & boxy, holders, k, world, low, high)
        for i in np.flatnonzero((low != _NONE) & (high != _NONE)):
            found.append(Wedge(int(i), axis, int(low[i]), int(high[i])))
    return sorted(found)


def _static_holders(pos, size, movers, holders, k, world, low, high):
    """Fill low/high (where _NONE) with the lowest id of a static box that holds each mover from
    below / above along axis k: it overlaps the mover's box on the other axis, and on axis k it
    reaches to the mover's low edge (touching or overlapping) without reaching past its high edge
    (from below), or the other way round (from above). A static box holding it from both sides
    (the mover inside it on that axis) is neither: once they collide they separate."""
    sel = np.flatnonzero(movers | holders)
    lo = pos[sel].copy()
    hi = lo + size[sel]
    lo[:, k] -= WEDGE_REACH_PX
    hi[:, k] += WEDGE_REACH_PX
    method, cell = choose(world.width, world.height, hi - lo)
    pairs = sel[find_pairs(method, lo, hi, movers[sel], cell)]
    a, b = pairs[:, 0], pairs[:, 1]
    mixed = movers[a] != movers[b]
    a, b = a[mixed], b[mixed]
    m = np.where(movers[a], a, b)
    s = np.where(movers[a], b, a)
    m_lo, s_lo = pos[m, k], pos[s, k]
    m_hi, s_hi = m_lo + size[m, k], s_lo + size[s, k]
    none = np.iinfo(np.int64).max
    for side, held in (
        (low, (s_lo < m_lo) & (m_lo <= s_hi) & (s_hi < m_hi)),
        (high, (m_lo < s_lo) & (s_lo <= m_hi) & (m_hi < s_hi)),
    ):
        first = np.full(len(side), none, np.int64)
        np.minimum.at(first, m[held], s[held])
        take = (side == _NONE) & (first != none)
        side[take] = first[take]


def no_room_message(found: list[Wedge], bodies: Bodies, names=None) -> str:
    """What `no_room` found, in words: the first object (`names[i]` when given, shown beside its
    id) and what holds it, then how many more."""
    w = found[0]
    k = 0 if w.axis == AXIS_X else 1
    axis = AXIS_NAMES[w.axis]
    name = names[w.obj] if names is not None and names[w.obj] else None
    who = f"object {w.obj}" + (f" ({name})" if name else "")
    sides = ("left", "right") if w.axis == AXIS_X else ("top", "bottom")
    wide = "wide" if w.axis == AXIS_X else "tall"

    def holder(j, side):
        return f"the {side} wall" if j == WALL else f"static object {j}"

    if w.low == WALL and w.high == WALL:
        span = f"it is as {wide} as the world"
    else:
        span = (
            f"it is as {wide} as the space between {holder(w.low, sides[0])} and "
            f"{holder(w.high, sides[1])} (or wider)"
        )
    v = float(np.asarray(bodies.vel, np.float64).reshape(-1, 2)[w.obj, k])
    also = [f for f in found[1:] if f.obj == w.obj]
    both = f" (and on {AXIS_NAMES[also[0].axis]})" if also else ""
    more = len({f.obj for f in found}) - 1
    rest = f"; {more} more such object{'s' if more > 1 else ''}" if more else ""
    return (
        f"{who} has no room to move on {axis}{both}: {span}, and it moves on {axis} "
        f"(v{axis} = {v:g} px/s), so under the exact model it would collide again and again "
        f"with no time passing; give it room or no velocity on {axis}{rest}"
    )


def _listing(word: str, ids: list[int], most: int = 8) -> str:
    """ "object 3", "objects 1 and 2", "objects 1, 2, 3, ... (12 in all)"."""
    if len(ids) == 1:
        return f"{word} {ids[0]}"
    shown = [str(i) for i in ids[:most]]
    if len(ids) > most:
        return f"{word}s {', '.join(shown)}, ... ({len(ids)} in all)"
    return f"{word}s {', '.join(shown[:-1])} and {shown[-1]}"


class Model:
    """Event-driven elastic model; see the module docstring. Surface as in engine.models."""

    def __init__(
        self,
        world: WorldSpec,
        bodies: Bodies,
        substeps: int = 1,
        geometry: str | None = None,
        max_events_per_tick: int = MAX_EVENTS_PER_TICK,
        cell_size: float | None = None,
        repredict: str = "touched",
    ):
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be a whole number >= 1, got {substeps!r}")
        geometry = "exact" if geometry is None else geometry
        if geometry not in GEOMETRIES:
            raise ValueError(f"unknown geometry {geometry!r}; expected one of {GEOMETRIES}")
        if int(max_events_per_tick) != max_events_per_tick or max_events_per_tick < 1:
            raise ValueError(f"max_events_per_tick must be >= 1, got {max_events_per_tick!r}")
        if bodies.n >= MAX_OBJECTS:
            raise ValueError(f"the exact model handles fewer than {MAX_OBJECTS} objects")
        if cell_size is not None and not cell_size > 0:
            raise ValueError(f"cell_size must be > 0 px, got {cell_size!r}")
        if repredict not in REPREDICT:
            raise ValueError(f"repredict must be one of {REPREDICT}, got {repredict!r}")
        stuck = no_room(world, bodies, geometry)
        if stuck:
            raise NoRoom(
                no_room_message(stuck, bodies),
                tuple(w.obj for w in stuck),
                AXIS_NAMES[stuck[0].axis],
            )
        self.repredict = repredict
        self.world = world
        self.geometry = geometry
        self.max_events_per_tick = int(max_events_per_tick)
        self.tick = 0
        self._broken = None
        n = bodies.n
        static = np.asarray(bodies.static, bool)
        cores = build_cores(bodies, geometry)
        self._F = np.zeros((n, 8))
        self._F[:, X : Y + 1] = bodies.pos
        self._F[:, VX : VY + 1] = np.where(static[:, None], 0.0, bodies.vel)
        self._F[:, SW : SH + 1] = bodies.size
        self._F[:, INV_MASS] = bodies.inv_mass
        self._N = np.zeros((n, 8), np.int64)
        self._N[:, PARTNER] = -1
        self._N[:, STATIC] = static
        self._N[:, SHAPE] = cores.shape
        self._C = (cores.radius, cores.start, cores.verts, cores.normals)
        if cell_size is None:
            cell_size = grid_cell(world.width, world.height, bodies.size, static)
        self.cell_size = float(cell_size)
        gnx, gny = grid_dims(world.width, world.height, self.cell_size)
        self._world = (
            float(world.width),
            float(world.height),
            float(world.fps),
            self.cell_size,
            gnx,
            gny,
        )
        self._G = _build_grid(self._F, self._N, self.cell_size, gnx, gny)
        cap = max(64, HEAP_PER_OBJECT * n)
        self._heap = [np.empty(cap), np.empty((cap, 3), np.int64), np.empty((cap, 2))]
        self._st = np.zeros(8, np.int64)
        self._stf = np.zeros(1)
        self._jobs = np.zeros((JOB_ROWS, 3), np.int64)  # scratch: the prediction jobs of one event
        self._stack = np.zeros(INSTANT_STACK, np.int64)  # scratch: walking one instant's entries

    def _state(self):
        """The arrays the kernels share: F, N, cores, grid (3), heap (3), st, world."""
        return (self._F, self._N, self._C, *self._G, *self._heap, self._st, self._world)

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events in the order they happened (empty when log is False)."""
        if self._broken:
            raise self._broken
        rows, times = new_log(log)
        self._st[_LOGGED] = 0
        target = self.tick + int(ticks)
        while True:
            status = self._call(target, bool(log), self.max_events_per_tick, rows, times)
            if status == STATUS_HEAP_FULL:
                self._heap = [_grown(a) for a in self._heap]
            elif status == STATUS_LOG_FULL:
                rows, times = _grown(rows), _grown(times)
            elif status == STATUS_CAP:
                self._broken = self._runaway()
                raise self._broken
            else:
                break
        self.tick = int(self._st[_TICK])
        return event_records(rows, times, int(self._st[_LOGGED]))

    def _call(self, target, log, cap, rows, times) -> int:
        """One call of the kernel `_run` on the model's state; its status."""
        F, N, C, cells, s_start, s_items, HT, HI, HN, st, world = self._state()
        return _run(
            self._jobs,
            self._stack,
            target,
            log,
            cap,
            self.repredict == "all",
            F,
            N,
            C,
            cells,
            s_start,
            s_items,
            HT,
            HI,
            HN,
            st,
            self._stf,
            world,
            rows,
            times,
        )

    def event_counts(self) -> tuple[int, int]:
        """(wall events, pair events) so far, logged or not."""
        return int(self._st[_WALLS]), int(self._st[_PAIRS])

    def _runaway(self) -> EventCapExceeded | NoRoom:
        """The error of a tick stopped at the cap: NoRoom when the objects of the events that
        would come next, at the instant it stopped, are jammed on an axis (`_jammed`: they collide
        again and again with no time passing, having no room to move), naming them; else
        EventCapExceeded. The model is stopped for good, so it runs up to RECENT more events of
        that tick, logged, to see them."""
        st, t = self._st, float(self._stf[_T_NOW])
        said = (
            f"tick {int(st[_TICK]) + 1} needed more than {self.max_events_per_tick} events "
            f"(max_events_per_tick); stopped as a runaway at t = {t!r} s"
        )
        counts = st[_WALLS : _PAIRS + 1].copy()
        st[_LOGGED] = 0
        rows, times = np.empty((RECENT, 5), np.int64), np.empty(RECENT)
        cap = int(st[_TICK_EVENTS]) + RECENT
        while self._call(int(st[_TICK]) + 1, True, cap, rows, times) == STATUS_HEAP_FULL:
            self._heap = [_grown(a) for a in self._heap]
        st[_WALLS : _PAIRS + 1] = counts  # the counts stay those of the events before the stop
        t = float(self._stf[_T_NOW])
        n = int(st[_LOGGED])
        same = np.abs(times[:n] - t) <= max(INSTANT_S, abs(t) * INSTANT_REL)
        last = rows[:n][same][:, 2:5]  # a, b, code
        involved = sorted({int(i) for i in last[:, :2].ravel() if i >= 0})
        walls = last[:, 1] < 0
        x_side = (last[:, 2] == SIDE_LEFT) | (last[:, 2] == SIDE_RIGHT)
        on = {
            AXIS_X: (walls & x_side) | (~walls & (last[:, 2] != AXIS_Y)),
            AXIS_Y: (walls & ~x_side) | (~walls & (last[:, 2] != AXIS_X)),
        }
        for axis in (AXIS_X, AXIS_Y):
            objects = self._jammed(involved, axis, t) if on[axis].any() else []
            if objects:
                one = len(objects) == 1
                against = " and the walls" if walls.any() else ""
                return NoRoom(
                    f"{_listing('object', objects)} {'has' if one else 'have'} no room to move on "
                    f"{AXIS_NAMES[axis]}: {'it collides' if one else 'they collide'} with "
                    f"{'its neighbours' if one else 'each other'}{against} again and again at "
                    f"t = {t!r} s with no time passing ({said})",
                    tuple(objects),
                    AXIS_NAMES[axis],
                )
        return EventCapExceeded(said)

    def _jammed(self, ids: list[int], axis: int, t: float) -> list[int]:
        """The moving objects of `ids` held on `axis` at time t from both sides by a chain of
        boxes of `ids` that touch (or overlap) along the axis and overlap on the other, from a
        wall or a static object to a wall or a static object: they cannot move on that axis."""
        F, k = self._F, 0 if axis == AXIS_X else 1
        ids = np.array(ids, np.int64)
        lo = F[ids, X : Y + 1] + F[ids, VX : VY + 1] * (t - F[ids, TLOC : TLOC + 1])
        hi = lo + F[ids, SW : SH + 1]
        side = self._world[k]
        tol = 1e-9 * max(self._world[0], self._world[1])
        fixed = self._N[ids, STATIC] != 0
        o = 1 - k
        beside = (lo[:, None, o] < hi[None, :, o]) & (lo[None, :, o] < hi[:, None, o])
        # below[j, i]: j touches i from below along the axis
        below = (
            beside & (lo[:, None, k] < lo[None, :, k]) & (hi[:, None, k] >= lo[None, :, k] - tol)
        )
        held = []
        for start, links in ((lo[:, k] <= tol, below), (hi[:, k] >= side - tol, below.T)):
            reached = fixed | start
            while True:
                more = reached | (links & reached[:, None]).any(axis=0)
                if (more == reached).all():
                    break
                reached = more
            held.append(reached)
        return [int(i) for i in ids[held[0] & held[1] & ~fixed]]

    def positions(self) -> np.ndarray:
        """(n, 2) float64 top-left corners at the last tick's end, px (each object carried from
        its own clock; kept inside the world against the last rounding)."""
        F = self._F
        t = self.tick / self._world[2]
        pos = F[:, X : Y + 1] + F[:, VX : VY + 1] * (t - F[:, TLOC : TLOC + 1])
        limit = np.array(self._world[:2]) - F[:, SW : SH + 1]
        return np.minimum(np.maximum(pos, 0.0), limit)

    def velocities(self) -> np.ndarray:
        """(n, 2) float64 velocities, px/s."""
        return self._F[:, VX : VY + 1].copy()
