"""The exact model's events: what each one changes in the state, and which objects it asks to be
predicted again (docs/models.md#exact).

A cell crossing refiles the object in the grid (cells.py); a wall contact reflects the velocity
component normal to the wall and sets the object exactly on the wall's line; a pair contact
exchanges velocities (engine/response.py) at the contact instant, the velocities under gravity
taken at that instant. Both act with the contact's restitution (the smaller of its two sides')
and friction (the larger): elastic and frictionless at the defaults, to the bit. Each writes its
prediction jobs (state.py) and returns how many; a pair that does not approach is no event (0
jobs), and one pressed together with no speed while one of the two falls on the other (which
would come to rest on it) returns -1: `rest_on` then rests it on a static box's face, as on a
wall, or the model stops there. A resting object's stop and leave (past the face's edge) are
events of their own. `move_to` carries an object's position, and under gravity its velocity, to
a time.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.events import SIDE_BOTTOM, SIDE_LEFT, SIDE_RIGHT, SIDE_TOP
from collide2d.engine.models.exact.cells import C_HEAD, cell_insert, cell_remove
from collide2d.engine.models.exact.prediction import leave_span, set_job, state_at, velocity_at
from collide2d.engine.models.exact.state import (
    AX,
    AY,
    CELL,
    CNT,
    DIR_DOWN,
    DIR_LEFT,
    DIR_RIGHT,
    DIR_UP,
    INV_MASS,
    JOB_CROSS,
    JOB_EVENT,
    MU,
    NEXT,
    PARTNER,
    S_STACKED,
    SH,
    SHAPE,
    STATIC,
    SW,
    TLOC,
    VX,
    VY,
    E,
    X,
    Y,
    cold,
    falls,
    hot,
    rest_side,
    rest_support,
)
from collide2d.engine.parabola import slide_acceleration
from collide2d.engine.response import impact, wall_impact
from collide2d.engine.world import KIND_BOX, KIND_POLYGON


@hot
def move_to(i, t, F, P, world):
    """Bring object i's position (and, under gravity, its velocity) to time t."""
    dt = t - F[i, TLOC]
    if not falls(world) or (P[i, AX] == 0.0 and P[i, AY] == 0.0):
        F[i, X] += F[i, VX] * dt
        F[i, Y] += F[i, VY] * dt
    else:
        F[i, X] += F[i, VX] * dt + 0.5 * P[i, AX] * dt * dt
        F[i, Y] += F[i, VY] * dt + 0.5 * P[i, AY] * dt * dt
        F[i, VX] += P[i, AX] * dt
        F[i, VY] += P[i, AY] * dt
    F[i, TLOC] = t


@hot
def again(i, skip, N, jobs):
    """Object i changed at an event of its own: its queued entries go stale (its counter) and it
    is predicted again, leaving out `skip` (-1: none). Returns the number of jobs (1)."""
    N[i, CNT] += 1
    N[i, PARTNER] = skip
    set_job(jobs, 0, i, skip, JOB_EVENT)
    return 1


@hot
def on_cross(i, d, N, cells, world, jobs):
    """i's centre enters the next cell: refile it. Returns the number of jobs (1)."""
    gnx = world.gnx
    gx = N[i, CELL] % gnx + (1 if d == DIR_RIGHT else -1 if d == DIR_LEFT else 0)
    gy = N[i, CELL] // gnx + (1 if d == DIR_DOWN else -1 if d == DIR_UP else 0)
    cell_remove(N, cells, i)
    cell_insert(N, cells, i, gy * gnx + gx)
    N[i, PARTNER] = -1
    set_job(jobs, 0, i, d, JOB_CROSS)
    return 1


@hot
def pull(side, world):
    """Gravity's pull into the wall `side`, px/s² (> 0: toward it)."""
    if side == SIDE_LEFT:
        return -world.gx
    if side == SIDE_RIGHT:
        return world.gx
    if side == SIDE_TOP:
        return -world.gy
    return world.gy


