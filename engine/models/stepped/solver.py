"""The settling path's solver (docs/models.md#stepped-gravity-restitution-and-friction): every
contact of a step at once, velocities first, then the overlap, without ever adding energy.

Input: the state (`records.Fall`), the constants (`records.Physics`) and this step's contacts
(touch.py: keys and rows of floats, columns touch.C_*). Output: velocities, then positions,
changed in place.

Velocities (`solve`), sequential impulses over `iterations` passes. A contact of normal n (from a
to b) has the relative normal velocity u = (v_b - v_a)·n (< 0 approaching) and the effective mass
1 / (w_a + w_b) (w the inverse masses; the same along the tangent t, there being no rotation).
Each pass gives each contact in turn the impulse that brings u up to its goal (touch.C_GO: 0
between two falling objects; ½·g·dt away from a support that does not fall, so that the next
step's gravity brings the object back to it exactly: a body at rest neither sinks nor lifts off),
kept as a running total clamped at >= 0 (a contact pushes, never pulls), then the friction
impulse that stops its sliding, its total clamped to mu times the normal total (Coulomb's cone,
in 2-D a segment). The passes run forward and backward in turn. A contact that the last step had
too starts from the impulses it ended with there (warm starting: a stack's weight is carried from
step to step instead of being found again in a few passes). Should the passes leave more kinetic
energy than the step began with (plus what its move took away), their change is scaled back by
the largest factor in [0, 1] that does not (the energy is a quadratic in the factor).

Then restitution, one pass: a contact that approached at the rest speed or faster (any speed
without gravity) is given the normal impulse that makes it part at e times that speed (and the
friction that goes with it); slower contacts get e = 0, so a body at rest stays at rest. Alone a
contact then parts at exactly -e times its approach. Among many, one pass can overshoot; the pass
is scaled back the same way.

Positions (`correct`): overlap deeper than `slop` is removed in `iterations` passes (forward and
backward in turn; done sooner once a pass finds nothing past slop), each pair pushed apart along its
normal by its depth past slop, shared by inverse mass, never out of the world (a side that a wall
stops hands the rest to the other). Velocities are not touched. A push shared by inverse mass along
gravity keeps the potential energy; one against a wall or a static or sleeping object raises it (the
object had sunk into its support, the fall's energy given up by the contact's velocity). The pushes
are scaled back, when needed, so that what they raise stays within the energy the velocity passes
have given up so far and pushes have not spent (settle.py keeps that account): the energy never
rises above what the scene began with, and a push never gives an object speed.
"""

from __future__ import annotations

import math

from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.move import B_H, B_VX, B_VY, B_W, B_X, B_Y
from collide2d.engine.models.stepped.touch import (
    C_E,
    C_GAP,
    C_GO,
    C_LN,
    C_LT,
    C_MU,
    C_NX,
    C_NY,
    C_U0,
    C_WA,
    C_WB,
    _sides,
)


@njit(cache=True)
def kinetic(F):
    """Kinetic energy of the awake objects, px^2/s^2 x mass."""
    body = F.body
    k = 0.0
    for i in range(body.shape[0]):
        if F.awake[i]:
            k += F.mass[i] * (body[i, B_VX] * body[i, B_VX] + body[i, B_VY] * body[i, B_VY])
    return 0.5 * k


@njit(cache=True)
def energy(F, P):
    """Kinetic and potential energy of the awake objects (potential relative to the world's
    origin, -m·(g·p), p the top-left corner), px^2/s^2 x mass."""
    body = F.body
    k = 0.0
    for i in range(body.shape[0]):
        if F.awake[i]:
            vx, vy = body[i, B_VX], body[i, B_VY]
            k += F.mass[i] * (0.5 * (vx * vx + vy * vy) - P.gx * body[i, B_X] - P.gy * body[i, B_Y])
    return k


@njit(cache=True, inline="always")
def _impulse(body, a, b, wa, wb, jx, jy):
    """Impulse j (per unit mass x inverse mass) from a to b: a loses wa j, b gains wb j."""
    body[a, B_VX] -= wa * jx
    body[a, B_VY] -= wa * jy
    if b >= 0:
        body[b, B_VX] += wb * jx
        body[b, B_VY] += wb * jy


