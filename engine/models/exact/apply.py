"""The exact model's events: what each one changes in the state, and which objects it asks to be
predicted again (docs/models.md#exact).

A cell crossing refiles the object in the grid (cells.py); a wall contact reflects the velocity
component normal to the wall and sets the object exactly on the wall's line; a pair contact
exchanges velocities (engine/response.py) at the contact instant, the velocities under gravity
taken at that instant. Both act with the contact's restitution (the smaller of its two sides')
and friction (the larger): elastic and frictionless at the defaults, to the bit. Each writes its
prediction jobs (state.py) and returns how many; a pair that does not approach is no event (0
jobs), and one pressed together with no speed while one of the two falls on the other (which
would come to rest on it) returns -1: the model stops there. `move_to` carries an object's
position, and under gravity its velocity, to a time.
"""

from __future__ import annotations

from collide2d.engine.events import SIDE_LEFT, SIDE_RIGHT, SIDE_TOP
from collide2d.engine.models.exact.cells import cell_insert, cell_remove
from collide2d.engine.models.exact.prediction import set_job, velocity_at
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
    PARTNER,
    SH,
    STATIC,
    SW,
    TLOC,
    VX,
    VY,
    E,
    X,
    Y,
    hot,
)
from collide2d.engine.response import impact, wall_impact


@hot
def move_to(i, t, F):
    """Bring object i's position (and, under gravity, its velocity) to time t."""
    dt = t - F[i, TLOC]
    if F[i, AX] == 0.0 and F[i, AY] == 0.0:
        F[i, X] += F[i, VX] * dt
        F[i, Y] += F[i, VY] * dt
    else:
        F[i, X] += F[i, VX] * dt + 0.5 * F[i, AX] * dt * dt
        F[i, Y] += F[i, VY] * dt + 0.5 * F[i, AY] * dt * dt
        F[i, VX] += F[i, AX] * dt
        F[i, VY] += F[i, AY] * dt
    F[i, TLOC] = t


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
def on_wall(i, side, t, F, N, world, jobs):
    """i's box touches a wall: reflect that velocity component (times the contact's restitution,
    the smaller of the object's and the walls'; friction, the larger, takes from the component
    along the wall), set it exactly on the wall line. Returns the number of jobs (1)."""
    move_to(i, t, F)
    e = min(F[i, E], world.restitution)
    mu = max(F[i, MU], world.friction)
    if side == SIDE_LEFT or side == SIDE_RIGHT:
        F[i, VX], F[i, VY] = wall_impact(F[i, VX], F[i, VY], e, mu)
        F[i, X] = 0.0 if side == SIDE_LEFT else world.width - F[i, SW]
    else:
        F[i, VY], F[i, VX] = wall_impact(F[i, VY], F[i, VX], e, mu)
        F[i, Y] = 0.0 if side == SIDE_TOP else world.height - F[i, SH]
    N[i, CNT] += 1
    N[i, PARTNER] = -1
    set_job(jobs, 0, i, -1, JOB_EVENT)
    return 1


@hot
def on_pair(a, b, code, nx, ny, t, F, N, jobs):
    """a and b touch: the elastic exchange; then each moving one is predicted again, but not
    against the other. Returns the number of jobs (0: they were not approaching, no event).

    The exchange reads only velocities, so it is decided before anything moves: a pair that
    turns out not to approach leaves both objects exactly as they were, clocks included (moving
    one to t by a rounded step would make a later prediction of it differ in its last bits from
    one made before, and the local re-prediction then drift from the full one). For the same
    reason a static object never moves its clock: its counter does not change either, so the
    entries of its other pairs stay valid, and they must equal what asking again would give."""
    vax, vay = velocity_at(a, t, F)
    vbx, vby = velocity_at(b, t, F)
    e = min(F[a, E], F[b, E])
    mu = max(F[a, MU], F[b, MU])
    vax, vay, vbx, vby, changed = impact(
        vax, vay, vbx, vby, F[a, INV_MASS], F[b, INV_MASS], code, nx, ny, e, mu
    )
    # one falls, the other stands: their relative path is curved, and may meet again
    ax = F[b, AX] - F[a, AX]
    ay = F[b, AY] - F[a, AY]
    curved = ax != 0.0 or ay != 0.0
    if not changed:
        if curved and ax * nx + ay * ny < 0.0:
            return -1  # pressed together with no speed: it would rest on the other (not yet)
        return 0
    for i in (a, b):
        if N[i, STATIC] == 0:  # a static object's clock stays at 0: its entries never go stale
            move_to(i, t, F)
    F[a, VX], F[a, VY], F[b, VX], F[b, VY] = vax, vay, vbx, vby
    n_jobs = 0
    for i, other in ((a, b), (b, a)):
        if N[i, STATIC] == 0:
            N[i, CNT] += 1
            N[i, PARTNER] = -1 if curved else other
            set_job(jobs, n_jobs, i, -1 if curved else other, JOB_EVENT)
            n_jobs += 1
    return n_jobs