@hot
def slide(i, F, P, R, world):
    """Set resting object i's acceleration: none into its wall, and along it gravity less friction
    against its sliding (parabola.slide_acceleration); none either against a wall it touches
    along its slide with no speed (it sits in the corner). On a static box's face, as on a wall
    that side, with the larger of its friction and the box's."""
    side = rest_side(R[i])
    j = rest_support(R[i])
    mu = max(P[i, MU], world.friction if j < 0 else P[j, MU])
    if side == SIDE_LEFT or side == SIDE_RIGHT:
        a = slide_acceleration(world.gy, F[i, VY], mu, pull(side, world))
        span, p, v = world.height - F[i, SH], F[i, Y], F[i, VY]
        P[i, AX] = 0.0
    else:
        a = slide_acceleration(world.gx, F[i, VX], mu, pull(side, world))
        span, p, v = world.width - F[i, SW], F[i, X], F[i, VX]
        P[i, AY] = 0.0
    if v == 0.0 and ((a < 0.0 and p <= 0.0) or (a > 0.0 and p >= span)):
        a = 0.0
    if side == SIDE_LEFT or side == SIDE_RIGHT:
        P[i, AY] = a
    else:
        P[i, AX] = a


@hot
def _settles(v, a, world):
    """A speed v away from a wall that an acceleration a (< 0: back toward it) would bring back
    within `rest_height` of rise: the bounce is over."""
    return a < 0.0 and v * v <= -2.0 * a * world.rest_height


@cold
def _settle(i, side, F, P, R, world):
    """After i's bounce on wall `side` under gravity: a bounce that would rise less than
    `rest_height` ends there, i coming to rest on that wall, or, resting on another and sliding
    into this one, stopping against it."""
    x_side = side == SIDE_LEFT or side == SIDE_RIGHT
    out = 1.0 if side == SIDE_LEFT or side == SIDE_TOP else -1.0  # away from this wall
    away = out * (F[i, VX] if x_side else F[i, VY])
    if R[i] >= 0:  # sliding on another wall into this one
        slide(i, F, P, R, world)
        if not _settles(away, out * (P[i, AX] if x_side else P[i, AY]), world):
            return
    elif _settles(away, -pull(side, world), world):
        R[i] = side
    else:
        return
    if x_side:
        F[i, VX] = 0.0
    else:
        F[i, VY] = 0.0
    slide(i, F, P, R, world)


@hot
def on_wall(i, side, t, S, jobs):
    """i's box touches a wall: reflect that velocity component (times the contact's restitution,
    the smaller of the object's and the walls'; friction, the larger, takes from the component
    along the wall), set it exactly on the wall line. Under gravity a bounce that would rise less
    than `rest_height` ends there: the object comes to rest on that wall (N's REST), or, resting
    on another and sliding into this one, stops against it. Returns the number of jobs (1)."""
    F, N, P, R, world = S.F, S.N, S.P, S.R, S.world
    move_to(i, t, F, P, world)
    e, mu = 1.0, 0.0  # a world without physics keys: no need to read them
    if not world.elastic:
        e = min(P[i, E], world.restitution)
        mu = max(P[i, MU], world.friction)
    x_side = side == SIDE_LEFT or side == SIDE_RIGHT
    if x_side:
        F[i, VX], F[i, VY] = wall_impact(F[i, VX], F[i, VY], e, mu)
        F[i, X] = 0.0 if side == SIDE_LEFT else world.width - F[i, SW]
    else:
        F[i, VY], F[i, VX] = wall_impact(F[i, VY], F[i, VX], e, mu)
        F[i, Y] = 0.0 if side == SIDE_TOP else world.height - F[i, SH]
    if falls(world):
        _settle(i, side, F, P, R, world)
    return again(i, -1, N, jobs)


