"""The exact model's predictions: an object's next wall contact, cell crossing and contacts.

A prediction job (a row of `jobs`, see state.py) names an object; `predict` sets its horizon
(the first of its next wall contact and its next cell crossing) in the horizon queue
(horizonqueue.py) and pushes its contacts with the objects in the 3×3 cells around it that come no
later than the horizon on the event queue (heap.py). A pair is swept from the later of its
two clocks (contact.next_contact), so a predicted time depends only on the pair's
state.
"""

from __future__ import annotations

from collide2d.engine.contact import box_next_contact, box_reach, next_contact
from collide2d.engine.events import SIDE_BOTTOM, SIDE_LEFT, SIDE_RIGHT, SIDE_TOP
from collide2d.engine.jit import njit
from collide2d.engine.models.exact.arccontact import Arc, Core, arc_contact
from collide2d.engine.models.exact.cells import C_HEAD
from collide2d.engine.models.exact.heap import RANK_CROSS, RANK_PAIR, RANK_WALL, make_key, push
from collide2d.engine.models.exact.horizonqueue import set_horizon
from collide2d.engine.models.exact.state import (
    AX,
    AY,
    CELL,
    CNT,
    DIR_DOWN,
    DIR_LEFT,
    DIR_RIGHT,
    DIR_UP,
    INF,
    J_HIGHER,
    J_OBJ,
    J_SKIP,
    JOB_CONTACTS,
    JOB_CROSS,
    JOB_FIRST,
    LEAVE,
    NEXT,
    S_STAMP,
    SH,
    SHAPE,
    STAMP,
    STOP,
    SW,
    TLOC,
    VX,
    VY,
    Entry,
    X,
    Y,
    cold,
    falls,
    hot,
    rest_side,
    rest_support,
)
from collide2d.engine.parabola import meet
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE


@hot
def velocity_at(i, t, F, P, world):
    """Object i's velocity at time t (its own, unchanged without acceleration)."""
    if not falls(world) or (P[i, AX] == 0.0 and P[i, AY] == 0.0):
        return F[i, VX], F[i, VY]
    dt = t - F[i, TLOC]
    return F[i, VX] + P[i, AX] * dt, F[i, VY] + P[i, AY] * dt


@hot
def state_at(i, t, F, P):
    """Object i's position and velocity at time t (x, y, vx, vy), not stored."""
    dt = t - F[i, TLOC]
    if P[i, AX] == 0.0 and P[i, AY] == 0.0:
        return F[i, X] + F[i, VX] * dt, F[i, Y] + F[i, VY] * dt, F[i, VX], F[i, VY]
    return (
        F[i, X] + F[i, VX] * dt + 0.5 * P[i, AX] * dt * dt,
        F[i, Y] + F[i, VY] * dt + 0.5 * P[i, AY] * dt * dt,
        F[i, VX] + P[i, AX] * dt,
        F[i, VY] + P[i, AY] * dt,
    )


@hot
def _first_of_two(t_lo, t_hi, lo, hi):
    """(t, what) of the earlier of two meetings, the low one on a tie; (inf, -1) if neither."""
    if t_lo <= t_hi and t_lo < INF:
        return t_lo, lo
    if t_hi < INF:
        return t_hi, hi
    return INF, -1


@cold
def _wall_time_falling(i, t_now, F, P, world):
    """_wall_time under an acceleration: on each axis the first of its two walls the parabola meets
    (parabola.meet), from i's state at t_now."""
    x, y, vx, vy = state_at(i, t_now, F, P)
    sx = world.width - F[i, SW]
    sy = world.height - F[i, SH]
    tx, side_x = _first_of_two(
        meet(max(x, 0.0), vx, P[i, AX]),
        meet(max(sx - x, 0.0), -vx, -P[i, AX]),
        SIDE_LEFT,
        SIDE_RIGHT,
    )
    ty, side_y = _first_of_two(
        meet(max(y, 0.0), vy, P[i, AY]),
        meet(max(sy - y, 0.0), -vy, -P[i, AY]),
        SIDE_TOP,
        SIDE_BOTTOM,
    )
    if ty < tx:
        return t_now + ty, side_y
    if tx < INF:
        return t_now + tx, side_x
    return INF, -1