@njit(cache=True, inline="always")
def _velocity(body, a, b, nx, ny):
    """(v_b - v_a)·n, and along the tangent (-ny, nx)."""
    ux = -body[a, B_VX]
    uy = -body[a, B_VY]
    if b >= 0:
        ux += body[b, B_VX]
        uy += body[b, B_VY]
    return ux * nx + uy * ny, -ux * ny + uy * nx


@njit(cache=True)
def _pass(body, pairs, floats, m, target, rest, back, inv_dt):
    """One pass over the contacts, in key order (from the last when `back`): each one's normal
    impulse toward the normal velocity `target` (0: stop the approach; 1: part at e x its
    approach, for those that came at `rest` or faster), then its friction."""
    for k in range(m):
        c = m - 1 - k if back else k
        a, b = _sides(pairs[c])
        nx, ny = floats[c, C_NX], floats[c, C_NY]
        wa, wb = floats[c, C_WA], floats[c, C_WB]
        mass = 1.0 / (wa + wb)
        un, ut = _velocity(body, a, b, nx, ny)
        goal = floats[c, C_GO]
        if target:
            u0 = floats[c, C_U0]
            if not (u0 > 0.0 and u0 >= rest and floats[c, C_E] > 0.0):
                continue
            goal = max(floats[c, C_E] * u0, goal)
        ln = floats[c, C_LN]
        total = max(ln + (goal - un) * mass, 0.0)
        dn = total - ln
        floats[c, C_LN] = total
        bound = floats[c, C_MU] * total
        lt = floats[c, C_LT]
        kept = min(max(lt - ut * mass, -bound), bound)  # (the normal impulse leaves ut)
        dl = kept - lt
        floats[c, C_LT] = kept
        _impulse(body, a, b, wa, wb, dn * nx - dl * ny, dn * ny + dl * nx)


@njit(cache=True)
def _apply_started(body, pairs, floats, m):
    """The impulses the contacts start from (warm starting), applied."""
    for c in range(m):
        a, b = _sides(pairs[c])
        ln, lt, nx, ny = floats[c, C_LN], floats[c, C_LT], floats[c, C_NX], floats[c, C_NY]
        jx, jy = ln * nx - lt * ny, ln * ny + lt * nx
        _impulse(body, a, b, floats[c, C_WA], floats[c, C_WB], jx, jy)


@njit(cache=True)
def _save_velocities(F):
    body, saved = F.body, F.saved
    for i in range(body.shape[0]):
        saved[i, 0] = body[i, B_VX]
        saved[i, 1] = body[i, B_VY]


@njit(cache=True)
def _scale_back(F, k0):
    """Scale the change from the saved velocities back so the kinetic energy is at most k0
    (the largest factor in [0, 1] that does it)."""
    body, saved = F.body, F.saved
    kc = 0.0  # energy at the saved velocities, the change's dot with them, its square
    lin = 0.0
    sq = 0.0
    for i in range(body.shape[0]):
        if not F.awake[i]:
            continue
        m = F.mass[i]
        dx = body[i, B_VX] - saved[i, 0]
        dy = body[i, B_VY] - saved[i, 1]
        kc += 0.5 * m * (saved[i, 0] * saved[i, 0] + saved[i, 1] * saved[i, 1])
        lin += m * (dx * saved[i, 0] + dy * saved[i, 1])
        sq += m * (dx * dx + dy * dy)
    if not kc + lin + 0.5 * sq > k0:
        return
    room = max(k0 - kc, 0.0)  # kc + s lin + s^2 sq / 2 <= k0
    s = 0.0
    if sq > 0.0:
        s = (-lin + math.sqrt(lin * lin + 2.0 * sq * room)) / sq
    s = min(max(s, 0.0), 1.0)
    for i in range(body.shape[0]):
        if F.awake[i]:
            body[i, B_VX] = saved[i, 0] + s * (body[i, B_VX] - saved[i, 0])
            body[i, B_VY] = saved[i, 1] + s * (body[i, B_VY] - saved[i, 1])


