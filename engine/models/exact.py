"""The `exact` model (SPEC 3.3): event-driven elastic collisions, the reference for every result.

Input: the world, the `Bodies` (copied) and the options `geometry` ("exact", the default: circles
and polygons by their real shapes; "box": every object as its box), `max_events_per_tick` and
`cell_size` (px; the grid's cell, chosen from the scene when not given). Output, per `advance`: the
wall and pair events in the order they happened, `t` = the exact contact time; positions and
velocities at the end of the last tick.

Objects fly on straight lines between events. A binary heap, in preallocated arrays that grow when
full, holds predicted events keyed by (time, rank, a, b): cell crossings first (bookkeeping, never
logged), then walls by id, then pairs in (a, b) order. Each object keeps its own clock (`tloc`: its
position is valid at that time) and an invalidation counter; an entry records the counters of its
objects when predicted and is skipped as stale if either has changed since. After an event only
the objects it touched are moved, counted and predicted again, against the 3×3 grid cells around
them (broadphase.py), so prediction stays local; a cell crossing predicts only against the cells it
brings into reach. At each tick's end every object is moved to that instant, for the frames.

Robust rules (contact.next_contact): touching or overlapping and approaching collide now;
overlapping and separating make no event; nothing is scheduled in the past; a pair that has just
collided is not predicted against itself again (on straight lines it cannot meet again before one
of the two has another event), so a rounding error cannot make it collide twice. Zero-time chains
(a row of touching boxes hit at one end) then run as a sequence of events at one instant. A tick
that needs more than `max_events_per_tick` events raises EventCapExceeded: a runaway is an error,
never a hang.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from engine.broadphase import grid_cell, grid_dims, static_cells
from engine.contact import next_contact
from engine.events import EV_PAIR, EV_WALL, SIDE_BOTTOM, SIDE_LEFT, SIDE_RIGHT, SIDE_TOP
from engine.models.stepped import event_records, log_event, new_log
from engine.response import exchange
from engine.shapes import GEOMETRIES, build_cores
from engine.world import Bodies, WorldSpec

# Most wall and pair events one tick may take before the run is stopped as a runaway.
MAX_EVENTS_PER_TICK = 1_000_000
# Heap entries to start with per object (the heap doubles, or drops stale entries, when full).
HEAP_PER_OBJECT = 8

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

# Crossing directions.
DIR_LEFT = 0
DIR_RIGHT = 1
DIR_UP = 2
DIR_DOWN = 3

# Scalar state, st (int64): heap size, ticks done, events in the current tick, query stamp.
_HEAP_N = 0
_TICK = 1
_TICK_EVENTS = 2
_STAMP = 3
# stf (float64): the current time, s.
_T_NOW = 0

STATUS_DONE = 0
STATUS_CAP = 1

INF = np.inf


class EventCapExceeded(RuntimeError):
    """A tick needed more events than allowed: a runaway (e.g. an object wedged between walls)."""


# --- heap keys and entries ---------------------------------------------------------------------


@njit(cache=True)
def _key(rank, a, b, code):
    return (rank << _RANK_SHIFT) | (a << _A_SHIFT) | (b << _B_SHIFT) | code


@njit(cache=True)
def _unkey(key):
    """(rank, a, b, code) of a heap key."""
    return (
        key >> _RANK_SHIFT,
        (key >> _A_SHIFT) & _ID_MASK,
        (key >> _B_SHIFT) & _ID_MASK,
        key & 15,
    )


@njit(cache=True)
def _valid(key, ca, cb, cnt):
    """An entry is valid while its objects' counters are those it was predicted with."""
    rank, a, b, _ = _unkey(key)
    if cnt[a] != ca:
        return False
    return rank != RANK_PAIR or cnt[b] == cb


# --- the binary heap (arrays: time, key, counter a, counter b, nx, ny) -------------------------