@cold
def _stop_time(i, t_now, F, P, R):
    """When resting object i, sliding against friction, stops (inf: never)."""
    x, y, vx, vy = state_at(i, t_now, F, P)
    side = rest_side(R[i])
    v, a = (vy, P[i, AY]) if side == SIDE_LEFT or side == SIDE_RIGHT else (vx, P[i, AX])
    if v * a < 0.0:
        return t_now + -v / a
    return INF


@cold
def leave_span(i, j, axis, F, N):
    """The positions (lo, hi) along `axis` (0: x, 1: y) between which object i is over the face
    of static box j it rests on: a box while it overlaps the face, a circle while its centre is
    over it (past that it would hang on the corner)."""
    lo = F[j, X + axis]
    hi = lo + F[j, SW + axis]
    size = F[i, SW + axis]
    if N[i, SHAPE] == KIND_CIRCLE:
        return lo - 0.5 * size, hi - 0.5 * size
    return lo - size, hi


@cold
def _leave_time(i, t_now, F, N, P, R):
    """When object i, resting on a static box's face, slides past its edge (leave_span; inf:
    never)."""
    side = rest_side(R[i])
    axis = 1 if side == SIDE_LEFT or side == SIDE_RIGHT else 0
    lo, hi = leave_span(i, rest_support(R[i]), axis, F, N)
    x, y, vx, vy = state_at(i, t_now, F, P)
    p, v, a = (y, vy, P[i, AY]) if axis == 1 else (x, vx, P[i, AX])
    t, _ = _first_of_two(meet(max(p - lo, 0.0), v, a), meet(max(hi - p, 0.0), -v, -a), 0, 1)
    return t_now + t


@hot
def _wall_time(i, t_now, F, P, world):
    """(t, side) of i's next wall contact (its box touching a wall line), (inf, -1) if none."""
    if falls(world) and (P[i, AX] != 0.0 or P[i, AY] != 0.0):
        return _wall_time_falling(i, t_now, F, P, world)
    t_best = INF
    side = -1
    if F[i, VX] > 0.0:
        t_best, side = F[i, TLOC] + (world.width - F[i, SW] - F[i, X]) / F[i, VX], SIDE_RIGHT
    elif F[i, VX] < 0.0:
        t_best, side = F[i, TLOC] + F[i, X] / -F[i, VX], SIDE_LEFT
    if F[i, VY] > 0.0:
        t = F[i, TLOC] + (world.height - F[i, SH] - F[i, Y]) / F[i, VY]
        if t < t_best:
            t_best, side = t, SIDE_BOTTOM
    elif F[i, VY] < 0.0:
        t = F[i, TLOC] + F[i, Y] / -F[i, VY]
        if t < t_best:
            t_best, side = t, SIDE_TOP
    return t_best, side


@cold
def _cross_time_falling(i, t_now, F, P, N, world):
    """_cross_time under an acceleration: on each axis the first of the cell's two sides the
    centre's parabola meets (parabola.meet; none on the grid's edge), from i's state at t_now."""
    cell, gnx, gny = world.cell, world.gnx, world.gny
    gx = N[i, CELL] % gnx
    gy = N[i, CELL] // gnx
    x, y, vx, vy = state_at(i, t_now, F, P)
    cx = x + 0.5 * F[i, SW] - gx * cell  # the centre within its cell
    cy = y + 0.5 * F[i, SH] - gy * cell
    ax, ay = P[i, AX], P[i, AY]
    t_left = meet(max(cx, 0.0), vx, ax) if gx > 0 else INF
    t_right = meet(max(cell - cx, 0.0), -vx, -ax) if gx < gnx - 1 else INF
    t_up = meet(max(cy, 0.0), vy, ay) if gy > 0 else INF
    t_down = meet(max(cell - cy, 0.0), -vy, -ay) if gy < gny - 1 else INF
    tx, dx = _first_of_two(t_left, t_right, DIR_LEFT, DIR_RIGHT)
    ty, dy = _first_of_two(t_up, t_down, DIR_UP, DIR_DOWN)
    if ty < tx:
        return t_now + ty, dy
    if tx < INF:
        return t_now + tx, dx
    return INF, -1


