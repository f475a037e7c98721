"""Collision response: the elastic exchange, pushing a pair apart, and reflection at the walls.

Input: velocities (n, 2) px/s, positions (n, 2) px (top-left corners), box sizes, inverse masses
(1/mass, 0 for static objects), and a contact from contact.py (code, nx, ny). Output: the arrays
changed in place. These are the only places where the accurate models change a velocity.

The elastic exchange, derived once. Two bodies with inverse masses w1, w2 (one may be 0) meet with
unit normal n from 1 to 2; let u = (v2 - v1)·n, negative when they approach. An impulse J along n
gives v1' = v1 - J w1 n and v2' = v2 + J w2 n, so u' = u + J (w1 + w2). Momentum is kept for any J
(m1 J w1 = m2 J w2 = J). Kinetic energy is kept when u' = -u, which gives

    J = -2 u / (w1 + w2),   v1' = v1 + 2 u r1 n,   v2' = v2 - 2 u r2 n,   r_i = w_i / (w1 + w2).

Written with the ratios r1 + r2 = 1 it stays finite and exact in the limits: a static partner
(w2 = 0) gives r1 = 1, a mirror reflection; masses 1 : 10^10 give r = 1 - 1e-10 and 1e-10 and no
cancellation. Only the heavier body's change is computed from its ratio; the lighter one's is
what leaves the pair at -u (times e) along n: a ratio rounded alike at every impact would
otherwise bias the energy alike (docs/models.md#the-elastic-exchange). With AXIS_XY (corner
to corner) the exchange acts on x and on y apart, each with its own sign, and only on an axis
along which the pair approaches.
"""

from __future__ import annotations

import math

from collide2d.engine.errors import FoldLimitExceeded
from collide2d.engine.events import AXIS_XY
from collide2d.engine.jit import njit

# More folds than this at one wall axis in one step is refused (a runaway, not a bounce).
MAX_FOLDS_PER_STEP = 1000


@njit(cache=True, inline="always")
def exchange_along(vax, vay, vbx, vby, wa, wb, nx, ny):
    """Elastic exchange of a and b along the unit normal n (from a to b).

    v* px/s; wa, wb inverse masses (not both 0). Returns (vax, vay, vbx, vby, changed): the new
    velocities, and changed = True when they were approaching along n (otherwise no change).
    """
    return impact_along(vax, vay, vbx, vby, wa, wb, nx, ny, 1.0, 0.0)


@njit(cache=True, inline="always")
def impact_along(vax, vay, vbx, vby, wa, wb, nx, ny, e, mu):
    """The impact of a and b along the unit normal n (from a to b) with restitution e and
    friction mu (docs/models.md#the-elastic-exchange): the normal impulse leaves the approach
    speed u at -e·u; the tangential one stops the sliding if that takes at most mu times the
    normal one, else is mu times it against the sliding. At e = 1 and mu = 0 it is the elastic
    exchange to the bit ((1 + 1) is 2 exactly, and no friction is computed). Returns (vax, vay,
    vbx, vby, changed)."""
    u = (vbx - vax) * nx + (vby - vay) * ny
    if not u < 0.0:
        return vax, vay, vbx, vby, False
    ra = wa / (wa + wb)
    rb = wb / (wa + wb)
    # the heavier one (a on a tie) takes its share of the impulse; the other then leaves at -e·u
    # from it, so that a mass ratio rounded the same way at every impact never biases the energy
    if wa <= wb:
        ja = (1.0 + e) * u * ra
        vax, vay = vax + ja * nx, vay + ja * ny
        jb = (vax - vbx) * nx + (vay - vby) * ny - e * u
        vbx, vby = vbx + jb * nx, vby + jb * ny
    else:
        jb = (1.0 + e) * u * rb
        vbx, vby = vbx - jb * nx, vby - jb * ny
        ja = (vbx - vax) * nx + (vby - vay) * ny + e * u
        vax, vay = vax + ja * nx, vay + ja * ny
    if mu > 0.0:
        # the sliding of b along a before the impact, and what friction takes of it
        tx = (vbx - vax) - ((vbx - vax) * nx + (vby - vay) * ny) * nx
        ty = (vby - vay) - ((vbx - vax) * nx + (vby - vay) * ny) * ny
        slide = math.sqrt(tx * tx + ty * ty)
        if slide > 0.0:
            take = min(slide, mu * (1.0 + e) * -u) / slide
            vax, vay = vax + take * ra * tx, vay + take * ra * ty
            vbx, vby = vbx - take * rb * tx, vby - take * rb * ty
    return vax, vay, vbx, vby, True


@njit(cache=True, inline="always")
def impact(vax, vay, vbx, vby, wa, wb, code, nx, ny, e, mu):
    """`exchange` with restitution e and friction mu (impact_along); AXIS_XY (a corner) acts on
    each axis apart, without friction. Returns (vax, vay, vbx, vby, changed)."""
    if code == AXIS_XY:
        vax, vay, vbx, vby, done_x = impact_along(vax, vay, vbx, vby, wa, wb, nx, 0.0, e, 0.0)
        vax, vay, vbx, vby, done_y = impact_along(vax, vay, vbx, vby, wa, wb, 0.0, ny, e, 0.0)
        return vax, vay, vbx, vby, done_x or done_y
    return impact_along(vax, vay, vbx, vby, wa, wb, nx, ny, e, mu)