@njit(cache=True)
def _sift_up(H, i, t, key, ca, cb, nx, ny):
    ht, hk, hca, hcb, hnx, hny = H
    while i > 0:
        p = (i - 1) >> 1
        if ht[p] < t or (ht[p] == t and hk[p] <= key):
            break
        ht[i], hk[i], hca[i], hcb[i], hnx[i], hny[i] = ht[p], hk[p], hca[p], hcb[p], hnx[p], hny[p]
        i = p
    ht[i], hk[i], hca[i], hcb[i], hnx[i], hny[i] = t, key, ca, cb, nx, ny


@njit(cache=True)
def _sift_down(H, n, i, t, key, ca, cb, nx, ny):
    ht, hk, hca, hcb, hnx, hny = H
    while True:
        c = 2 * i + 1
        if c >= n:
            break
        if c + 1 < n and (ht[c + 1] < ht[c] or (ht[c + 1] == ht[c] and hk[c + 1] < hk[c])):
            c += 1
        if t < ht[c] or (t == ht[c] and key <= hk[c]):
            break
        ht[i], hk[i], hca[i], hcb[i], hnx[i], hny[i] = ht[c], hk[c], hca[c], hcb[c], hnx[c], hny[c]
        i = c
    ht[i], hk[i], hca[i], hcb[i], hnx[i], hny[i] = t, key, ca, cb, nx, ny


