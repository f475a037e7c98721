"""The `stepped` model (SPEC 3.2): fixed-step elastic collisions with float state.

Input: the world, the `Bodies` (copied: the model owns its state) and the options `substeps`
(each tick split into that many equal steps of 1/(fps·substeps) s) and `geometry` ("box", the
default, also for None: every object collides as its box; "exact": by its real shape, shapes.py).
Output, per `advance`: the events of the ticks run, walls and responding pairs, `t` = the tick's
end.

Each step runs move -> walls -> pairs. Walls reflect exactly as a wall would (response.fold).
Pairs: the candidates are the pairs whose boxes overlap after the walls, or overlapped during the
step (a corner passed through within it, found by sweeping the pair back along its relative
velocity), taken in the order their contacts began (swept back the same way; ties and pairs whose
overlap began before the step, first, in ascending (a, b) order), each tested again on the
current state so that it sees what the pairs before it changed (a pair that only comes to
overlap through such a push waits for the next step). A pair in contact that approaches along
the contact normal gets the elastic exchange. The normal is the axis along which the pair
started overlapping, found from its relative velocity (contact.box_step_contact; for exact shapes
the direction of approach, contact.step_contact), and the pair is pushed apart along it, shared
by inverse mass, never out of the world, by twice the depth it went in since that instant: each
object ends where a bounce at the contact instant would have put it, as the walls reflect. Only
when the motion cannot tell (the overlap began before the previous step, or nothing moves) the
axis of the smaller overlap decides, and the push is that depth once.

Finding the overlapping pairs without testing them all (a Verlet list): the broad phase
(broadphase.py, sort-and-sweep or a grid chosen by the scene) lists the pairs whose boxes, each
grown by a margin of MARGIN_STEPS of the fastest step, overlap, and the list is kept until some
object has drifted that margin from where it was when the list was made. While no object has, any
pair overlapping now was on the list (each box moved less than the margin), so each step only
tests the listed pairs on the current boxes (and their sweeps over the step: each box's path lies
within its margin too), sorts the few in contact, and takes them in that order: exactly the
pairs, in exactly the order, of testing every pair. Pairs of two static
objects are never listed, and with no movable object (or fewer than two objects) the pair stage is
skipped; the `skip=False` option turns both skips off, and `broadphase` ("sweep", "grid",
"cells") forces a method instead of the scene's choice (for tests and `collide2d bench`).

Events go to the one event log of events.py. The step's stages are one kernel, `_step` (STAGES:
move, broad, narrow, response): `_run` runs all of them every step, `Model.profile` the same
kernel one stage at a time to time each.
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from collide2d.engine.broadphase import (
    KEY_MASK,
    KEY_SHIFT,
    METHOD_CELLS,
    METHOD_GRID,
    METHOD_SWEEP,
    cell_candidates_split,
    choose,
    find,
    marker,
    workspace,
)
from collide2d.engine.contact import (
    box_clip,
    box_reach,
    box_step_contact,
    box_sweep,
    step_contact,
)
from collide2d.engine.events import (
    EV_PAIR,
    EV_WALL,
    SIDE_BOTTOM,
    SIDE_LEFT,
    SIDE_RIGHT,
    SIDE_TOP,
    event_records,
    log_event,
    new_log,
)
from collide2d.engine.jit import njit, overload, prange
from collide2d.engine.response import exchange, fold, separate
from collide2d.engine.shapes import GEOMETRIES, build_cores
from collide2d.engine.sort import heap_argsort, sort_by_time
from collide2d.engine.threads import chunks_for, join_shares, shares_total
from collide2d.engine.world import Bodies, WorldSpec

# The candidate list's margin, px: this many of the fastest object's step (|v|·dt), within
# [MARGIN_MIN_PX, MARGIN_MAX_SIDES x the median box side]. A wider margin remakes the list less
# often but lists more pairs; tuned on the standard scene of `collide2d bench`.
MARGIN_STEPS = 5.0
MARGIN_MIN_PX = 0.5
MARGIN_MAX_SIDES = 1.5
# The list is remade once an object has drifted within this much (px, and this share of the
# world's side) of the margin: room for the rounding of the drift and of the grown boxes.
DRIFT_SLACK_PX = 1e-6
DRIFT_SLACK_REL = 1e-12
# The wall and pair event counters and this step's overlapping pairs in the broad phase's `state`
# array, this step's drift in its `params` (see `_run`).
ST_WALLS, ST_PAIRS, ST_NEAR = 3, 4, 5
# How many chunks (threads) the move and narrow stages split into (1: none), in `state`.
ST_CHUNKS = 6
P_DRIFT = 3
# Candidate slots to start with per object (the buffers double when full).
CANDIDATES_PER_OBJECT = 4
# The objects inside are put back in the broad phase's order once they have strayed from it by
# more than this many rows of the grid on average (a row holds about sqrt(n) objects in a
# squarish world; see the kernels' section).
REORDER_ROWS = 2.0


# --- the stages of one step ---------------------------------------------------------------------
#
# Inside the kernels objects are kept in the broad phase's order (index i inside is object ext[i];
# rank[e] is where object e is): objects near in space are then near in memory, which keeps a large
# scene's pair tests in the cache. Everything that reaches the outside, events and their order,
# pair order and positions, goes by object id, so the order inside never shows.


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
def _move_range(pos, vel, static, span, ext, anchor, first, last, dt, folds, n_folds):
    """Move objects first ... last-1 (inside) for dt seconds and reflect each back into the
    world; their fold rows go to folds from row n_folds. Returns (rows now, the farthest any of
    them is from its anchor on an axis, px)."""
    drift = 0.0
    for i in range(first, last):
        if static[i]:
            continue
        x = pos[i, 0] + vel[i, 0] * dt
        y = pos[i, 1] + vel[i, 1] * dt
        sx = span[i, 0]
        if not (sx > 0.0 and 0.0 <= x and x <= sx):  # inside, fold would change nothing
            x, vx, low, high, first_low = fold(x, vel[i, 0], sx)
            vel[i, 0] = vx
            n_folds = _fold_row(folds, n_folds, ext[i], 0, low, high, first_low)
        sy = span[i, 1]
        if not (sy > 0.0 and 0.0 <= y and y <= sy):
            y, vy, low, high, first_low = fold(y, vel[i, 1], sy)
            vel[i, 1] = vy
            n_folds = _fold_row(folds, n_folds, ext[i], 1, low, high, first_low)
        pos[i, 0] = x
        pos[i, 1] = y
        drift = max(drift, abs(x - anchor[i, 0]), abs(y - anchor[i, 1]))
    return n_folds, drift


@njit(cache=True)
def _move_walls(S, dt, folds):
    """Move every object for dt seconds, then reflect it back into the world.

    S: the state arrays (a `State`). folds (2n, 4) int64 receives a row per object and axis that
    folded. Returns (how many rows, the farthest any object now is from its anchor on an axis, px).
    """
    pos, vel, size, inv_mass, static, movable, span, ext, rank, anchor = S
    return _move_range(pos, vel, static, span, ext, anchor, 0, pos.shape[0], dt, folds, 0)


@njit(cache=True)
def _move_walls_split(S, dt, folds, chunks):
    """`_move_walls` with the objects cut into `chunks` contiguous runs, one per thread (see
    `_move_chunks`): the same rows, drift and state, to the bit."""
    pos, vel, size, inv_mass, static, movable, span, ext, rank, anchor = S
    return _move_chunks(pos, vel, static, span, ext, anchor, dt, folds, chunks)


@njit(cache=True, parallel=True)
def _move_chunks(pos, vel, static, span, ext, anchor, dt, folds, chunks):
    """Run c of `chunks` writes its fold rows from row 2 x its first object (each object folds
    on two axes at most); then the runs' rows are moved together in run order."""
    n = pos.shape[0]
    rows = np.zeros(chunks, np.int64)
    drifts = np.zeros(chunks)
    for c in prange(chunks):
        first = c * n // chunks
        k, d = _move_range(
            pos, vel, static, span, ext, anchor, first, (c + 1) * n // chunks, dt, folds, 2 * first
        )
        rows[c] = k - 2 * first
        drifts[c] = d
    n_folds = 0
    drift = 0.0
    for c in range(chunks):
        first = 2 * (c * n // chunks)
        for r in range(rows[c]):
            for col in range(4):
                folds[n_folds + r, col] = folds[first + r, col]
        n_folds += rows[c]
        drift = max(drift, drifts[c])
    return n_folds, drift


@njit(cache=True)
def _log_walls(folds, n_folds, tick, t, rows, times, n_ev):
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


@njit(cache=True)
def _gather(a, order, tmp):
    """a[:] = a[order] along the first axis, through the scratch tmp (a's shape)."""
    for s in range(order.shape[0]):
        tmp[s] = a[order[s]]
    a[:] = tmp


@njit(cache=True)
def _reorder(S, order):
    """Put the objects inside in `order` (a permutation of the indices inside), then order is
    the identity."""
    pos, vel, size, inv_mass, static, movable, span, ext, rank, anchor = S
    t2 = np.empty_like(pos)
    for a in (pos, vel, size, span, anchor):
        _gather(a, order, t2)
    _gather(inv_mass, order, np.empty_like(inv_mass))
    for a in (static, movable):
        _gather(a, order, np.empty_like(static))
    _gather(ext, order, np.empty_like(ext))
    for i in range(ext.shape[0]):
        rank[ext[i]] = i
        order[i] = i


@njit(cache=True)
def _relist(S, dt, margin, method, cell, bp):
    """Make the candidate list anew from the boxes grown by `margin` px, each over the step of dt
    s just taken (so that a pair that cut a corner within it is listed), and anchor every object
    where it is; first put the objects inside in the broad phase's order when they have strayed
    from it (on average more than REORDER_ROWS rows of the grid). Returns (the key buffer, possibly
    grown; how many keys)."""
    pos, vel, size, inv_mass, static, movable, span, ext, rank, anchor = S
    keys, near, order, lo, hi, folds, state, params, ws, when, finder = bp
    n = pos.shape[0]
    for _ in range(2):
        for i in range(n):
            # the box over the step just taken (swept back on a straight line), grown by margin
            bx = pos[i, 0] - vel[i, 0] * dt
            by = pos[i, 1] - vel[i, 1] * dt
            lo[i, 0] = min(pos[i, 0], bx) - margin
            lo[i, 1] = min(pos[i, 1], by) - margin
            hi[i, 0] = max(pos[i, 0], bx) + size[i, 0] + margin
            hi[i, 1] = max(pos[i, 1], by) + size[i, 1] + margin
            anchor[i, 0] = pos[i, 0]
            anchor[i, 1] = pos[i, 1]
        k = _candidates(finder, lo, hi, movable, cell, order, keys, ws, state[ST_CHUNKS])
        if method == METHOD_GRID:
            break
        stray = 0
        for s in range(n):
            stray += abs(order[s] - s)
        if stray <= REORDER_ROWS * math.sqrt(n) * n:
            break
        _reorder(S, order)
    while k > keys.shape[0]:
        keys = np.empty(2 * k, np.int64)
        k = _candidates(finder, lo, hi, movable, cell, order, keys, ws, state[ST_CHUNKS])
    return keys, k


@njit(cache=True, inline="always")
def _swept_back(pos, vel, span, i, dt):
    """Whether object i, moved back dt seconds on a straight line, is where it started the step:
    inside the world (an object that folded at a wall this step is not, SPEC 3.2)."""
    x = pos[i, 0] - vel[i, 0] * dt
    y = pos[i, 1] - vel[i, 1] * dt
    return 0.0 <= x <= max(span[i, 0], 0.0) and 0.0 <= y <= max(span[i, 1], 0.0)


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


@njit(cache=True)
def _contact_range(pos, vel, size, span, ext, keys, first, last, near, when, base, room, dt):
    """The listed pairs keys[first:last] in contact during the step of dt s just taken: their
    boxes overlap now with positive area, or overlapped during the step (swept back on straight
    lines, both objects clear of the walls this step: a corner passed through within the step).
    Written to near[base:base + room] as keys of object ids ascending, with the time each contact
    began in `when` (s from the step's start, swept back along the relative velocity; -inf when
    the motion cannot tell), while they fit; returns how many."""
    k = 0
    for c in range(first, last):
        a = keys[c] >> KEY_SHIFT
        b = keys[c] & KEY_MASK
        qx = pos[b, 0] - pos[a, 0]
        qy = pos[b, 1] - pos[a, 1]
        wa, ha, wb, hb = size[a, 0], size[a, 1], size[b, 0], size[b, 1]
        now = -wb < qx < wa and -hb < qy < ha
        ux = vel[b, 0] - vel[a, 0]
        uy = vel[b, 1] - vel[a, 1]
        if not (now or box_reach(qx - ux * dt, qy - uy * dt, ux, uy, wa, ha, wb, hb, dt)):
            continue
        t_enter, _, _, _, _ = box_sweep(qx - ux * dt, qy - uy * dt, ux, uy, wa, ha, wb, hb)
        if not now and not (
            box_clip(qx, qy, ux, uy, wa, ha, wb, hb, dt)
            and _swept_back(pos, vel, span, a, dt)
            and _swept_back(pos, vel, span, b, dt)
        ):
            continue
        if k < room:
            ea = ext[a]
            eb = ext[b]
            near[base + k] = (min(ea, eb) << KEY_SHIFT) | max(ea, eb)
            when[base + k] = t_enter if -dt <= t_enter < dt else -math.inf
        k += 1
    return k


@njit(cache=True)
def _overlapping(pos, vel, size, span, ext, keys, n_keys, near, when, dt):
    """The listed pairs in contact during the step (`_contact_range` over the whole list), in the
    order their contacts began: sorted by the time in `when`, then by key, when they fit; returns
    how many (the caller grows `near` and `when` and asks again)."""
    room = near.shape[0]
    k = _contact_range(pos, vel, size, span, ext, keys, 0, n_keys, near, when, 0, room, dt)
    if k <= room:
        sort_by_time(when, near, k)
    return k


@njit(cache=True, parallel=True)
def _overlapping_split(pos, vel, size, span, ext, keys, n_keys, near, when, dt, chunks):
    """`_overlapping` with the listed pairs cut into `chunks` contiguous runs, one per thread: run
    c writes its pairs into its own share of `near` and `when`, then the shares are moved
    together in run order and sorted by (time, key), a total order, so the result is the same as
    `_overlapping`'s. When a share is too small the count returned is more than `near` holds, and
    the caller grows it and asks again."""
    room = near.shape[0]
    share = room // chunks
    found = np.zeros(chunks, np.int64)
    for c in prange(chunks):
        found[c] = _contact_range(
            pos, vel, size, span, ext, keys, c * n_keys // chunks, (c + 1) * n_keys // chunks,
            near, when, c * share, share, dt
        )
    total = shares_total(found, share, room)
    if total > room:
        return total
    k = join_shares(found, share, near)
    join_shares(found, share, when)
    sort_by_time(when, near, k)
    return k


@njit(cache=True)
def _contact(a, b, ea, eb, pos, vel, size, dt, exact, shape, radius, start, verts, normals):
    """(push, push_y, code, nx, ny) of a pair after a step of dt s (a, b inside; ea, eb their
    ids): the normal from the direction of approach, contact.box_step_contact / step_contact;
    push <= 0 when they do not overlap."""
    qx = pos[b, 0] - pos[a, 0]
    qy = pos[b, 1] - pos[a, 1]
    ux = vel[b, 0] - vel[a, 0]
    uy = vel[b, 1] - vel[a, 1]
    if not exact:
        return box_step_contact(qx, qy, ux, uy, size[a, 0], size[a, 1], size[b, 0], size[b, 1], dt)
    return step_contact(
        qx,
        qy,
        ux,
        uy,
        dt,
        shape[ea],
        size[a, 0],
        size[a, 1],
        radius[ea],
        verts[start[ea] : start[ea + 1]],
        normals[start[ea] : start[ea + 1]],
        shape[eb],
        size[b, 0],
        size[b, 1],
        radius[eb],
        verts[start[eb] : start[eb + 1]],
        normals[start[eb] : start[eb + 1]],
    )


@njit(cache=True)
def _pairs(
    S, dt, width, height, exact, cores, near, n_near, tick, t, log, rows, times, n_ev, state
):
    """Respond to every overlapping, approaching pair of `near` (ascending keys of ids) in order,
    after a step of dt s; count each in state[ST_PAIRS], log it when `log`."""
    pos, vel, size, inv_mass, static, movable, span, ext, rank, anchor = S
    shape, radius, start, verts, normals = cores
    for m in range(n_near):
        ea = near[m] >> KEY_SHIFT
        eb = near[m] & KEY_MASK
        a = rank[ea]
        b = rank[eb]
        depth, depth_y, code, nx, ny = _contact(
            a, b, ea, eb, pos, vel, size, dt, exact, shape, radius, start, verts, normals
        )
        if depth <= 0.0:
            continue
        vax, vay, vbx, vby, changed = exchange(
            vel[a, 0], vel[a, 1], vel[b, 0], vel[b, 1], inv_mass[a], inv_mass[b], code, nx, ny
        )
        if not changed:
            continue
        vel[a, 0], vel[a, 1], vel[b, 0], vel[b, 1] = vax, vay, vbx, vby
        separate(
            pos, size, a, b, inv_mass[a], inv_mass[b], code, nx, ny, depth, depth_y, width, height
        )
        state[ST_PAIRS] += 1
        if log:
            rows, times = log_event(rows, times, n_ev, tick, t, EV_PAIR, ea, eb, code)
            n_ev += 1
    return rows, times, n_ev


@njit(cache=True)
def _narrow(S, keys, n_keys, near, when, dt, chunks):
    """The narrow phase: `_overlapping`, split among `chunks` threads when more than one."""
    if chunks > 1:
        return _overlapping_split(
            S.pos, S.vel, S.size, S.span, S.ext, keys, n_keys, near, when, dt, chunks
        )
    return _overlapping(S.pos, S.vel, S.size, S.span, S.ext, keys, n_keys, near, when, dt)


# The stages of one step, in the order `_step` runs them; `Model.profile` times each by name
# through the same kernel.
STAGES = ("move", "broad", "narrow", "response")
_MOVE, _BROAD, _NARROW, _RESPONSE = range(len(STAGES))


@njit(cache=True)
def _step(first, last, S, dt, width, height, exact, cores, tick, t, log, rows, times, n_ev, bp):
    """Run the stages first ... last-1 (of STAGES) of one step; returns (event buffers, how many
    events, bp): the buffers that grew replace the caller's. What a stage hands the next waits
    in bp between calls: the drift in params[P_DRIFT], the overlapping pairs in state[ST_NEAR]."""
    keys, near, order, lo, hi, folds, state, params, ws, when, finder = bp
    if first <= _MOVE < last:
        # move, walls: every object; the walls' events in id order; how far anything drifted
        # from where the candidate list was made
        if state[ST_CHUNKS] > 1:
            n_folds, params[P_DRIFT] = _move_walls_split(S, dt, folds, state[ST_CHUNKS])
        else:
            n_folds, params[P_DRIFT] = _move_walls(S, dt, folds)
        if n_folds:
            for r in range(n_folds):  # one wall event per fold
                state[ST_WALLS] += folds[r, 1] + folds[r, 2]
            if log:
                rows, times, n_ev = _log_walls(folds, n_folds, tick, t, rows, times, n_ev)
    if state[2] == 0:  # no pair can happen
        return rows, times, n_ev, bp
    if first <= _BROAD < last:
        # the candidate list made anew once an object drifted its margin
        if state[0] < 0 or params[P_DRIFT] >= params[0] - params[2]:
            keys, state[0] = _relist(S, dt, params[0], state[1], params[1], bp)
            bp = (keys, near, order, lo, hi, folds, state, params, ws, when, finder)
    if first <= _NARROW < last:
        # the listed pairs in contact this step, in the order their contacts began
        state[ST_NEAR] = _narrow(S, keys, state[0], near, when, dt, state[ST_CHUNKS])
        while state[ST_NEAR] > near.shape[0]:
            near = np.empty(2 * state[ST_NEAR], np.int64)
            when = np.empty(2 * state[ST_NEAR])
            bp = (keys, near, order, lo, hi, folds, state, params, ws, when, finder)
            state[ST_NEAR] = _narrow(S, keys, state[0], near, when, dt, state[ST_CHUNKS])
    if first <= _RESPONSE < last:
        rows, times, n_ev = _pairs(
            S,
            dt,
            width,
            height,
            exact,
            cores,
            near,
            state[ST_NEAR],
            tick,
            t,
            log,
            rows,
            times,
            n_ev,
            state,
        )
    return rows, times, n_ev, bp


@njit(cache=True)
def _run(world, substeps, tick0, ticks, log, S, exact, cores, rows, times, bp):
    """Run ticks tick0+1 ... tick0+ticks, every step all of `_step`; returns (event buffers, how
    many events, bp): the buffers that grew replace the caller's.

    S: the state arrays (a `State`). bp = (keys, near, order, lo, hi, folds, state, params, ws,
    when, finder): the candidate list kept between calls (see the module docstring) and scratch
    (`when`: the times the pairs of `near` began their contacts; `finder`: the marker of the
    method, broadphase.marker, so that a kernel compiles only that pair finder); state = [keys
    listed (-1: no list yet), method, whether pairs can happen at all, wall events and pair events
    so far, logged or not (ST_WALLS, ST_PAIRS), overlapping pairs of this step (ST_NEAR), chunks
    the move and narrow stages split into among threads (ST_CHUNKS, engine.threads)]; params
    = [margin px, grid cell px, drift slack px, this step's drift px (P_DRIFT)].
    """
    width, height, fps = world
    dt = 1.0 / (fps * substeps)
    n_ev = np.int64(0)  # not the literal 0, which would compile _step once more for it
    for tick in range(tick0 + 1, tick0 + ticks + 1):
        t = tick / fps
        for _ in range(substeps):
            rows, times, n_ev, bp = _step(
                0,
                len(STAGES),
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
            )
    return rows, times, n_ev, bp


class State(NamedTuple):
    """The stepped model's state arrays, every row in the broad phase's order (numba takes a
    named tuple as it takes a tuple; the kernels unpack it by position)."""

    pos: np.ndarray  # (n, 2) float64 top-left corners, px
    vel: np.ndarray  # (n, 2) float64 px/s
    size: np.ndarray  # (n, 2) float64 px
    inv_mass: np.ndarray  # (n,) float64, 0 for static objects
    static: np.ndarray  # (n,) bool
    movable: np.ndarray  # (n,) bool: what the broad phase pairs
    span: np.ndarray  # (n, 2) float64 world side - box side, px
    ext: np.ndarray  # (n,) int64 the id of each row
    rank: np.ndarray  # (n,) int64 the row of each id
    anchor: np.ndarray  # (n, 2) float64 where each was when the candidate list was made, px


class Model:
    """Fixed-step elastic model; see the module docstring. Surface as in engine.models.
    Its state is a `State`, in the broad phase's order."""

    def __init__(
        self,
        world: WorldSpec,
        bodies: Bodies,
        substeps: int = 1,
        geometry: str | None = None,
        skip: bool = True,
        broadphase: str | None = None,
    ):
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be a whole number >= 1, got {substeps!r}")
        geometry = "box" if geometry is None else geometry
        if geometry not in GEOMETRIES:
            raise ValueError(f"unknown geometry {geometry!r}; expected one of {GEOMETRIES}")
        self.world = world
        self.substeps = int(substeps)
        self.geometry = geometry
        self.tick = 0
        n = bodies.n
        static = np.ascontiguousarray(bodies.static, bool).copy()
        pos = np.ascontiguousarray(bodies.pos, np.float64).copy()
        vel = np.ascontiguousarray(bodies.vel, np.float64).copy()
        vel[static] = 0.0
        size = np.ascontiguousarray(bodies.size, np.float64).copy()
        span = np.array([world.width, world.height], np.float64) - size
        movable = ~static if skip else np.ones(n, bool)
        self._S = State(
            pos,
            vel,
            size,
            np.ascontiguousarray(bodies.inv_mass, np.float64),
            static,
            movable,
            np.ascontiguousarray(span),
            np.arange(n, dtype=np.int64),
            np.arange(n, dtype=np.int64),
            pos.copy(),
        )
        cores = build_cores(bodies, geometry)
        self._cores = (cores.shape, cores.radius, cores.start, cores.verts, cores.normals)
        self._bp = _broad_phase(world, pos, vel, size, movable, substeps, skip, broadphase)

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events in the order they happened (empty when log is False)."""
        world = (float(self.world.width), float(self.world.height), float(self.world.fps))
        rows, times = new_log(log)
        rows, times, n, self._bp = _run(
            world,
            self.substeps,
            self.tick,
            int(ticks),
            bool(log),
            self._S,
            self.geometry == "exact",
            self._cores,
            rows,
            times,
            self._bp,
        )
        self.tick += int(ticks)
        return event_records(rows, times, n)

    def event_counts(self) -> tuple[int, int]:
        """(wall events, pair events) so far, logged or not."""
        state = self._bp[6]
        return int(state[ST_WALLS]), int(state[ST_PAIRS])

    def profile(self, ticks: int) -> dict[str, float]:
        """Run `ticks` ticks with the event log off, one stage of `_step` at a time, and return
        the seconds spent in each (STAGES): "move" (motion and walls), "broad" (making the
        candidate list), "narrow" (testing the listed pairs), "response" (exchange and
        separation). The state ends exactly as `advance(ticks, log=False)` would leave it. Each
        stage is timed from Python, so each count includes a call's overhead (microseconds),
        which dominates in small scenes."""
        fps = float(self.world.fps)
        width, height = float(self.world.width), float(self.world.height)
        dt = 1.0 / (fps * self.substeps)
        exact = self.geometry == "exact"
        rows, times = new_log(False)
        spent = dict.fromkeys(STAGES, 0.0)
        clock = time.perf_counter
        for tick in range(self.tick + 1, self.tick + int(ticks) + 1):
            t = tick / fps
            for _ in range(self.substeps):
                for stage, name in enumerate(STAGES):
                    began = clock()
                    rows, times, _, self._bp = _step(
                        stage,
                        stage + 1,
                        self._S,
                        dt,
                        width,
                        height,
                        exact,
                        self._cores,
                        tick,
                        t,
                        False,
                        rows,
                        times,
                        0,
                        self._bp,
                    )
                    spent[name] += clock() - began
        self.tick += int(ticks)
        return spent

    def positions(self) -> np.ndarray:
        """(n, 2) float64 top-left corners, px."""
        return self._by_id(self._S.pos)

    def velocities(self) -> np.ndarray:
        """(n, 2) float64 velocities, px/s."""
        return self._by_id(self._S.vel)

    def _by_id(self, a: np.ndarray) -> np.ndarray:
        out = np.empty_like(a)
        out[self._S.ext] = a
        return out


def _broad_phase(world, pos, vel, size, movable, substeps, skip, broadphase):
    """The candidate list's state and scratch (see `_run`): its margin from the fastest step and
    the box sizes, the method and cell from the scene or `broadphase` (broadphase.choose)."""
    n = pos.shape[0]
    possible = n >= 2 and (bool(movable.any()) or not skip)
    fastest = float(np.abs(vel).max()) / (world.fps * substeps) if n else 0.0
    median_side = float(np.median(size.max(axis=1))) if n else 1.0
    margin = min(MARGIN_STEPS * fastest, MARGIN_MAX_SIDES * median_side)
    margin = max(margin, MARGIN_MIN_PX) if np.isfinite(margin) else MARGIN_MIN_PX
    method, cell = choose(world.width, world.height, size + 2.0 * margin, broadphase)
    slack = DRIFT_SLACK_PX + DRIFT_SLACK_REL * max(world.width, world.height)
    order = np.arange(n, dtype=np.int64)
    if method == METHOD_SWEEP:
        order = np.argsort(pos[:, 0], kind="stable").astype(np.int64)
    return (
        np.empty(max(16, CANDIDATES_PER_OBJECT * n), np.int64),  # keys
        np.empty(max(16, n), np.int64),  # near
        order,
        np.empty_like(pos),  # lo
        np.empty_like(pos),  # hi
        np.empty((2 * n, 4), np.int64),  # folds
        np.array([-1, method, int(possible), 0, 0, 0, chunks_for(n)], np.int64),  # see _run
        np.array([margin, cell, slack, 0.0]),
        workspace(n),
        np.empty(max(16, n)),  # when
        marker(method),  # finder: the kernels compile only this method's pair finder
    )