@cold
def on_stop(i, t, S, jobs):
    """Resting object i stops sliding: its speed along its wall is 0 from here, and static
    friction holds it or gravity starts it the other way. Returns the number of jobs (1)."""
    F, N, P, R, world = S.F, S.N, S.P, S.R, S.world
    move_to(i, t, F, P, world)
    side = rest_side(R[i])
    if side == SIDE_LEFT or side == SIDE_RIGHT:
        F[i, VY] = 0.0
    else:
        F[i, VX] = 0.0
    slide(i, F, P, R, world)
    return again(i, -1, N, jobs)


@cold
def wake_or_slide(i, F, P, R, world):
    """After a pair event, resting object i wakes (flies under gravity again) when it has a speed
    off its wall (or static box), into it or away; else it goes on sliding. Returns whether it
    woke."""
    side = rest_side(R[i])
    normal = F[i, VX] if side == SIDE_LEFT or side == SIDE_RIGHT else F[i, VY]
    if normal != 0.0:
        R[i] = -1
        P[i, AX], P[i, AY] = world.gx, world.gy
        return True
    slide(i, F, P, R, world)
    return False


@hot
def on_pair(a, b, code, nx, ny, t, S, jobs):
    """a and b touch: the impact; then each moving one is predicted again, but not against the
    other (unless one falls and the other stands: on a curved relative path they may meet again),
    and a resting one wakes if knocked off its wall (wake_or_slide). Returns the number of jobs
    (0: they were not approaching, no event; -1: one would come to rest on the other, pressed
    against it with no speed, or with a bounce that would rise less than `rest_height`: not yet).

    The exchange reads only velocities, so it is decided before anything moves: a pair that
    turns out not to approach leaves both objects exactly as they were, clocks included (moving
    one to t by a rounded step would make a later prediction of it differ in its last bits from
    one made before, and the local re-prediction then drift from the full one). For the same
    reason a static object never moves its clock: its counter does not change either, so the
    entries of its other pairs stay valid, and they must equal what asking again would give."""
    F, N, P, R, world = S.F, S.N, S.P, S.R, S.world
    vax, vay = velocity_at(a, t, F, P, world)
    vbx, vby = velocity_at(b, t, F, P, world)
    e, mu = 1.0, 0.0
    wa, wb = F[a, INV_MASS], F[b, INV_MASS]
    if not world.elastic:
        e = min(P[a, E], P[b, E])
        mu = max(P[a, MU], P[b, MU])
        if falls(world):  # a body resting still, pressed into its support, is held by it
            wa, wb = _held(a, b, nx, ny, wa, wb, S)
    vax, vay, vbx, vby, changed = impact(vax, vay, vbx, vby, wa, wb, code, nx, ny, e, mu)
    if changed and S.st[S_STACKED] > 0 and _knocks_carrier(a, b, vax, vay, vbx, vby, t, S, jobs):
        return -2  # a body another rests on is knocked into motion: its support would move
    # one falls, the other stands: their relative path is curved, and may meet again
    ax = ay = 0.0
    if falls(world):
        ax = P[b, AX] - P[a, AX]
        ay = P[b, AY] - P[a, AY]
    curved = ax != 0.0 or ay != 0.0
    if not changed:
        if curved and ax * nx + ay * ny < 0.0:
            return -1  # pressed together with no speed: it would rest on the other (not yet)
        return 0
    if curved and _settles((vbx - vax) * nx + (vby - vay) * ny, ax * nx + ay * ny, world):
        return -1  # a bounce that dies away on the other: it would rest on it (not yet)
    for i in (a, b):
        if N[i, STATIC] == 0:  # a static object's clock stays at 0: its entries never go stale
            move_to(i, t, F, P, world)
    F[a, VX], F[a, VY], F[b, VX], F[b, VY] = vax, vay, vbx, vby
    for i in (a, b):
        if falls(world) and R[i] >= 0:
            wake_or_slide(i, F, P, R, world)
    n_jobs = 0
    for i, other in ((a, b), (b, a)):
        if N[i, STATIC] == 0:
            N[i, CNT] += 1
            N[i, PARTNER] = -1 if curved else other
            set_job(jobs, n_jobs, i, -1 if curved else other, JOB_EVENT)
            n_jobs += 1
    return n_jobs


