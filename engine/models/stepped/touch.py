"""The settling path's contacts (docs/models.md#stepped-gravity-restitution-and-friction): which
objects touch after a step's move, the walls included, each with its normal, depth, restitution and
friction; which sleeping objects a moving one wakes; and the impulses last step's contacts ended
with.

Input: the state (`records.Fall`), the constants (`records.Physics`) and the candidate list and
contact buffers (`records.Touch`). Output: this step's contacts, written into `Touch.pairs` (a key
each) and `Touch.floats` (columns C_*), in ascending key order: the walls first (by object, then
side), then the pairs (by ids). Their order is a total order of ids, so the solver's passes, and
with them every result, are the same whatever order the broad phase found the pairs in.

The candidate list (a Verlet list) holds the pairs whose boxes, each grown by half a margin,
overlap, at least one of them awake; it is made anew once an awake object has drifted half the
margin from where it was when the list was made (then no two objects can have closed the margin
since, so every pair that touches now is listed), and whenever an object wakes (its pairs with the
sleeping were not listed). A contact of a sleeping object with an awake one that moves at the
rest speed or faster wakes it; with a slower one, the sleeping object holds like a static one.
Two sleeping objects are never paired.

A contact's normal runs from its first object to its second (to the wall, for a wall). Boxes: the
axis along which the pair started overlapping in the step, when it did (contact.box_sweep, swept
back along the relative velocity), else the axis of the smaller overlap (contact.box_penetration);
exact shapes (`geometry: exact`): the minimum-penetration normal (contact.penetration). The sweep
starts where the step began (fall.fall keeps it), so a bounce off a wall within the step does
not turn it. Boxes that touched in the last step keep the normal they touched by while they
still overlap across it. It keeps
`C_GAP`, the depth plus the offset of the two objects along the normal, so that the solver reads
the depth left after any push as C_GAP - (p_b - p_a)·n.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.broadphase import KEY_MASK, KEY_SHIFT, find_split
from collide2d.engine.contact import box_sweep, penetration
from collide2d.engine.events import AXIS_NORMAL, AXIS_X, AXIS_XY, AXIS_Y, EV_PAIR, log_event
from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.move import B_H, B_VX, B_VY, B_W, B_X, B_Y
from collide2d.engine.sort import sort_pair_keys

# The columns of a contact's row of floats: the normal, the depth plus the offset along it (px),
# the two sides' inverse masses (0 for a static, sleeping or wall side), the contact's e and mu,
# the speed it approached at when found (px/s, > 0 approaching), the normal and friction
# impulses so far (per unit of inverse mass: px/s x mass), and the speed it is to part at (px/s,
# `_goal`).
C_NX, C_NY, C_GAP, C_WA, C_WB, C_E, C_MU, C_U0, C_LN, C_LT, C_GO = range(11)
C_COLUMNS = 11
# The model's counts: listed keys (-1: no list), contacts, last step's contacts, wall events,
# pair events, whether the list must be made anew, awake objects.
N_KEYS, N_CONTACTS, N_LAST, N_WALLS, N_PAIRS, N_RELIST, N_AWAKE = range(7)
N_SIZE = 7
# A wall contact's key: below every pair's key (which are >= 0), by object, then side (SIDE_*).
WALL_KEY_BASE = -(1 << 62)
# The depth of two boxes that touch along a side without overlapping (px): a contact that holds
# them apart (a stack built exactly touching) but that no push acts on.
TOUCHING = 1e-300
# Boxes this close (px) touch: room for the rounding of two positions that moved alike.
TOUCH_PX = 1e-9
# Under gravity, a pair of boxes overlapping as much along gravity as across, times this, part
# along gravity (touch._leaning).
GRAVITY_LEAN = 0.5
# An object this close to a wall (px) touches it.
WALL_TOUCH_PX = 1e-9
# Contacts and keys to start with per object (the buffers double when full).
CONTACTS_PER_OBJECT = 4


@njit(cache=True)
def relist(F, P, T, keys):
    """Make the candidate list anew (module docstring) and anchor every object where it is;
    returns the key buffer (grown when it was too small)."""
    body, anchor, lo, hi = F.body, F.anchor, T.lo, T.hi
    n = body.shape[0]
    for i in range(n):
        lo[i, 0] = body[i, B_X] - P.half
        lo[i, 1] = body[i, B_Y] - P.half
        hi[i, 0] = body[i, B_X] + body[i, B_W] + P.half
        hi[i, 1] = body[i, B_Y] + body[i, B_H] + P.half
        anchor[i, 0] = body[i, B_X]
        anchor[i, 1] = body[i, B_Y]
    found = np.zeros(1, np.int64)
    k = find_split(T.finder, lo, hi, F.awake, T.cell, T.order, keys, T.ws, found)
    while k > keys.shape[0]:
        keys = np.empty(2 * k, np.int64)
        k = find_split(T.finder, lo, hi, F.awake, T.cell, T.order, keys, T.ws, found)
    sort_pair_keys(keys, k, KEY_SHIFT, T.heads)
    T.counts[N_KEYS] = k
    T.counts[N_RELIST] = 0
    return keys


@njit(cache=True, inline="always")
def _speed2(body, i):
    return body[i, B_VX] * body[i, B_VX] + body[i, B_VY] * body[i, B_VY]


@njit(cache=True)
def _room(pairs, floats, m):
    """The contact buffers with room for row m (doubled when full)."""
    if m < pairs.shape[0]:
        return pairs, floats
    more_pairs = np.empty(2 * pairs.shape[0] + 16, np.int64)
    more_floats = np.empty((more_pairs.shape[0], C_COLUMNS))
    for r in range(m):
        more_pairs[r] = pairs[r]
        for c in range(C_COLUMNS):
            more_floats[r, c] = floats[r, c]
    return more_pairs, more_floats


@njit(cache=True, inline="always")
def _goal(P, wa, wb, nx, ny, dt):
    """The speed a contact is to part at so that the next step's gravity brings it back to where
    it is: half what gravity closes it by in a step (0 between two objects that both fall).
    A body resting on a support so leaves it at ½·g·dt and is back on it at the step's end: it
    neither sinks into it nor lifts off."""
    ga = 1.0 if wa > 0.0 else 0.0
    gb = 1.0 if wb > 0.0 else 0.0
    closing = (ga - gb) * (P.gx * nx + P.gy * ny)
    return max(0.5 * closing * dt, 0.0)


@njit(cache=True, inline="always")
def _put(floats, m, normal, gap, wa, wb, e, mu, u0, goal):
    floats[m, C_NX], floats[m, C_NY], floats[m, C_GAP] = normal[0], normal[1], gap
    floats[m, C_WA], floats[m, C_WB], floats[m, C_E], floats[m, C_MU] = wa, wb, e, mu
    floats[m, C_U0], floats[m, C_LN], floats[m, C_LT], floats[m, C_GO] = u0, 0.0, 0.0, goal


@njit(cache=True)
def walls(F, P, sides, pairs, floats, dt):
    """The contacts of awake objects with the walls they touch or are within half the margin of,
    in id order (x sides first); returns (buffers, how many). Such a contact keeps its gap (px)
    in C_GAP, and may close by up to the gap in the step, or at the speed the object already
    has toward it, whichever is more (a speculative contact: the wall's own bounce is the
    move's, fall.py), so that an object a bounce just took off a wall is still held by it when
    others push it back."""
    body = F.body
    m = 0
    for i in range(body.shape[0]):
        if not F.awake[i]:
            continue
        e = min(F.restitution[i], P.restitution)
        mu = max(F.friction[i], P.friction)
        w = F.inv_mass[i]
        for axis in range(2):
            span = sides[axis] - body[i, B_W + axis]
            if not span > 0.0:
                continue
            p = body[i, B_X + axis]
            v = body[i, B_VX + axis]
            for high in range(2):
                gap = span - p if high else p
                if not gap <= P.half:
                    continue
                gap = gap if gap > WALL_TOUCH_PX else 0.0
                sign = 1.0 if high else -1.0
                pairs, floats = _room(pairs, floats, m)
                pairs[m] = WALL_KEY_BASE + 4 * i + 2 * axis + high
                nx, ny = (sign, 0.0) if axis == 0 else (0.0, sign)
                toward = max(sign * v, 0.0)
                goal = _goal(P, w, 0.0, nx, ny, dt)
                u0 = toward
                if gap > 0.0:  # may close by the gap, and never slows what moves it there
                    goal = -max(gap / dt, toward)
                    u0 = 0.0
                _put(floats, m, (nx, ny), gap, w, 0.0, e, mu, u0, goal)
                m += 1
    return pairs, floats, m


@njit(cache=True)
def _exact_normal(body, cores, a, b):
    """(depth, code, nx, ny) of objects a and b (ids) by their exact shapes."""
    shape, radius, start, verts, normals = cores
    qx = body[b, B_X] - body[a, B_X]
    qy = body[b, B_Y] - body[a, B_Y]
    wa, ha, wb, hb = body[a, B_W], body[a, B_H], body[b, B_W], body[b, B_H]
    return penetration(
        qx, qy, shape[a], wa, ha, radius[a], verts[start[a] : start[a + 1]],
        normals[start[a] : start[a + 1]], shape[b], wb, hb, radius[b],
        verts[start[b] : start[b + 1]], normals[start[b] : start[b + 1]],
    )  # fmt: skip


@njit(cache=True, inline="always")
def _leaning(qx, qy, wa, ha, wb, hb, lean):
    """contact.box_penetration, its y depth taken `lean` times (x's when lean < 0: |lean|) when
    choosing the axis: under gravity a box squeezed into a row too full for it rides up onto
    its neighbours rather than pushing the row apart. (depth, code, nx, ny)."""
    right = wa - qx
    left = qx + wb
    down = ha - qy
    up = qy + hb
    dx, sx = (right, 1.0) if right <= left else (left, -1.0)
    dy, sy = (down, 1.0) if down <= up else (up, -1.0)
    wx = dx if lean > 0.0 else dx * -lean
    wy = dy * lean if lean > 0.0 else dy
    if wx < wy or (dx < 0.0 and dx < dy):
        return dx, AXIS_X, sx, 0.0
    if wy < wx or (dy < 0.0 and dy < dx):
        return dy, AXIS_Y, 0.0, sy
    return min(dx, dy), AXIS_XY, sx, sy


@njit(cache=True, inline="always")
def _normal(body, saved, a, b, dt, lean):
    """(depth, code, nx, ny) of boxes a and b (ids) after the step: module docstring."""
    qx = body[b, B_X] - body[a, B_X]
    qy = body[b, B_Y] - body[a, B_Y]
    wa, ha, wb, hb = body[a, B_W], body[a, B_H], body[b, B_W], body[b, B_H]
    depth, code, nx, ny = _leaning(qx, qy, wa, ha, wb, hb, lean)
    if -TOUCH_PX <= depth <= 0.0:  # touching (the other axis overlaps, or touches too)
        return TOUCHING, code, nx, ny
    if not depth > 0.0:
        return depth, code, nx, ny
    # from where the step began (fall.fall saved it), on a straight line
    q0x = saved[b, 0] - saved[a, 0]
    q0y = saved[b, 1] - saved[a, 1]
    ux = (qx - q0x) / dt
    uy = (qy - q0y) / dt
    t_enter, _, c, sx, sy = box_sweep(q0x, q0y, ux, uy, wa, ha, wb, hb)
    if 0.0 <= t_enter <= dt:  # began this step: the axis it came in by
        code, nx, ny = c, sx, sy
        if c == AXIS_X:
            depth = wa - qx if nx > 0.0 else qx + wb
        elif c == AXIS_Y:
            depth = ha - qy if ny > 0.0 else qy + hb
    elif t_enter < 0.0:  # overlapping as the step began: the smaller overlap then
        d0, c0, mx, my = _leaning(q0x, q0y, wa, ha, wb, hb, lean)
        if c0 != AXIS_XY:
            along = _held(body, a, b, mx, my)
            if along > 0.0:
                depth, code, nx, ny = along, c0, mx, my
    if code == AXIS_XY:  # corner to corner: the diagonal, deep enough to part both axes
        depth = min(wa - qx if nx > 0.0 else qx + wb, ha - qy if ny > 0.0 else qy + hb)
        depth *= math.sqrt(2.0)
        nx *= math.sqrt(0.5)
        ny *= math.sqrt(0.5)
        code = AXIS_NORMAL
    return depth, code, nx, ny


@njit(cache=True, inline="always")
def _held(body, a, b, nx, ny):
    """The depth of boxes a and b along the axis-aligned normal they touched by in the last step
    (they still overlap, or touch, across it); -1 when they no longer do, or it was no axis."""
    if nx != 0.0 and ny != 0.0:
        return -1.0
    qx = body[b, B_X] - body[a, B_X]
    qy = body[b, B_Y] - body[a, B_Y]
    wa, ha, wb, hb = body[a, B_W], body[a, B_H], body[b, B_W], body[b, B_H]
    xdiff = min(wa, qx + wb) - max(0.0, qx)
    ydiff = min(ha, qy + hb) - max(0.0, qy)
    if ny != 0.0:
        across, depth = xdiff, (ha - qy if ny > 0.0 else qy + hb)
    else:
        across, depth = ydiff, (wa - qx if nx > 0.0 else qx + wb)
    if not (across > 0.0 and depth >= -TOUCH_PX):
        return -1.0
    return max(depth, TOUCHING)


@njit(cache=True, inline="always")
def _wake(F, T, s, o, rest2):
    """Wake s if it sleeps and o, awake, moves at the rest speed or faster (module docstring)."""
    if F.asleep[s] and F.awake[o] and _speed2(F.body, o) >= rest2 and rest2 > 0.0:
        F.asleep[s] = False
        F.awake[s] = True
        F.quiet[s] = 0.0
        T.counts[N_RELIST] = 1


@njit(cache=True)
def pair_contacts(F, P, T, keys, pairs, floats, m, at, log, held):
    """The listed pairs in contact after the step `at` (a Step), from row m on: wakes a sleeping
    object that an awake one moving at the rest speed or faster touches (and asks for a new
    list), and logs a pair event for each approaching at the rest speed or faster (faster than
    0 without gravity). log = (rows, times, n_ev); held = (keys, rows) of last step's contacts
    (`keep`): boxes that touched then keep the normal they touched by while they still overlap
    across it (a box wedged into a gap narrower than itself stays on top, where the smaller
    overlap would turn it sideways). Returns (buffers, how many rows, log)."""
    body, awake, asleep = F.body, F.awake, F.asleep
    rows, times, n_ev = log
    last_keys, last = held
    n_last = T.counts[N_LAST]
    lean = 1.0  # the axis of gravity preferred (_leaning)
    if P.gy != 0.0 and abs(P.gy) >= abs(P.gx):
        lean = GRAVITY_LEAN
    elif P.gx != 0.0:
        lean = -GRAVITY_LEAN
    j = 0
    rest2 = P.rest * P.rest
    for c in range(T.counts[N_KEYS]):
        a = keys[c] >> KEY_SHIFT
        b = keys[c] & KEY_MASK
        if not (awake[a] or awake[b]):
            continue
        while j < n_last and last_keys[j] < keys[c]:
            j += 1
        depth = -1.0
        if j < n_last and last_keys[j] == keys[c] and not T.exact:
            nx, ny = last[j, 2], last[j, 3]
            depth = _held(body, a, b, nx, ny)
            code = AXIS_NORMAL
        if depth < 0.0:
            if T.exact:
                depth, code, nx, ny = _exact_normal(body, T.cores, a, b)
            else:
                depth, code, nx, ny = _normal(body, F.saved, a, b, at.dt, lean)
        if not depth > 0.0:
            continue
        if asleep[a] or asleep[b]:  # a sleeping side woken by a moving one
            _wake(F, T, a, b, rest2)
            _wake(F, T, b, a, rest2)
        wa = F.inv_mass[a] if awake[a] else 0.0
        wb = F.inv_mass[b] if awake[b] else 0.0
        if wa + wb == 0.0:
            continue
        ux = body[b, B_VX] - body[a, B_VX]
        uy = body[b, B_VY] - body[a, B_VY]
        u0 = max(-(ux * nx + uy * ny), 0.0)
        gap = depth + (body[b, B_X] - body[a, B_X]) * nx + (body[b, B_Y] - body[a, B_Y]) * ny
        e = min(F.restitution[a], F.restitution[b])
        mu = max(F.friction[a], F.friction[b])
        pairs, floats = _room(pairs, floats, m)
        pairs[m] = keys[c]
        _put(floats, m, (nx, ny), gap, wa, wb, e, mu, u0, _goal(P, wa, wb, nx, ny, at.dt))
        m += 1
        if u0 > 0.0 and u0 >= P.rest:
            T.counts[N_PAIRS] += 1
            if at.log:
                if nx == 0.0:
                    code = AXIS_Y
                elif ny == 0.0:
                    code = AXIS_X
                rows, times = log_event(rows, times, n_ev, at.tick, at.t, EV_PAIR, a, b, code)
                n_ev += 1
    return pairs, floats, m, (rows, times, n_ev)


@njit(cache=True)
def cap_goals(F, P, pairs, floats, m, capped):
    """No goal (touch._goal) for the contacts of an object that something which does not fall (a
    wall, a static or a sleeping object) holds from above: held between two such, it could not
    part from both, and the impulses would grow without end. capped (n,) bool is scratch."""
    for c in range(m):
        a, b = _sides(pairs[c])
        up = -(P.gx * floats[c, C_NX] + P.gy * floats[c, C_NY])  # > 0: b is above a
        if b < 0 and floats[c, C_GAP] > 0.0:  # a wall not touched yet
            continue
        if b < 0 or floats[c, C_WB] == 0.0:
            if up > 0.0:
                capped[a] = True
        elif floats[c, C_WA] == 0.0 and up < 0.0:
            capped[b] = True
    for c in range(m):
        a, b = _sides(pairs[c])
        if capped[a] or (b >= 0 and capped[b]):
            floats[c, C_GO] = min(floats[c, C_GO], 0.0)
    for c in range(m):
        a, b = _sides(pairs[c])
        capped[a] = False
        if b >= 0:
            capped[b] = False


@njit(cache=True, inline="always")
def _sides(key):
    """(a, b) of a contact's key; b = -1 for a wall."""
    if key < 0:
        return (key - WALL_KEY_BASE) >> 2, -1
    return key >> KEY_SHIFT, key & KEY_MASK


@njit(cache=True)
def warm(T, pairs, floats, m, last_keys, last):
    """Each contact that last step had too (same key) starts from the impulses it ended with
    there (both lists ascend by key: one merge)."""
    j = 0
    n_last = T.counts[N_LAST]
    for c in range(m):
        while j < n_last and last_keys[j] < pairs[c]:
            j += 1
        if j < n_last and last_keys[j] == pairs[c]:
            floats[c, C_LN] = last[j, 0]
            floats[c, C_LT] = last[j, 1]


@njit(cache=True)
def keep(T, pairs, floats, m, last_keys, last):
    """Keep this step's contacts' keys, impulses and normals for the next step's `warm` and
    `pair_contacts`; returns the
    buffers (grown when too small)."""
    if last.shape[0] < m:
        last_keys = np.empty(2 * m, np.int64)
        last = np.empty((2 * m, 4))
    for c in range(m):
        last_keys[c] = pairs[c]
        last[c, 0] = floats[c, C_LN]
        last[c, 1] = floats[c, C_LT]
        last[c, 2] = floats[c, C_NX]
        last[c, 3] = floats[c, C_NY]
    T.counts[N_LAST] = m
    return last_keys, last