@njit(cache=True)
def solve(F, P, pairs, floats, m, taken, dt):
    """The velocity passes and the restitution pass (module docstring), leaving at most the
    kinetic energy the awake objects had before them plus `taken`, what the step's move took
    away; returns that bound."""
    body = F.body
    inv_dt = 1.0 / dt
    limit = kinetic(F) + taken
    _save_velocities(F)
    _apply_started(body, pairs, floats, m)
    for it in range(P.iterations):
        _pass(body, pairs, floats, m, False, P.rest, it % 2 == 1, inv_dt)
    _scale_back(F, limit)  # should the warm start have added energy
    _save_velocities(F)
    _pass(body, pairs, floats, m, True, P.rest, False, inv_dt)
    _scale_back(F, limit)
    return limit


@njit(cache=True, inline="always")
def _shift(body, i, dx, dy, sides):
    """Move object i by (dx, dy) px, kept in the world; returns the move made."""
    x = min(max(body[i, B_X] + dx, 0.0), max(sides[0] - body[i, B_W], 0.0))
    y = min(max(body[i, B_Y] + dy, 0.0), max(sides[1] - body[i, B_H], 0.0))
    mx = x - body[i, B_X]
    my = y - body[i, B_Y]
    body[i, B_X] = x
    body[i, B_Y] = y
    return mx, my


@njit(cache=True, inline="always")
def _push(body, mass, gx, gy, a, b, nx, ny, wa, wb, push, sides):
    """Push a contact's pair, a and b, apart along its normal n by `push` px (module docstring);
    returns the potential energy that raised."""
    raised = 0.0
    made = 0.0
    if wa > 0.0:
        share = push * (wa / (wa + wb))
        mx, my = _shift(body, a, -share * nx, -share * ny, sides)
        made = -(mx * nx + my * ny)
        raised -= mass[a] * (gx * mx + gy * my)
    if wb > 0.0:
        mx, my = _shift(body, b, (push - made) * nx, (push - made) * ny, sides)
        made += mx * nx + my * ny
        raised -= mass[b] * (gx * mx + gy * my)
    left = push - made
    if wa > 0.0 and left > 0.0:
        mx, my = _shift(body, a, -left * nx, -left * ny, sides)
        raised -= mass[a] * (gx * mx + gy * my)
    return raised


@njit(cache=True)
def correct(F, P, pairs, floats, m, budget, sides):
    """The position passes (module docstring); `budget` the energy the velocity passes took
    away this step. Returns the potential energy the pushes raised."""
    body, saved = F.body, F.saved
    for i in range(body.shape[0]):  # (sleep.doze reads how far each was pushed)
        saved[i, 0] = body[i, B_X]
        saved[i, 1] = body[i, B_Y]
    first = 0
    while first < m and pairs[first] < 0:  # the walls' contacts: the move keeps objects inside
        first += 1
    if first == m:
        return 0.0
    raised = 0.0
    mass, gx, gy, slop = F.mass, P.gx, P.gy, P.slop
    for it in range(P.iterations):
        pushed = False
        for k in range(first, m):
            c = m - 1 - (k - first) if it % 2 else k
            a, b = _sides(pairs[c])
            nx, ny, wa, wb = floats[c, C_NX], floats[c, C_NY], floats[c, C_WA], floats[c, C_WB]
            apart = (body[b, B_X] - body[a, B_X]) * nx + (body[b, B_Y] - body[a, B_Y]) * ny
            push = floats[c, C_GAP] - apart - slop  # the depth past slop
            if not push > 0.0:
                continue
            pushed = True
            raised += _push(body, mass, gx, gy, a, b, nx, ny, wa, wb, push, sides)
        if not pushed:  # every overlap within slop: the passes left would push nothing either
            break
    if raised > max(budget, 0.0):  # (so raised > 0: a budget below 0 with nothing raised is no 0/0)
        s = max(budget, 0.0) / raised
        for i in range(body.shape[0]):
            if F.awake[i]:
                body[i, B_X] = saved[i, 0] + s * (body[i, B_X] - saved[i, 0])
                body[i, B_Y] = saved[i, 1] + s * (body[i, B_Y] - saved[i, 1])
        raised *= s
    return raised