@cold
def still_on_support(i, S):
    """Whether object i rests, still (no speed, no acceleration), on a wall or a static box or a
    body resting still in turn: a support for what falls on it."""
    F, P, R = S.F, S.P, S.R
    return (
        R[i] >= 0
        and F[i, VX] == 0.0
        and F[i, VY] == 0.0
        and P[i, AX] == 0.0
        and P[i, AY] == 0.0
    )


@cold
def _held(a, b, nx, ny, wa, wb, S):
    """The inverse masses of pair (a, b), of unit normal n from a to b, for their impact: one
    resting still that the impact presses straight into its support (its side, along n for b,
    -n for a) is held by it, as if static (0), the support taking the impulse."""
    if wb > 0.0 and still_on_support(b, S) and _face_side(nx, ny) == rest_side(S.R[b]):
        return wa, 0.0
    if wa > 0.0 and still_on_support(a, S) and _face_side(-nx, -ny) == rest_side(S.R[a]):
        return 0.0, wb
    return wa, wb


@cold
def _knocks_carrier(a, b, vax, vay, vbx, vby, t, S, jobs):
    """Whether the impact of a and b, leaving them at (vax, vay) and (vbx, vby), sets moving a
    body that another rests on (a stack): that one and the carried one in jobs' row 0. What
    rests on a body touches it, so it is filed in the 3×3 cells around it (as for predict)."""
    F, N, P, R, world, cells = S.F, S.N, S.P, S.R, S.world, S.cells
    gnx, gny = world.gnx, world.gny
    for i, vx, vy in ((a, vax, vay), (b, vbx, vby)):
        ux, uy = velocity_at(i, t, F, P, world)
        if N[i, STATIC] != 0 or (ux == vx and uy == vy):
            continue
        gx = N[i, CELL] % gnx
        gy = N[i, CELL] // gnx
        for cy in range(max(gy - 1, 0), min(gy + 1, gny - 1) + 1):
            for cx in range(max(gx - 1, 0), min(gx + 1, gnx - 1) + 1):
                k = cells[cy * gnx + cx, C_HEAD]
                while k >= 0:
                    if rest_support(R[k]) == i:
                        set_job(jobs, 0, i, k, JOB_EVENT)
                        return True
                    k = N[k, NEXT]
    return False


@hot
def _face_side(dx, dy):
    """The side pressed into along the unit direction (dx, dy) when it is an axis (-1 if not)."""
    if dx == 0.0 and dy == 1.0:
        return SIDE_BOTTOM
    if dx == 0.0 and dy == -1.0:
        return SIDE_TOP
    if dy == 0.0 and dx == 1.0:
        return SIDE_RIGHT
    if dy == 0.0 and dx == -1.0:
        return SIDE_LEFT
    return -1


