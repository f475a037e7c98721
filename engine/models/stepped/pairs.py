"""The stepped model's response: each pair in contact after a step, in the order its contact
began, gets the elastic exchange and is pushed apart.

Input: the state (`model.State`), `near` from the narrow phase (keys of object ids, in order)
and the step dt. Output: velocities and positions changed in place, each pair that responded
counted and, when the log is on, logged.

Each pair is tested again on the current state, so that it sees what the pairs before it
changed. The normal is the axis along which the pair started overlapping, found from its relative
velocity (approach.box_step_contact; for exact shapes the direction of approach,
approach.step_contact); an approaching pair gets the exchange (response.exchange) and is pushed
apart along it by twice the depth it went in since that instant (response.separate).
"""

from __future__ import annotations

from collide2d.engine.broadphase import KEY_MASK, KEY_SHIFT
from collide2d.engine.events import EV_PAIR, log_event
from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.approach import box_step_contact, step_contact
from collide2d.engine.models.stepped.candidates import P_PUSHED, ST_PAIRS
from collide2d.engine.models.stepped.move import B_H, B_VX, B_VY, B_W, B_X, B_Y
from collide2d.engine.response import exchange, separate


@njit(cache=True)
def _contact(a, b, ea, eb, body, dt, exact, shape, radius, start, verts, normals):
    """(push, push_y, code, nx, ny) of a pair after a step of dt s (a, b inside; ea, eb their
    ids): the normal from the direction of approach, approach.box_step_contact / step_contact;
    push <= 0 when they do not overlap."""
    qx = body[b, B_X] - body[a, B_X]
    qy = body[b, B_Y] - body[a, B_Y]
    ux = body[b, B_VX] - body[a, B_VX]
    uy = body[b, B_VY] - body[a, B_VY]
    wa, ha, wb, hb = body[a, B_W], body[a, B_H], body[b, B_W], body[b, B_H]
    if not exact:
        return box_step_contact(qx, qy, ux, uy, wa, ha, wb, hb, dt)
    return step_contact(
        qx,
        qy,
        ux,
        uy,
        dt,
        shape[ea],
        wa,
        ha,
        radius[ea],
        verts[start[ea] : start[ea + 1]],
        normals[start[ea] : start[ea + 1]],
        shape[eb],
        wb,
        hb,
        radius[eb],
        verts[start[eb] : start[eb + 1]],
        normals[start[eb] : start[eb + 1]],
    )


@njit(cache=True)
def respond(S, at, cores, near, n_near, rows, times, n_ev, L):
    """Respond to every overlapping, approaching pair of `near` (ascending keys of ids) in order,
    after the step `at` (a Step); count each in L.state[ST_PAIRS], log it when at.log;
    L.params[P_PUSHED] the farthest from its anchor on an axis that an object pushed apart ended
    (px, 0 when none was). S: a State, L: a Lists (records.py); L.folds, the move's fold rows,
    free by now, is scratch."""
    body, inv_mass, rank, anchor = S.body, S.inv_mass, S.rank, S.anchor
    state, params, inside = L.state, L.params, L.folds
    dt, width, height, exact = at.dt, at.width, at.height, at.exact
    shape, radius, start, verts, normals = cores
    pos = body  # its columns 0, 1: the corners, as response.separate reads them
    size = body[:, B_W : B_H + 1]
    pushed = 0.0
    # First each pair's rows inside and a read of each row, in a short loop whose iterations do
    # not wait on each other: the reads from memory that a large scene needs (the pairs come in
    # the order of time, scattered over the state) then overlap instead of following one another.
    ahead = min(n_near, inside.shape[0])
    for m in range(ahead):
        a = rank[near[m] >> KEY_SHIFT]
        b = rank[near[m] & KEY_MASK]
        inside[m, 0] = a
        inside[m, 1] = b
        inside[m, 2] = (body[a, B_X] < body[b, B_X]) + (inv_mass[a] < inv_mass[b])
    for m in range(n_near):
        ea = near[m] >> KEY_SHIFT
        eb = near[m] & KEY_MASK
        if m < ahead:
            a = inside[m, 0]
            b = inside[m, 1]
        else:
            a = rank[ea]
            b = rank[eb]
        if exact:
            depth, depth_y, code, nx, ny = _contact(
                a, b, ea, eb, body, dt, exact, shape, radius, start, verts, normals
            )
        else:  # boxes: no call that takes an array (each costs reference counts, per pair)
            depth, depth_y, code, nx, ny = box_step_contact(
                body[b, B_X] - body[a, B_X],
                body[b, B_Y] - body[a, B_Y],
                body[b, B_VX] - body[a, B_VX],
                body[b, B_VY] - body[a, B_VY],
                body[a, B_W],
                body[a, B_H],
                body[b, B_W],
                body[b, B_H],
                dt,
            )
        if depth <= 0.0:
            continue
        vax, vay, vbx, vby, changed = exchange(
            body[a, B_VX],
            body[a, B_VY],
            body[b, B_VX],
            body[b, B_VY],
            inv_mass[a],
            inv_mass[b],
            code,
            nx,
            ny,
        )
        if not changed:
            continue
        body[a, B_VX], body[a, B_VY], body[b, B_VX], body[b, B_VY] = vax, vay, vbx, vby
        separate(
            pos, size, a, b, inv_mass[a], inv_mass[b], code, nx, ny, depth, depth_y, width, height
        )
        for i in (a, b):
            pushed = max(pushed, abs(body[i, B_X] - anchor[i, 0]), abs(body[i, B_Y] - anchor[i, 1]))
        state[ST_PAIRS] += 1
        if at.log:
            rows, times = log_event(rows, times, n_ev, at.tick, at.t, EV_PAIR, ea, eb, code)
            n_ev += 1
    params[P_PUSHED] = pushed
    return rows, times, n_ev
