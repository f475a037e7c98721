"""Contact geometry: overlap tests, contact normals and exact times of impact for pairs.

Input: two objects' exact shapes (shapes.py: a convex core grown by a radius, relative to each
box's top-left corner), the position of B's corner relative to A's, `q = p_B - p_A` (px), and B's
velocity relative to A's, `u = v_B - v_A` (px/s). Output: overlap depth and contact normal
(`penetration`), the times the pair enters and leaves contact (`sweep`) and the next contact
under the exact model's rules (`next_contact`); the stepped model's contact after a step is
built on them in `models/stepped/approach.py`.

All of it rests on one picture. A and B overlap exactly when q lies in the Minkowski difference
`M = shape_A ⊕ (-shape_B)`, a convex set, and without rotation q moves on the straight line
`q + u t`. So a time of impact is a ray cast against M (the Cyrus–Beck clip of the line against
M's faces, with discs at the corners when a circle is involved), and the contact normal, from A
to B, is M's outward normal where the line enters: for two boxes, the axis whose overlap started
last. Inside M, the face nearest to q gives the minimum-penetration normal (separating axes).

Contacts are (code, nx, ny): code AXIS_X / AXIS_Y with (nx, ny) the unit axis, AXIS_NORMAL with a
unit normal that is not axis-aligned, or AXIS_XY (two boxes meeting corner to corner, or tied
overlaps) with nx, ny = the signs ±1 of each axis; the response then acts on each axis apart.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.events import AXIS_NORMAL, AXIS_X, AXIS_XY, AXIS_Y
from collide2d.engine.jit import njit
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE

INF = np.inf
# Two unit normals whose dot product is at least this are the same face direction (rad^2 scale).
SAME_DIRECTION = 1.0 - 1e-12
# Contacts closer than this (px of travel, or of overlap width) count as simultaneous: two faces
# starting to overlap within it meet at once (a corner, AXIS_XY), a pass overlapping for less
# than it grazes. Far below anything visible, far above float rounding of pixel coordinates.
TIE_PX = 1e-9


# --- boxes -----------------------------------------------------------------------------------


@njit(cache=True)
def _slab(q, u, lo, hi):
    """Times (t0, t1) while lo <= q + u t <= hi; interior strictly between them.

    For u == 0: (-inf, inf) when lo < q < hi by more than TIE_PX, else (inf, -inf): sliding
    along the boundary never gives an overlap of positive length.
    """
    if u == 0.0:
        if lo + TIE_PX < q < hi - TIE_PX:
            return -INF, INF
        return INF, -INF
    t0 = (lo - q) / u
    t1 = (hi - q) / u
    if t0 > t1:
        return t1, t0
    return t0, t1


@njit(cache=True)
def box_sweep(qx, qy, ux, uy, wa, ha, wb, hb):
    """Box A (wa×ha) and box B (wb×hb) on the line q + u t: (t_enter, t_exit, code, nx, ny).

    Overlap of positive area exactly for t_enter < t < t_exit (relative seconds, may be ±inf;
    t_enter >= t_exit when it never happens). The contact axis is the one whose overlap starts last;
    AXIS_XY when both start together. "Together" and "positive" are up to TIE_PX of travel, so
    that a corner hit or a grazing pass that is exact in the scene's numbers stays one after
    rounding.
    """
    x0, x1 = _slab(qx, ux, -wb, wa)
    y0, y1 = _slab(qy, uy, -hb, ha)
    t_enter = max(x0, y0)
    t_exit = min(x1, y1)
    tie = TIE_PX / max(abs(ux), abs(uy), 1e-300)
    if t_exit - t_enter <= tie:
        t_exit = t_enter  # grazing: no overlap of positive length
    sx = 1.0 if ux < 0.0 else -1.0
    sy = 1.0 if uy < 0.0 else -1.0
    if abs(x0 - y0) <= tie:
        return t_enter, t_exit, AXIS_XY, sx, sy
    if x0 > y0:
        return t_enter, t_exit, AXIS_X, sx, 0.0
    return t_enter, t_exit, AXIS_Y, 0.0, sy


@njit(cache=True, inline="always")
def axis_reach(q, u, lo, hi, dt):
    """`box_reach` on one axis: False when on this axis the boxes are apart (q, B's position
    less A's, outside [lo, hi]) and not closing at the relative speed u, or too far apart to
    close the gap in dt s. Only comparisons joined by `&` and `|`, no choice between two numbers
    (`x if c else y`, which may compile to a branch): the test runs on every candidate pair, most
    of them far apart, where a branch that goes either way at random costs more than the
    arithmetic."""
    above_ok = (not q > hi) | ((-u > 0.0) & (not (q - hi > -u * dt)))
    below_ok = (not q < lo) | ((u > 0.0) & (not (lo - q > u * dt)))
    return above_ok & below_ok


@njit(cache=True, inline="always")
def box_reach(qx, qy, ux, uy, wa, ha, wb, hb, dt):
    """False when boxes A and B (any shapes inside them) surely cannot touch within dt seconds:
    on some axis they are apart and not closing, or too far apart to close the gap in time. A
    cheap filter before a sweep; True does not promise a contact."""
    return axis_reach(qx, ux, -wb, wa, dt) & axis_reach(qy, uy, -hb, ha, dt)


@njit(cache=True)
def box_penetration(qx, qy, wa, ha, wb, hb):
    """Minimum-penetration contact of two boxes: (depth, code, nx, ny).

    depth > 0 when they overlap with positive area: the smallest push along ±x or ±y that parts
    them (M's nearest face). The normal points from A to B; equal depths give AXIS_XY.
    """
    right = wa - qx  # B pushed along +x
    left = qx + wb  # B pushed along -x
    down = ha - qy
    up = qy + hb
    dx, sx = (right, 1.0) if right <= left else (left, -1.0)
    dy, sy = (down, 1.0) if down <= up else (up, -1.0)
    if dx < dy:
        return dx, AXIS_X, sx, 0.0
    if dy < dx:
        return dy, AXIS_Y, 0.0, sy
    return dx, AXIS_XY, sx, sy


# --- classifying a normal ---------------------------------------------------------------------


@njit(cache=True)
def classify(nx, ny):
    """(code, nx, ny) of a unit normal: AXIS_X / AXIS_Y when axis-aligned, else AXIS_NORMAL."""
    if ny == 0.0:
        return AXIS_X, (1.0 if nx > 0.0 else -1.0), 0.0
    if nx == 0.0:
        return AXIS_Y, 0.0, (1.0 if ny > 0.0 else -1.0)
    return AXIS_NORMAL, nx, ny


@njit(cache=True)
def _combine(n1x, n1y, n2x, n2y, distinct):
    """The contact of one face (distinct False) or a vertex where faces n1 and n2 meet."""
    if not distinct:
        return classify(n1x, n1y)
    if (n1y == 0.0 and n2x == 0.0) or (n1x == 0.0 and n2y == 0.0):
        sx = n1x + n2x
        sy = n1y + n2y
        return AXIS_XY, (1.0 if sx > 0.0 else -1.0), (1.0 if sy > 0.0 else -1.0)
    sx = n1x + n2x
    sy = n1y + n2y
    length = np.sqrt(sx * sx + sy * sy)
    if length < 1e-9:  # opposite faces tie (q at the very centre): take the first
        return classify(n1x, n1y)
    return classify(sx / length, sy / length)


# --- convex polygons (radius 0) ---------------------------------------------------------------


@njit(cache=True)
def _support(verts, nx, ny):
    """max over verts of n·v."""
    best = -INF
    for k in range(verts.shape[0]):
        d = nx * verts[k, 0] + ny * verts[k, 1]
        if d > best:
            best = d
    return best


@njit(cache=True)
def _face(va, na, vb, nb, f):
    """Face f of M = A ⊕ (-B): A's faces first, then B's turned around. (nx, ny, offset)."""
    if f < na.shape[0]:
        nx = na[f, 0]
        ny = na[f, 1]
    else:
        nx = -nb[f - na.shape[0], 0]
        ny = -nb[f - na.shape[0], 1]
    return nx, ny, _support(va, nx, ny) + _support(vb, -nx, -ny)


@njit(cache=True)
def polygon_sweep(va, na, vb, nb, qx, qy, ux, uy):
    """Two convex polygons (vertices and outward unit normals, relative to their corners) on the
    line q + u t: (t_enter, t_exit, code, nx, ny), by Cyrus–Beck clipping against M's faces.

    M's faces are A's faces and B's faces turned around (separating axes). Overlap of positive
    area exactly for t_enter < t < t_exit; the normal is that of the face the line enters by, or
    of the vertex where two faces are entered within TIE_PX of travel of each other.
    """
    t_enter = -INF
    t_exit = INF
    n1x = n1y = 0.0
    for f in range(na.shape[0] + nb.shape[0]):
        nx, ny, c = _face(va, na, vb, nb, f)
        s0 = nx * qx + ny * qy - c  # signed distance of q outside this face
        d = nx * ux + ny * uy
        if d == 0.0:
            if s0 >= -TIE_PX:  # outside, or sliding along this face
                return INF, -INF, AXIS_X, 1.0, 0.0
            continue
        t = -s0 / d
        if d < 0.0:
            if t > t_enter:
                t_enter = t
                n1x, n1y = nx, ny
        elif t < t_exit:
            t_exit = t
    tie = TIE_PX / max(abs(ux), abs(uy), 1e-300)
    if t_exit - t_enter <= tie:
        t_exit = t_enter  # grazing: no overlap of positive length
    # A second face entered at (nearly) the same time, in another direction: a vertex.
    n2x = n2y = 0.0
    distinct = False
    for f in range(na.shape[0] + nb.shape[0]):
        nx, ny, c = _face(va, na, vb, nb, f)
        d = nx * ux + ny * uy
        if d < 0.0 and nx * n1x + ny * n1y < SAME_DIRECTION:
            if abs((nx * qx + ny * qy - c) / -d - t_enter) <= tie:
                n2x, n2y, distinct = nx, ny, True
                break
    code, cx, cy = _combine(n1x, n1y, n2x, n2y, distinct)
    return t_enter, t_exit, code, cx, cy


@njit(cache=True)
def polygon_penetration(va, na, vb, nb, qx, qy):
    """Minimum-penetration contact of two convex polygons: (depth, code, nx, ny).

    depth > 0 when they overlap with positive area: minus the largest signed face distance of q
    in M (the separating axis of least overlap), whose normal is the contact normal.
    """
    best = -INF
    n1x = n1y = n2x = n2y = 0.0
    distinct = False
    for f in range(na.shape[0] + nb.shape[0]):
        nx, ny, c = _face(va, na, vb, nb, f)
        s = nx * qx + ny * qy - c
        if s > best:
            best = s
            n1x, n1y, distinct = nx, ny, False
        elif s == best and not distinct and nx * n1x + ny * n1y < SAME_DIRECTION:
            n2x, n2y, distinct = nx, ny, True
    code, cx, cy = _combine(n1x, n1y, n2x, n2y, distinct)
    return -best, code, cx, cy


# --- rounded polygons: a circle against anything ----------------------------------------------


@njit(cache=True)
def disc_roots(px, py, r, qx, qy, ux, uy):
    """Times (t1, t2), t1 < t2, when |q + u t - p| = r; (inf, -inf) when the line misses the disc
    or only grazes it. Numerically stable form of the quadratic."""
    dx = qx - px
    dy = qy - py
    a = ux * ux + uy * uy
    b = dx * ux + dy * uy
    c = dx * dx + dy * dy - r * r
    disc = b * b - a * c
    if a == 0.0 or disc <= 0.0:
        return INF, -INF
    root = np.sqrt(disc)
    h = -(b + root) if b >= 0.0 else -(b - root)
    t1 = h / a
    t2 = c / h
    if t1 > t2:
        return t2, t1
    return t1, t2


@njit(cache=True)
def _vertex(core, s, cx, cy, k):
    """Vertex k of the polygon P = c + s·core (s = ±1)."""
    return cx + s * core[k, 0], cy + s * core[k, 1]


@njit(cache=True)
def rounded_sweep(core, cnorm, s, cx, cy, r, qx, qy, ux, uy):
    """The line q + u t against M = P ⊕ disc(r), P = c + s·core a convex polygon (s = ±1 keeps
    its vertex order positive; a point rotated by pi). (t_enter, t_exit, code, nx, ny).

    P grown by r is clipped by Cyrus–Beck against P's faces pushed out by r; where the line crosses
    such a face beyond the face's own extent it is in a corner pocket, and the true crossing is
    on the disc of radius r around that corner (or nowhere: outside M but inside the grown polygon
    lie only the corner pockets, and a line that enters one and misses its disc leaves the grown
    polygon, which is convex, for good).
    """
    h = core.shape[0]
    if h == 1:
        px, py = _vertex(core, s, cx, cy, 0)
        t1, t2 = disc_roots(px, py, r, qx, qy, ux, uy)
        if t2 - t1 <= TIE_PX / max(abs(ux), abs(uy), 1e-300):
            return INF, -INF, AXIS_X, 1.0, 0.0  # missed, or grazed
        nx = qx + ux * t1 - px
        ny = qy + uy * t1 - py
        length = np.sqrt(nx * nx + ny * ny)
        code, nx, ny = classify(nx / length, ny / length)
        return t1, t2, code, nx, ny
    t_enter = -INF
    t_exit = INF
    f_enter = -1
    f_exit = -1
    for k in range(h):
        nx = s * cnorm[k, 0]
        ny = s * cnorm[k, 1]
        vx, vy = _vertex(core, s, cx, cy, k)
        s0 = nx * (qx - vx) + ny * (qy - vy) - r
        d = nx * ux + ny * uy
        if d == 0.0:
            if s0 >= -TIE_PX:  # outside, or sliding along this face
                return INF, -INF, AXIS_X, 1.0, 0.0
            continue
        t = -s0 / d
        if d < 0.0:
            if t > t_enter:
                t_enter = t
                f_enter = k
        elif t < t_exit:
            t_exit = t
            f_exit = k
    if not t_enter < t_exit:
        return INF, -INF, AXIS_X, 1.0, 0.0
    # Entry: on face f_enter's own extent, or on a corner disc.
    corner = _pocket(core, s, cx, cy, f_enter, qx + ux * t_enter, qy + uy * t_enter)
    if corner < 0:
        code, nx, ny = classify(s * cnorm[f_enter, 0], s * cnorm[f_enter, 1])
    else:
        px, py = _vertex(core, s, cx, cy, corner)
        t1, t2 = disc_roots(px, py, r, qx, qy, ux, uy)
        if t1 >= t2:
            return INF, -INF, AXIS_X, 1.0, 0.0
        t_enter = t1
        nx = qx + ux * t1 - px
        ny = qy + uy * t1 - py
        length = np.sqrt(nx * nx + ny * ny)
        code, nx, ny = classify(nx / length, ny / length)
    corner = _pocket(core, s, cx, cy, f_exit, qx + ux * t_exit, qy + uy * t_exit)
    if corner >= 0:
        px, py = _vertex(core, s, cx, cy, corner)
        t1, t2 = disc_roots(px, py, r, qx, qy, ux, uy)
        t_exit = t2 if t1 < t2 else t_enter
    if t_exit - t_enter <= TIE_PX / max(abs(ux), abs(uy), 1e-300):
        t_exit = t_enter  # grazing: no overlap of positive length
    return t_enter, t_exit, code, nx, ny


@njit(cache=True)
def _pocket(core, s, cx, cy, f, ex, ey):
    """Which corner pocket the point e on face f's pushed-out line is in: -1 when it lies within
    the face's own extent, else the vertex of P nearest to e (whose disc bounds that pocket)."""
    h = core.shape[0]
    ax, ay = _vertex(core, s, cx, cy, f)
    bx, by = _vertex(core, s, cx, cy, (f + 1) % h)
    tx = bx - ax
    ty = by - ay
    lam = ((ex - ax) * tx + (ey - ay) * ty) / (tx * tx + ty * ty)
    if 0.0 <= lam <= 1.0:
        return -1
    best = INF
    nearest = f
    for k in range(h):
        vx, vy = _vertex(core, s, cx, cy, k)
        d2 = (ex - vx) ** 2 + (ey - vy) ** 2
        if d2 < best:
            best = d2
            nearest = k
    return nearest


@njit(cache=True)
def rounded_penetration(core, cnorm, s, cx, cy, r, qx, qy):
    """Minimum-penetration contact of q in M = P ⊕ disc(r): (depth, code, nx, ny); depth > 0
    inside. Outside P, the normal runs from P's nearest point to q; inside P, it is the nearest
    face's normal."""
    h = core.shape[0]
    if h == 1:
        px, py = _vertex(core, s, cx, cy, 0)
        dx = qx - px
        dy = qy - py
        dist = np.sqrt(dx * dx + dy * dy)
        if dist == 0.0:
            return r, AXIS_X, 1.0, 0.0
        code, nx, ny = classify(dx / dist, dy / dist)
        return r - dist, code, nx, ny
    best = -INF
    f_best = 0
    for k in range(h):
        vx, vy = _vertex(core, s, cx, cy, k)
        sk = s * cnorm[k, 0] * (qx - vx) + s * cnorm[k, 1] * (qy - vy)
        if sk > best:
            best = sk
            f_best = k
    if best <= 0.0:
        code, nx, ny = classify(s * cnorm[f_best, 0], s * cnorm[f_best, 1])
        return r - best, code, nx, ny
    # Outside P: nearest point on P's boundary.
    dist2 = INF
    bx = by = 0.0
    for k in range(h):
        ax, ay = _vertex(core, s, cx, cy, k)
        ex, ey = _vertex(core, s, cx, cy, (k + 1) % h)
        tx = ex - ax
        ty = ey - ay
        lam = ((qx - ax) * tx + (qy - ay) * ty) / (tx * tx + ty * ty)
        lam = min(max(lam, 0.0), 1.0)
        px = ax + lam * tx
        py = ay + lam * ty
        d2 = (qx - px) ** 2 + (qy - py) ** 2
        if d2 < dist2:
            dist2 = d2
            bx, by = px, py
    dist = np.sqrt(dist2)
    code, nx, ny = classify((qx - bx) / dist, (qy - by) / dist)
    return r - dist, code, nx, ny


# --- any pair ---------------------------------------------------------------------------------
# A pair's shapes are passed as (kind, w, h, r, core, cnorm) for each object: the shape kind from
# shapes.Cores, the box size (px), the radius (px) and the core's vertices and unit normals
# (relative to the object's top-left corner). Box pairs need no arrays: see box_next_contact.


@njit(cache=True)
def _rounded_frame(ka, ra, va, na, rb, vb, nb):
    """For a pair with at least one circle: M = c + s·core ⊕ disc(r). Returns
    (core, cnorm, s, cx, cy, r): P's core is the non-circle's (or B's for two circles)."""
    if ka == KIND_CIRCLE:
        # M = {centre_A} ⊕ (-core_B) ⊕ disc(r_A + r_B)
        return vb, nb, -1.0, va[0, 0], va[0, 1], ra + rb
    # M = core_A ⊕ {-centre_B} ⊕ disc(r_B)
    return va, na, 1.0, -vb[0, 0], -vb[0, 1], rb


@njit(cache=True)
def sweep(qx, qy, ux, uy, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb):
    """A and B on the line q + u t: (t_enter, t_exit, code, nx, ny).

    Overlap of positive area exactly for t_enter < t < t_exit (relative seconds); the contact at
    t_enter has normal n from A to B.
    """
    if ka == KIND_BOX and kb == KIND_BOX:
        return box_sweep(qx, qy, ux, uy, wa, ha, wb, hb)
    if ka == KIND_CIRCLE or kb == KIND_CIRCLE:
        core, cnorm, s, cx, cy, r = _rounded_frame(ka, ra, va, na, rb, vb, nb)
        return rounded_sweep(core, cnorm, s, cx, cy, r, qx, qy, ux, uy)
    return polygon_sweep(va, na, vb, nb, qx, qy, ux, uy)


@njit(cache=True)
def penetration(qx, qy, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb):
    """Minimum-penetration contact of A and B at offset q: (depth, code, nx, ny).

    depth > 0 exactly when their shapes overlap with positive area; the normal runs from A to B.
    """
    if ka == KIND_BOX and kb == KIND_BOX:
        return box_penetration(qx, qy, wa, ha, wb, hb)
    if ka == KIND_CIRCLE or kb == KIND_CIRCLE:
        core, cnorm, s, cx, cy, r = _rounded_frame(ka, ra, va, na, rb, vb, nb)
        return rounded_penetration(core, cnorm, s, cx, cy, r, qx, qy)
    return polygon_penetration(va, na, vb, nb, qx, qy)


@njit(cache=True)
def approaching(code, nx, ny, ux, uy):
    """True when B closes on A along the contact normal (u = v_B - v_A); for AXIS_XY, along
    either axis."""
    if code == AXIS_XY:
        return ux * nx < 0.0 or uy * ny < 0.0
    return ux * nx + uy * ny < 0.0


@njit(cache=True, inline="always")
def _decide(t_enter, t_exit, now):
    """The exact model's rules on a sweep, at time `now` on the same clock: 1 = contact at
    t_enter (>= now: touching now included), 0 = none (never, or already leaving), -1 =
    overlapping now: ask whether they approach."""
    if not t_enter < t_exit or t_exit <= now:
        return 0
    if t_enter >= now:
        return 1
    return -1


@njit(cache=True, inline="always")
def box_next_contact(qx, qy, ux, uy, wa, ha, wb, hb, now=0.0):
    """next_contact for two boxes, on scalars alone."""
    t_enter, t_exit, code, nx, ny = box_sweep(qx, qy, ux, uy, wa, ha, wb, hb)
    rule = _decide(t_enter, t_exit, now)
    if rule == 1:
        return t_enter, code, nx, ny
    if rule == -1:
        depth, code, nx, ny = box_penetration(qx + ux * now, qy + uy * now, wa, ha, wb, hb)
        if approaching(code, nx, ny, ux, uy):
            return now, code, nx, ny
    return INF, code, nx, ny


@njit(cache=True)
def next_contact(qx, qy, ux, uy, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb, now=0.0):
    """The exact model's next contact of A and B: (t, code, nx, ny), inf when none.

    q is the offset at time 0 of the pair's own clock, `now` the present on that clock (s); the
    contact time t is on the same clock, never before now. (Predicting from the time the pair was
    last changed, rather than from now, keeps the answer free of when it is asked.) Robust
    rules: touching or overlapping and approaching collide now; overlapping and separating give
    nothing (the line leaves M and, M being convex, never comes back).
    """
    t_enter, t_exit, code, nx, ny = sweep(
        qx, qy, ux, uy, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb
    )
    rule = _decide(t_enter, t_exit, now)
    if rule == 1:
        return t_enter, code, nx, ny
    if rule == -1:
        qx += ux * now
        qy += uy * now
        depth, code, nx, ny = penetration(qx, qy, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb)
        if approaching(code, nx, ny, ux, uy):
            return now, code, nx, ny
    return INF, code, nx, ny