@cold
def rest_on(a, b, nx, ny, t, S, jobs):
    """Pair (a, b), of unit normal n from a to b, where on_pair found that one falls onto the
    other to rest (-1): the falling one comes to rest on the other when that is a static box, or
    a box resting still pressed the same way (a stack; still_on_support), and they touch on its
    face across gravity's pull, the falling one over that face (leave_span; a box or a circle):
    its impact there with the pair's restitution and friction, then no speed into the face, set
    exactly on it, sliding along it as on a wall. Returns the jobs (1); -1 where it cannot rest
    (a moving, curved or polygonal support, a corner): the model stops."""
    F, N, P, R, world = S.F, S.N, S.P, S.R, S.world
    if R[a] < 0 and N[a, STATIC] == 0 and (N[b, STATIC] != 0 or still_on_support(b, S)):
        i, j, side = a, b, _face_side(nx, ny)
    elif R[b] < 0 and N[b, STATIC] == 0 and (N[a, STATIC] != 0 or still_on_support(a, S)):
        i, j, side = b, a, _face_side(-nx, -ny)
    else:
        return -1
    if side < 0 or N[j, SHAPE] != KIND_BOX or N[i, SHAPE] == KIND_POLYGON:
        return -1
    if N[j, STATIC] == 0 and rest_side(R[j]) != side:  # a stack: pressed the way j is
        return -1
    if not pull(side, world) > 0.0:
        return -1
    x_side = side == SIDE_LEFT or side == SIDE_RIGHT
    axis = 1 if x_side else 0  # along the face
    lo, hi = leave_span(i, j, axis, F, N)
    x, y, _, _ = state_at(i, t, F, P)
    p = y if x_side else x
    if not (lo < p < hi):
        return -1
    move_to(i, t, F, P, world)
    e = min(P[i, E], P[j, E])
    mu = max(P[i, MU], P[j, MU])
    if x_side:
        F[i, VX], F[i, VY] = wall_impact(F[i, VX], F[i, VY], e, mu)
        F[i, VX] = 0.0
        F[i, X] = F[j, X] - F[i, SW] if side == SIDE_RIGHT else F[j, X] + F[j, SW]
    else:
        F[i, VY], F[i, VX] = wall_impact(F[i, VY], F[i, VX], e, mu)
        F[i, VY] = 0.0
        F[i, Y] = F[j, Y] - F[i, SH] if side == SIDE_BOTTOM else F[j, Y] + F[j, SH]
    R[i] = side + 4 * (j + 1)
    if N[j, STATIC] == 0:
        S.st[S_STACKED] += 1
    slide(i, F, P, R, world)
    return again(i, -1, N, jobs)


@cold
def on_leave(i, t, S, jobs):
    """Resting object i slides past the edge of the static box j it rests on (leave_span): set
    exactly at that edge, it falls from there at its velocity. A box leaves the corner at once
    (they only touch there); a circle, whose centre is then over the corner, flies clear of it
    when its speed v along the face holds v² >= r·g (g gravity's pull into the face) and gravity
    along the face does not pull it back: predicting i again leaves j out this once (they touch
    at that instant, parting). Else it would slide round the corner: -1, the model stops. Returns
    the jobs (1)."""
    F, N, P, R, world = S.F, S.N, S.P, S.R, S.world
    side = rest_side(R[i])
    j = rest_support(R[i])
    axis = 1 if side == SIDE_LEFT or side == SIDE_RIGHT else 0
    v = velocity_at(i, t, F, P, world)[axis]
    skip = -1
    if N[i, SHAPE] != KIND_BOX:  # a circle (rest_on takes no polygon)
        along = world.gy if axis == 1 else world.gx
        if v * v < 0.5 * F[i, SW] * pull(side, world) or v * along < 0.0:
            return -1
        skip = j
    move_to(i, t, F, P, world)
    lo, hi = leave_span(i, j, axis, F, N)
    F[i, X + axis] = lo if v < 0.0 else hi
    R[i] = -1
    P[i, AX], P[i, AY] = world.gx, world.gy
    return again(i, skip, N, jobs)


def start_resting(F, N, P, R, world) -> None:
    """Moving objects that start still against a wall gravity pulls them into rest on it (sliding
    along it at their speed there): on the floor, or the ceiling, before on a side wall. Python,
    called once when the model is built."""
    span = np.array([world.width, world.height]) - F[:, SW : SH + 1]
    walls = ((1, world.gy, SIDE_TOP, SIDE_BOTTOM), (0, world.gx, SIDE_LEFT, SIDE_RIGHT))
    for axis, g, low, high in walls:
        if g == 0.0:
            continue
        on = F[:, X + axis] >= span[:, axis] if g > 0 else F[:, X + axis] <= 0.0
        still = (F[:, VX + axis] == 0.0) & (N[:, STATIC] == 0) & (R < 0)
        for i in np.flatnonzero(on & still):
            R[i] = high if g > 0 else low
            slide(int(i), F, P, R, world)