@njit(cache=True)
def _make_room(H, st, cnt):
    """Drop stale entries and rebuild the heap; double its arrays if still more than half full."""
    ht, hk, hca, hcb, hnx, hny = H
    n = st[_HEAP_N]
    keep = 0
    for i in range(n):
        if _valid(hk[i], hca[i], hcb[i], cnt):
            ht[keep], hk[keep], hca[keep], hcb[keep] = ht[i], hk[i], hca[i], hcb[i]
            hnx[keep], hny[keep] = hnx[i], hny[i]
            keep += 1
    cap = ht.shape[0]
    if 2 * keep > cap:
        cap *= 2
        H = (
            np.concatenate((ht[:keep], np.empty(cap - keep))),
            np.concatenate((hk[:keep], np.empty(cap - keep, np.int64))),
            np.concatenate((hca[:keep], np.empty(cap - keep, np.int64))),
            np.concatenate((hcb[:keep], np.empty(cap - keep, np.int64))),
            np.concatenate((hnx[:keep], np.empty(cap - keep))),
            np.concatenate((hny[:keep], np.empty(cap - keep))),
        )
    ht, hk, hca, hcb, hnx, hny = H
    for i in range(keep // 2 - 1, -1, -1):
        _sift_down(H, keep, i, ht[i], hk[i], hca[i], hcb[i], hnx[i], hny[i])
    st[_HEAP_N] = keep
    return H


@njit(cache=True)
def _push(H, st, cnt, t, key, ca, cb, nx, ny):
    """Add an entry; returns the heap arrays to use from now on (new ones if it had to grow)."""
    if st[_HEAP_N] == H[0].shape[0]:
        H = _make_room(H, st, cnt)
    n = st[_HEAP_N]
    st[_HEAP_N] = n + 1
    _sift_up(H, n, t, key, ca, cb, nx, ny)
    return H


@njit(cache=True)
def _pop(H, st):
    """Remove and return the earliest entry (t, key, ca, cb, nx, ny)."""
    ht, hk, hca, hcb, hnx, hny = H
    top = (ht[0], hk[0], hca[0], hcb[0], hnx[0], hny[0])
    n = st[_HEAP_N] - 1
    st[_HEAP_N] = n
    if n > 0:
        _sift_down(H, n, 0, ht[n], hk[n], hca[n], hcb[n], hnx[n], hny[n])
    return top


# --- grid cells: doubly linked lists of the moving objects in each cell -----------------------


@njit(cache=True)
def _cell_insert(G, i, c):
    cell, head, nxt, prv = G[0], G[1], G[2], G[3]
    cell[i] = c
    prv[i] = -1
    nxt[i] = head[c]
    if head[c] >= 0:
        prv[head[c]] = i
    head[c] = i


@njit(cache=True)
def _cell_remove(G, i):
    cell, head, nxt, prv = G[0], G[1], G[2], G[3]
    c = cell[i]
    if prv[i] >= 0:
        nxt[prv[i]] = nxt[i]
    else:
        head[c] = nxt[i]
    if nxt[i] >= 0:
        prv[nxt[i]] = prv[i]


@njit(cache=True)
def _build_grid(pos, size, static, cell, gnx, gny):
    """Grid arrays G = (cell, head, next, prev, static_start, static_items, stamp)."""
    n = pos.shape[0]
    head = np.full(gnx * gny, -1, np.int64)
    s_start, s_items = static_cells(pos, size, static, cell, gnx, gny)
    G = (
        np.full(n, -1, np.int64),
        head,
        np.full(n, -1, np.int64),
        np.full(n, -1, np.int64),
        s_start,
        s_items,
        np.zeros(n, np.int64),
    )
    for i in range(n - 1, -1, -1):  # lists then run in id order
        if not static[i]:
            cx = min(max(int((pos[i, 0] + 0.5 * size[i, 0]) // cell), 0), gnx - 1)
            cy = min(max(int((pos[i, 1] + 0.5 * size[i, 1]) // cell), 0), gny - 1)
            _cell_insert(G, i, cy * gnx + cx)
    return G


# --- predictions -------------------------------------------------------------------------------


@njit(cache=True)
def _wall_time(i, B, world):
    """(t, side) of i's next wall contact (its box touching a wall line), (inf, -1) if none."""
    pos, vel, tloc, size = B[0], B[1], B[2], B[3]
    width, height = world[0], world[1]
    t_best = INF
    side = -1
    if vel[i, 0] > 0.0:
        t_best = tloc[i] + (width - size[i, 0] - pos[i, 0]) / vel[i, 0]
        side = SIDE_RIGHT
    elif vel[i, 0] < 0.0:
        t_best = tloc[i] + pos[i, 0] / -vel[i, 0]
        side = SIDE_LEFT
    if vel[i, 1] > 0.0:
        t = tloc[i] + (height - size[i, 1] - pos[i, 1]) / vel[i, 1]
        if t < t_best:
            t_best, side = t, SIDE_BOTTOM
    elif vel[i, 1] < 0.0:
        t = tloc[i] + pos[i, 1] / -vel[i, 1]
        if t < t_best:
            t_best, side = t, SIDE_TOP
    return t_best, side


@njit(cache=True)
def _cross_time(i, B, G, world):
    """(t, direction) when i's box centre next leaves its grid cell, (inf, -1) if never."""
    pos, vel, tloc, size = B[0], B[1], B[2], B[3]
    cell, gnx, gny = world[3], world[4], world[5]
    c = G[0][i]
    gx = c % gnx
    gy = c // gnx
    t_best = INF
    d = -1
    if vel[i, 0] > 0.0 and gx < gnx - 1:
        t_best = tloc[i] + ((gx + 1) * cell - pos[i, 0] - 0.5 * size[i, 0]) / vel[i, 0]
        d = DIR_RIGHT
    elif vel[i, 0] < 0.0 and gx > 0:
        t_best = tloc[i] + (gx * cell - pos[i, 0] - 0.5 * size[i, 0]) / vel[i, 0]
        d = DIR_LEFT
    if vel[i, 1] > 0.0 and gy < gny - 1:
        t = tloc[i] + ((gy + 1) * cell - pos[i, 1] - 0.5 * size[i, 1]) / vel[i, 1]
        if t < t_best:
            t_best, d = t, DIR_DOWN
    elif vel[i, 1] < 0.0 and gy > 0:
        t = tloc[i] + (gy * cell - pos[i, 1] - 0.5 * size[i, 1]) / vel[i, 1]
        if t < t_best:
            t_best, d = t, DIR_UP
    return t_best, d


@njit(cache=True)
def _predict_pair(i, j, t_now, B, C, H, st):
    """Push the next contact of i and j, if any."""
    pos, vel, tloc, size, cnt = B[0], B[1], B[2], B[3], B[6]
    a = min(i, j)
    b = max(i, j)
    da = t_now - tloc[a]
    db = t_now - tloc[b]
    qx = (pos[b, 0] + vel[b, 0] * db) - (pos[a, 0] + vel[a, 0] * da)
    qy = (pos[b, 1] + vel[b, 1] * db) - (pos[a, 1] + vel[a, 1] * da)
    ux = vel[b, 0] - vel[a, 0]
    uy = vel[b, 1] - vel[a, 1]
    t, code, nx, ny = next_contact(a, b, qx, qy, ux, uy, C[0], size, C[1], C[2], C[3], C[4])
    if t < INF:
        H = _push(H, st, cnt, t_now + t, _key(RANK_PAIR, a, b, code), cnt[a], cnt[b], nx, ny)
    return H


@njit(cache=True)
def _predict_cells(i, skip, lower_only, x0, x1, y0, y1, t_now, B, C, G, H, st, world):
    """Predict i against the objects filed in cells [x0, x1] × [y0, y1] (clipped to the grid),
    except `skip`; with lower_only, only against static objects and moving ones with a higher id."""
    head, nxt, s_start, s_items, stamp = G[1], G[2], G[4], G[5], G[6]
    gnx, gny = world[4], world[5]
    st[_STAMP] += 1
    for cy in range(max(y0, 0), min(y1, gny - 1) + 1):
        for cx in range(max(x0, 0), min(x1, gnx - 1) + 1):
            c = cy * gnx + cx
            j = head[c]
            while j >= 0:
                if j != i and j != skip and not (lower_only and j < i):
                    H = _predict_pair(i, j, t_now, B, C, H, st)
                j = nxt[j]
            for m in range(s_start[c], s_start[c + 1]):
                j = s_items[m]
                if stamp[j] != st[_STAMP] and j != skip:
                    stamp[j] = st[_STAMP]
                    H = _predict_pair(i, j, t_now, B, C, H, st)
    return H


@njit(cache=True)
def _predict(i, skip, lower_only, t_now, B, C, G, H, st, world):
    """Push every next event of moving object i: its wall, its cell crossing, its contacts with
    the objects in the 3×3 cells around it (but not `skip`, the partner it has just left)."""
    cnt = B[6]
    t, side = _wall_time(i, B, world)
    if t < INF:
        H = _push(H, st, cnt, max(t, t_now), _key(RANK_WALL, i, side, side), cnt[i], 0, 0.0, 0.0)
    t, d = _cross_time(i, B, G, world)
    if t < INF:
        H = _push(H, st, cnt, max(t, t_now), _key(RANK_CROSS, i, d, d), cnt[i], 0, 0.0, 0.0)
    c = G[0][i]
    gx = c % world[4]
    gy = c // world[4]
    return _predict_cells(
        i, skip, lower_only, gx - 1, gx + 1, gy - 1, gy + 1, t_now, B, C, G, H, st, world
    )


# --- events ------------------------------------------------------------------------------------


@njit(cache=True)
def _move_to(i, t, B):
    """Bring object i's position to time t."""
    pos, vel, tloc = B[0], B[1], B[2]
    dt = t - tloc[i]
    pos[i, 0] += vel[i, 0] * dt
    pos[i, 1] += vel[i, 1] * dt
    tloc[i] = t


@njit(cache=True)
def _on_cross(i, d, t, B, C, G, H, st, world):
    """i's centre enters the next cell: refile it, predict its next crossing and its contacts with
    the row or column of cells that comes into reach."""
    cnt = B[6]
    gnx = world[4]
    c = G[0][i]
    gx = c % gnx + (1 if d == DIR_RIGHT else -1 if d == DIR_LEFT else 0)
    gy = c // gnx + (1 if d == DIR_DOWN else -1 if d == DIR_UP else 0)
    _cell_remove(G, i)
    _cell_insert(G, i, gy * gnx + gx)
    tc, dc = _cross_time(i, B, G, world)
    if tc < INF:
        H = _push(H, st, cnt, max(tc, t), _key(RANK_CROSS, i, dc, dc), cnt[i], 0, 0.0, 0.0)
    if d == DIR_RIGHT or d == DIR_LEFT:
        x = gx + (1 if d == DIR_RIGHT else -1)
        return _predict_cells(i, -1, False, x, x, gy - 1, gy + 1, t, B, C, G, H, st, world)
    y = gy + (1 if d == DIR_DOWN else -1)
    return _predict_cells(i, -1, False, gx - 1, gx + 1, y, y, t, B, C, G, H, st, world)


@njit(cache=True)
def _on_wall(i, side, t, B, C, G, H, st, world):
    """i's box touches a wall: reflect that velocity component, set it exactly on the wall line."""
    pos, vel, size, cnt = B[0], B[1], B[3], B[6]
    _move_to(i, t, B)
    if side == SIDE_LEFT or side == SIDE_RIGHT:
        vel[i, 0] = -vel[i, 0]
        pos[i, 0] = 0.0 if side == SIDE_LEFT else world[0] - size[i, 0]
    else:
        vel[i, 1] = -vel[i, 1]
        pos[i, 1] = 0.0 if side == SIDE_TOP else world[1] - size[i, 1]
    cnt[i] += 1
    return _predict(i, -1, False, t, B, C, G, H, st, world)


@njit(cache=True)
def _on_pair(a, b, code, nx, ny, t, B, C, G, H, st, world):
    """a and b touch: the elastic exchange, then each predicted again (not against the other).
    Returns (H, whether the velocities changed)."""
    inv_mass, static, cnt = B[4], B[5], B[6]
    _move_to(a, t, B)
    _move_to(b, t, B)
    if not exchange(B[1], a, b, inv_mass[a], inv_mass[b], code, nx, ny):
        return H, False
    if not static[a]:
        cnt[a] += 1
    if not static[b]:
        cnt[b] += 1
    if not static[a]:
        H = _predict(a, b, False, t, B, C, G, H, st, world)
    if not static[b]:
        H = _predict(b, a, False, t, B, C, G, H, st, world)
    return H, True


@njit(cache=True)
def _sync(t, B, world):
    """Move every object to time t (a tick's end), kept inside the world against rounding."""
    pos, vel, tloc, size, static = B[0], B[1], B[2], B[3], B[5]
    for i in range(pos.shape[0]):
        if static[i]:
            continue
        dt = t - tloc[i]
        pos[i, 0] = min(max(pos[i, 0] + vel[i, 0] * dt, 0.0), world[0] - size[i, 0])
        pos[i, 1] = min(max(pos[i, 1] + vel[i, 1] * dt, 0.0), world[1] - size[i, 1])
        tloc[i] = t


# --- the kernels ---------------------------------------------------------------------------------


@njit(cache=True)
def _predict_all(B, C, G, H, st, world):
    """Initial predictions at time 0: every moving object, each pair once."""
    static = B[5]
    for i in range(static.shape[0]):
        if not static[i]:
            H = _predict(i, -1, True, 0.0, B, C, G, H, st, world)
    return H


@njit(cache=True)
def _run(tick_to, log, cap, B, C, G, H, st, stf, world, rows, times):
    """Run ticks until tick_to: pop events in order, handle each, sync at each tick's end.

    Returns (status, H, rows, times, events logged); STATUS_CAP stops mid-tick.
    """
    cnt = B[6]
    fps = world[2]
    n_ev = 0
    while st[_TICK] < tick_to:
        tick = st[_TICK] + 1
        t_end = tick / fps
        while st[_HEAP_N] > 0 and H[0][0] <= t_end:
            t, key, ca, cb, nx, ny = _pop(H, st)
            if not _valid(key, ca, cb, cnt):
                continue
            stf[_T_NOW] = t
            rank, a, b, code = _unkey(key)
            if rank == RANK_CROSS:
                H = _on_cross(a, b, t, B, C, G, H, st, world)
                continue
            st[_TICK_EVENTS] += 1
            if st[_TICK_EVENTS] > cap:
                return STATUS_CAP, H, rows, times, n_ev
            if rank == RANK_WALL:
                H = _on_wall(a, b, t, B, C, G, H, st, world)
                kind, b, happened = EV_WALL, -1, True
            else:
                H, happened = _on_pair(a, b, code, nx, ny, t, B, C, G, H, st, world)
                kind = EV_PAIR
            if log and happened:
                rows, times = log_event(rows, times, n_ev, tick, t, kind, a, b, code)
                n_ev += 1
        _sync(t_end, B, world)
        stf[_T_NOW] = t_end
        st[_TICK] = tick
        st[_TICK_EVENTS] = 0
    return STATUS_DONE, H, rows, times, n_ev


class Model:
    """Event-driven elastic model; see the module docstring. Surface as in engine.models."""

    def __init__(
        self,
        world: WorldSpec,
        bodies: Bodies,
        substeps: int = 1,
        geometry: str = "exact",
        max_events_per_tick: int = MAX_EVENTS_PER_TICK,
        cell_size: float | None = None,
    ):
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be a whole number >= 1, got {substeps!r}")
        if geometry not in GEOMETRIES:
            raise ValueError(f"unknown geometry {geometry!r}; expected one of {GEOMETRIES}")
        if int(max_events_per_tick) != max_events_per_tick or max_events_per_tick < 1:
            raise ValueError(f"max_events_per_tick must be >= 1, got {max_events_per_tick!r}")
        if bodies.n >= MAX_OBJECTS:
            raise ValueError(f"the exact model handles fewer than {MAX_OBJECTS} objects")
        self.world = world
        self.geometry = geometry
        self.max_events_per_tick = int(max_events_per_tick)
        self.tick = 0
        self._broken = None
        static = np.ascontiguousarray(bodies.static, bool).copy()
        pos = np.ascontiguousarray(bodies.pos, np.float64).copy()
        vel = np.ascontiguousarray(bodies.vel, np.float64).copy()
        vel[static] = 0.0
        size = np.ascontiguousarray(bodies.size, np.float64).copy()
        inv_mass = np.ascontiguousarray(bodies.inv_mass, np.float64)
        n = bodies.n
        self._B = (pos, vel, np.zeros(n), size, inv_mass, static, np.zeros(n, np.int64))
        cores = build_cores(bodies, geometry)
        self._C = (cores.shape, cores.radius, cores.start, cores.verts, cores.normals)
        self.cell_size = (
            float(cell_size) if cell_size else grid_cell(world.width, world.height, size, static)
        )
        gnx, gny = grid_dims(world.width, world.height, self.cell_size)
        self._world = (
            float(world.width),
            float(world.height),
            float(world.fps),
            self.cell_size,
            gnx,
            gny,
        )
        self._G = _build_grid(pos, size, static, self.cell_size, gnx, gny)
        cap = max(64, HEAP_PER_OBJECT * n)
        H = (
            np.empty(cap),
            np.empty(cap, np.int64),
            np.empty(cap, np.int64),
            np.empty(cap, np.int64),
            np.empty(cap),
            np.empty(cap),
        )
        self._st = np.zeros(4, np.int64)
        self._stf = np.zeros(1)
        self._H = _predict_all(self._B, self._C, self._G, H, self._st, self._world)

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events in the order they happened (empty when log is False)."""
        if self._broken:
            raise EventCapExceeded(self._broken)
        rows, times = new_log(log)
        status, self._H, rows, times, n = _run(
            self.tick + int(ticks),
            bool(log),
            self.max_events_per_tick,
            self._B,
            self._C,
            self._G,
            self._H,
            self._st,
            self._stf,
            self._world,
            rows,
            times,
        )
        if status == STATUS_CAP:
            tick = int(self._st[_TICK]) + 1
            self._broken = (
                f"tick {tick} needed more than {self.max_events_per_tick} events "
                f"(max_events_per_tick); stopped at t = {self._stf[_T_NOW]!r} s as a runaway"
            )
            raise EventCapExceeded(self._broken)
        self.tick = int(self._st[_TICK])
        return event_records(rows, times, n)

    def positions(self) -> np.ndarray:
        """(n, 2) float64 top-left corners at the last tick's end, px."""
        return self._B[0].copy()

    def velocities(self) -> np.ndarray:
        """(n, 2) float64 velocities, px/s."""
        return self._B[1].copy()