@hot
def _cross_time(i, t_now, F, P, N, world):
    """(t, direction) when i's box centre next leaves its grid cell, (inf, -1) if never."""
    if falls(world) and (P[i, AX] != 0.0 or P[i, AY] != 0.0):
        return _cross_time_falling(i, t_now, F, P, N, world)
    cell, gnx, gny = world.cell, world.gnx, world.gny
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
    """next_contact for a pair with a circle or polygon, of cores C (state.Cores)."""
    radius, start, verts, normals = C.radius, C.start, C.verts, C.normals
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


@njit(cache=True)
def _arc_contact(a, b, path, now, N, C):
    """arccontact.arc_contact for a pair one of which falls and the other stands (path: their
    Arc)."""
    radius, start, verts, normals = C.radius, C.start, C.verts, C.normals
    core_a = Core(
        N[a, SHAPE], radius[a], verts[start[a] : start[a + 1]], normals[start[a] : start[a + 1]]
    )
    core_b = Core(
        N[b, SHAPE], radius[b], verts[start[b] : start[b + 1]], normals[start[b] : start[b + 1]]
    )
    return arc_contact(path, core_a, core_b, now)


@cold
def _falling_pair(a, b, t0, t_now, limit, S):
    """_predict_pair's start under gravity: the pair's relative position and velocity at t0,
    (False, qx, qy, ux, uy); or, when one falls and the other stands, their curved relative path's
    contact pushed if it comes no later than `limit`, (True, ...)."""
    F, N, P = S.F, S.N, S.P
    xa, ya, vax, vay = state_at(a, t0, F, P)
    xb, yb, vbx, vby = state_at(b, t0, F, P)
    qx, qy, ux, uy = xb - xa, yb - ya, vbx - vax, vby - vay
    ax = P[b, AX] - P[a, AX]
    ay = P[b, AY] - P[a, AY]
    if ax == 0.0 and ay == 0.0:
        return False, qx, qy, ux, uy
    t, code, nx, ny = _arc_contact(a, b, Arc(qx, qy, ux, uy, ax, ay), t_now - t0, N, S.C)
    t = max(t0 + t, t_now)
    if t <= limit:
        e = Entry(t, make_key(RANK_PAIR, a, b, code), N[a, CNT], N[b, CNT], nx, ny)
        push(S.HT, S.HI, S.HN, S.st, e)
    return True, qx, qy, ux, uy


@hot
def _predict_pair(i, j, t_now, limit, S):
    """Push the next contact of i and j if it comes no later than `limit` (s).

    The pair is swept from the later of the two objects' clocks, so that only one position is
    carried forward and the predicted time does not depend on when the question is asked.
    """
    F, N = S.F, S.N
    a = min(i, j)
    b = max(i, j)
    t0 = max(F[a, TLOC], F[b, TLOC])
    if falls(S.world):
        curved, qx, qy, ux, uy = _falling_pair(a, b, t0, t_now, limit, S)
        if curved:
            return
    else:
        qx = (F[b, X] + F[b, VX] * (t0 - F[b, TLOC])) - (F[a, X] + F[a, VX] * (t0 - F[a, TLOC]))
        qy = (F[b, Y] + F[b, VY] * (t0 - F[b, TLOC])) - (F[a, Y] + F[a, VY] * (t0 - F[a, TLOC]))
        ux = F[b, VX] - F[a, VX]
        uy = F[b, VY] - F[a, VY]
    if not box_reach(qx, qy, ux, uy, F[a, SW], F[a, SH], F[b, SW], F[b, SH], limit - t0):
        return
    now = t_now - t0
    if N[a, SHAPE] == KIND_BOX and N[b, SHAPE] == KIND_BOX:
        t, code, nx, ny = box_next_contact(
            qx, qy, ux, uy, F[a, SW], F[a, SH], F[b, SW], F[b, SH], now
        )
    else:
        t, code, nx, ny = _shape_contact(a, b, qx, qy, ux, uy, now, F, N, S.C)
    t = max(t0 + t, t_now)
    if t <= limit:
        e = Entry(t, make_key(RANK_PAIR, a, b, code), N[a, CNT], N[b, CNT], nx, ny)
        push(S.HT, S.HI, S.HN, S.st, e)