@njit(cache=True, inline="always")
def wall_impact(vn, vt, e, mu):
    """A wall impact: the velocity component into the wall vn and the one along it vt after, with
    restitution e and friction mu (at most what stops the sliding)."""
    if mu > 0.0 and vt != 0.0:
        take = min(abs(vt), mu * (1.0 + e) * abs(vn))
        vt = vt - take if vt > 0.0 else vt + take
    return -e * vn, vt


@njit(cache=True, inline="always")
def exchange(vax, vay, vbx, vby, wa, wb, code, nx, ny):
    """The elastic response to a contact (code, nx, ny) from contact.py.

    AXIS_XY: a 1-D exchange on x (sign nx) and on y (sign ny), each where approaching. Otherwise
    one exchange along the unit normal. Returns (vax, vay, vbx, vby, changed).
    """
    if code == AXIS_XY:
        vax, vay, vbx, vby, done_x = exchange_along(vax, vay, vbx, vby, wa, wb, nx, 0.0)
        vax, vay, vbx, vby, done_y = exchange_along(vax, vay, vbx, vby, wa, wb, 0.0, ny)
        return vax, vay, vbx, vby, done_x or done_y
    return exchange_along(vax, vay, vbx, vby, wa, wb, nx, ny)


@njit(cache=True)
def _shift_within(x, d, span):
    """x moved by d but kept in [0, span]: (where it ends, the part of d actually made)."""
    target = min(max(x + d, 0.0), max(span, 0.0))
    return target, target - x


@njit(cache=True)
def _separate_axis(xa, xb, wa, wb, push, span_a, span_b):
    """Push b by +push·wb/(wa+wb) and a by -push·wa/(wa+wb) along one axis, in the world;
    what one of them cannot take at a wall is handed to the other. Returns (xa, xb): the
    coordinates on that axis after. Scalars in and out, so that the pair loop that calls it
    hands no array to a call (each costs reference counts)."""
    da = -push * (wa / (wa + wb))
    db = push * (wb / (wa + wb))
    made_a = 0.0
    if wa > 0.0:
        xa, made_a = _shift_within(xa, da, span_a)
    if wb > 0.0:
        xb, made_b = _shift_within(xb, db + (da - made_a) * -1.0, span_b)
    else:
        made_b = 0.0
    left = push - (made_b - made_a)
    if wa > 0.0 and left != 0.0:
        xa, _ = _shift_within(xa, -left, span_a)
    return xa, xb


@njit(cache=True)
def separate(pos, size, a, b, wa, wb, code, nx, ny, depth, depth_y, width, height):
    """Push an overlapping pair apart along the contact normal, shared by inverse mass, in place.

    pos/size (n, 2) px; the pair moves apart by depth (px) along the unit normal (nx, ny), or for
    AXIS_XY by depth along x (sign nx) and depth_y along y (sign ny). No object is pushed out
    of the world [0, width) × [0, height); when one side is blocked the other takes the rest.
    """
    span_ax = width - size[a, 0]
    span_ay = height - size[a, 1]
    span_bx = width - size[b, 0]
    span_by = height - size[b, 1]
    push_x = depth * nx
    push_y = depth_y * ny if code == AXIS_XY else depth * ny
    if code == AXIS_XY or nx != 0.0:
        pos[a, 0], pos[b, 0] = _separate_axis(
            pos[a, 0], pos[b, 0], wa, wb, push_x, span_ax, span_bx
        )
    if code == AXIS_XY or ny != 0.0:
        pos[a, 1], pos[b, 1] = _separate_axis(
            pos[a, 1], pos[b, 1], wa, wb, push_y, span_ay, span_by
        )


@njit(cache=True)
def fold(x, v, span):
    """Reflect a coordinate into [0, span] as walls would (docs/models.md#stepped-walls), folding
    while outside.

    x px (top-left corner), v px/s, span = world side - box side. Returns (x', v', folds_low,
    folds_high, first_low): x -> -x at the low wall, x -> 2 span - x at the high wall, v reversed
    at each fold; first_low tells which wall came first. span <= 0 pins x at 0 without a fold.
    Raises FoldLimitExceeded (a Runaway, and a ValueError) past MAX_FOLDS_PER_STEP folds (a step
    far too long for the speed).
    """
    if span <= 0.0:
        return 0.0, v, 0, 0, False
    if x < -MAX_FOLDS_PER_STEP * span or x > (MAX_FOLDS_PER_STEP + 1) * span:
        raise FoldLimitExceeded(
            "an object crosses the world too many times in one step; use substeps"
        )
    low = 0
    high = 0
    first_low = x < 0.0
    while x < 0.0 or x > span:
        if x < 0.0:
            x = -x
            low += 1
        else:
            x = 2.0 * span - x
            high += 1
        v = -v
    return x, v, low, high, first_low