@hot
def predict(jobs, k, t_now, S):
    """Run prediction job k for object i: set its horizon (the first of its next wall contact
    and its next cell crossing; horizonqueue.py) and push its contacts with the objects in the
    3×3 cells around it that come no later than that. Inlined into the event loop's one call
    site: a call would cost more than the prediction of a small scene."""
    F, N, cells, st, world = S.F, S.N, S.cells, S.st, S.world
    s_start, s_items = S.s_start, S.s_items
    i, skip, mode = jobs[k, J_OBJ], jobs[k, J_SKIP], jobs[k, J_HIGHER]
    higher = mode == JOB_FIRST
    P, R = S.P, S.R
    t_wall, side = _wall_time(i, t_now, F, P, world)
    support = -1  # the box i rests on: touching it, it is no contact
    if falls(world) and R[i] >= 0:  # resting: its stop or its leaving, if first, changes it next
        t_stop = _stop_time(i, t_now, F, P, R)
        if t_stop < t_wall:
            t_wall, side = t_stop, STOP
        support = rest_support(R[i])
        if support >= 0:
            t_leave = _leave_time(i, t_now, F, N, P, R)
            if t_leave < t_wall:
                t_wall, side = t_leave, LEAVE
    if mode != JOB_CONTACTS:
        t_cross, d = _cross_time(i, t_now, F, P, N, world)
        if t_cross <= t_wall and t_cross < INF:
            t_h, rank, what = max(t_cross, t_now), RANK_CROSS, d
        elif t_wall < INF:
            t_h, rank, what = max(t_wall, t_now), RANK_WALL, side
        else:
            t_h, rank, what = INF, RANK_WALL, 0
        set_horizon(S.Q, i, t_h, rank, what)  # (one call site: one compiled specialisation)
    limit = max(t_wall, t_now)
    gnx, gny = world.gnx, world.gny
    gx = N[i, CELL] % gnx
    gy = N[i, CELL] // gnx
    x0, x1 = max(gx - 1, 0), min(gx + 1, gnx - 1)
    y0, y1 = max(gy - 1, 0), min(gy + 1, gny - 1)
    if mode == JOB_CROSS:  # only the row or column of cells it has just come next to
        came, skip = skip, -1
        if came == DIR_RIGHT:
            x0 = gx + 1
        elif came == DIR_LEFT:
            x1 = gx - 1
        elif came == DIR_DOWN:
            y0 = gy + 1
        else:
            y1 = gy - 1
    st[S_STAMP] += 1
    statics = s_items.shape[0] > 0
    for cy in range(y0, y1 + 1):
        for cx in range(x0, x1 + 1):
            c = cy * gnx + cx
            j = cells[c, C_HEAD]
            while j >= 0:
                if j != i and j != skip and j != support and not (higher and j < i):
                    _predict_pair(i, j, t_now, limit, S)
                j = N[j, NEXT]
            if not statics:  # (spares reading the static objects' lists of a scene without any)
                continue
            for m in range(s_start[c], s_start[c + 1]):
                j = s_items[m]
                if N[j, STAMP] != st[S_STAMP] and j != skip and j != support:
                    N[j, STAMP] = st[S_STAMP]
                    _predict_pair(i, j, t_now, limit, S)


@hot
def set_job(jobs, k, i, skip, higher):
    jobs[k, J_OBJ], jobs[k, J_SKIP], jobs[k, J_HIGHER] = i, skip, higher
