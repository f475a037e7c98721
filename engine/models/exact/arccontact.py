"""Contact on a curved relative path: the next contact of two shapes one of which falls and the
other does not (docs/models.md#exact-under-gravity).

Input: as contact.next_contact (two shapes, the offset q of B's corner from A's at the pair's
clock 0, the relative velocity u, the present `now` on that clock), and the relative acceleration
a != 0 (px/s²): B falls while A stands (a static object), or the other way round. The relative path
is then the parabola `q + u·t + ½·a·t²` in the plane of the Minkowski difference M = A ⊕ (-B)
(contact.py), and the next contact is the first instant at or after `now` at which it reaches M
moving in. Output: (t, code, nx, ny) as contact.next_contact gives it, t = inf when none.

Polygons and boxes (M a convex polygon): M is the intersection of its faces' half-planes
`n·q <= c`, and on the parabola each face's distance `s(t) = n·q(t) - c` is a quadratic. From
t = now, every face the point is outside of (or on and leaving) is next entered at its own root
(parabola.meet, cancellation-free); none can be inside M before the latest of those roots, so the
search moves there and looks again, until every face holds (the contact: the normal is the face
entered last, a corner when another is met within TIE_PX) or a face is never entered again (no
contact). A face holds over at most two spans of time, so a few rounds end it.

A circle involved (M = P ⊕ disc(r), P a convex polygon or a point): M's boundary is P's faces
pushed out by r, each over its own extent, and an arc of radius r at each corner. The contact is
the earliest instant at or after now at which the parabola crosses it inward: a face's root (a
quadratic) where q(t) lies within that face's extent, or a corner's root, where |q(t) - v| = r: a
quartic, whose roots are isolated between those of its derivatives and each found by bisection
to the last bit, where q(t) lies in that corner's pocket.

Touching or overlapping now and approaching along the normal of least penetration, or meeting
with no speed along it while the acceleration presses them together, collide now (the model then
stops the run: a body would rest on the other); leaving, the search goes on from the moment the
path leaves, since on a parabola it may come back (a ball bouncing on a static box's top).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from collide2d.engine.contact import (
    SAME_DIRECTION,
    TIE_PX,
    _combine,
    _face,
    _pocket,
    _rounded_frame,
    _vertex,
    approaching,
    classify,
    polygon_penetration,
    rounded_penetration,
)
from collide2d.engine.events import AXIS_X
from collide2d.engine.jit import njit
from collide2d.engine.parabola import meet
from collide2d.engine.world import KIND_CIRCLE

INF = np.inf
NONE = (INF, AXIS_X, 1.0, 0.0)


class Arc(NamedTuple):
    """A pair's relative path at the pair's clock 0: B's corner less A's (px), and B's velocity
    (px/s) and acceleration (px/s²) less A's."""

    qx: float
    qy: float
    ux: float
    uy: float
    ax: float
    ay: float


class Core(NamedTuple):
    """One object's exact shape as contact.py takes it: kind, radius (px), the core's vertices and
    unit normals (relative to the object's corner)."""

    kind: int
    radius: float
    verts: np.ndarray
    normals: np.ndarray


# Bisection steps at most for one root (each halves the bracket; float64 needs fewer than 1,100).
BISECTIONS = 1200


@njit(cache=True, inline="always")
def _holds(s, ds, k):
    """A face's half-plane holds the point at this instant: inside by more than TIE_PX, or on the
    face (within it) and not leaving it."""
    if s < -TIE_PX:
        return True
    if s > TIE_PX:
        return False
    return ds < 0.0 or (ds == 0.0 and k < 0.0)


@njit(cache=True, inline="always")
def _pressing(code, nx, ny, vx, vy, ax, ay):
    """Touching or overlapping, B approaches A along the normal, or meets it with no speed while
    the acceleration presses them together (a contact now, that the model answers)."""
    if approaching(code, nx, ny, vx, vy):
        return True
    return not approaching(code, nx, ny, -vx, -vy) and approaching(code, nx, ny, ax, ay)


@njit(cache=True, inline="always")
def _entry(s, ds, k):
    """Seconds until a face's distance s (rate ds, acceleration k) next crosses 0 inward: at once
    when on it and entering; after leaving and coming back when inside now; inf when never."""
    if s > 0.0 or (s == 0.0 and (ds > 0.0 or (ds == 0.0 and k >= 0.0))):
        return meet(max(s, 0.0), ds, k)
    out = meet(-s, -ds, -k)  # inside: it leaves first
    if out == INF:
        return INF
    return out + meet(0.0, ds + k * out, k)


@njit(cache=True)
def polygon_arc(va, na, vb, nb, path, now):
    """Two convex polygons on the parabola q + u t + ½ a t² (`path`, an Arc): the next contact at
    or after now (module docstring)."""
    qx, qy, ux, uy = path.qx, path.qy, path.ux, path.uy
    ax, ay = path.ax, path.ay
    nf = na.shape[0] + nb.shape[0]
    t = now
    last = -1
    for _ in range(4 * nf + 4):
        px = qx + t * (ux + 0.5 * ax * t)
        py = qy + t * (uy + 0.5 * ay * t)
        vx = ux + ax * t
        vy = uy + ay * t
        later = t
        late = -1
        for f in range(nf):
            nx, ny, c = _face(va, na, vb, nb, f)
            s = nx * px + ny * py - c
            ds = nx * vx + ny * vy
            k = nx * ax + ny * ay
            if _holds(s, ds, k):
                continue
            r = meet(max(s, 0.0), ds, k)
            if r == INF:
                return NONE
            if t + r > later or late < 0:
                later = t + r
                late = f
        if late < 0:
            if last >= 0:
                return _entered(va, na, vb, nb, last, px, py, vx, vy, t)
            # every face holds at `now`: touching or overlapping now
            depth, code, nx, ny = polygon_penetration(va, na, vb, nb, px, py)
            if _pressing(code, nx, ny, vx, vy, ax, ay):
                return t, code, nx, ny
            t = t + _exit(va, na, vb, nb, px, py, vx, vy, ax, ay)
            if t == INF:
                return NONE
            continue
        t = later
        last = late
    return NONE


@njit(cache=True)
def _exit(va, na, vb, nb, px, py, vx, vy, ax, ay):
    """Seconds until the point, inside every face, first leaves one; inf when never."""
    first = INF
    for f in range(na.shape[0] + nb.shape[0]):
        nx, ny, c = _face(va, na, vb, nb, f)
        s = nx * px + ny * py - c
        first = min(first, meet(max(-s, 0.0), -(nx * vx + ny * vy), -(nx * ax + ny * ay)))
    return first


@njit(cache=True)
def _entered(va, na, vb, nb, f, px, py, vx, vy, t):
    """The contact at t through face f, or at a corner when another face is met there too."""
    n1x, n1y, _ = _face(va, na, vb, nb, f)
    n2x = n2y = 0.0
    distinct = False
    for g in range(na.shape[0] + nb.shape[0]):
        nx, ny, c = _face(va, na, vb, nb, g)
        s = nx * px + ny * py - c
        if abs(s) <= TIE_PX and nx * vx + ny * vy < 0.0 and nx * n1x + ny * n1y < SAME_DIRECTION:
            n2x, n2y, distinct = nx, ny, True
            break
    code, cx, cy = _combine(n1x, n1y, n2x, n2y, distinct)
    return t, code, cx, cy


# --- a circle involved -----------------------------------------------------------------------


@njit(cache=True, inline="always")
def _poly(c4, c3, c2, c1, c0, t):
    return (((c4 * t + c3) * t + c2) * t + c1) * t + c0


@njit(cache=True)
def _bisect(c4, c3, c2, c1, c0, lo, hi):
    """The root of a polynomial of one sign at lo and the other at hi, to the last bit."""
    f_lo = _poly(c4, c3, c2, c1, c0, lo)
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            break
        f_mid = _poly(c4, c3, c2, c1, c0, mid)
        if (f_mid > 0.0) == (f_lo > 0.0):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    return hi


@njit(cache=True)
def _cubic_root_in(d3, d2, d1, d0, lo, hi):
    """A root of the cubic in [lo, hi] where it changes sign (monotone there), or -1."""
    f_lo = _poly(0.0, d3, d2, d1, d0, lo)
    f_hi = _poly(0.0, d3, d2, d1, d0, hi)
    if (f_lo > 0.0) == (f_hi > 0.0) or f_lo == 0.0:
        return lo if f_lo == 0.0 else -1.0
    return _bisect(0.0, d3, d2, d1, d0, lo, hi)


@njit(cache=True)
def quartic_entry(c4, c3, c2, c1, c0):
    """The first t >= 0 at which c4 t⁴ + ... + c0 (c4 > 0) crosses from above 0 to 0 or below;
    inf when never. Its derivative's roots cut [0, bound] into spans where it is monotone (they
    are found the same way, between the roots of the second derivative, a quadratic)."""
    scale = max(abs(c3), abs(c2), abs(c1), abs(c0)) / c4
    bound = 1.0 + max(scale, 1.0) * 4.0
    # roots of p'' = 12 c4 t² + 6 c3 t + 2 c2 in (0, bound)
    e2, e1, e0 = 12.0 * c4, 6.0 * c3, 2.0 * c2
    z1 = z2 = bound
    disc = e1 * e1 - 4.0 * e2 * e0
    if disc >= 0.0:
        h = -0.5 * (e1 + math.copysign(math.sqrt(disc), e1))
        r1 = h / e2
        r2 = e0 / h if h != 0.0 else r1
        z1, z2 = min(max(min(r1, r2), 0.0), bound), min(max(max(r1, r2), 0.0), bound)
    # roots of p' = 4 c4 t³ + 3 c3 t² + 2 c2 t + c1 in each monotone span
    d3, d2, d1, d0 = 4.0 * c4, 3.0 * c3, 2.0 * c2, c1
    cuts0 = _cubic_root_in(d3, d2, d1, d0, 0.0, z1)
    cuts1 = _cubic_root_in(d3, d2, d1, d0, z1, z2)
    cuts2 = _cubic_root_in(d3, d2, d1, d0, z2, bound)
    lo = 0.0
    for cut in (cuts0, cuts1, cuts2, bound):
        if cut < lo:
            continue
        if _poly(c4, c3, c2, c1, c0, lo) > 0.0 and _poly(c4, c3, c2, c1, c0, cut) <= 0.0:
            return _bisect(c4, c3, c2, c1, c0, lo, cut)
        lo = cut
    return INF


@njit(cache=True)
def _corner_entry(vx, vy, px, py, ux, uy, ax, ay, r):
    """Seconds until the parabola p + u t + ½ a t² comes within r of the point v, moving in."""
    dx = px - vx
    dy = py - vy
    c4 = 0.25 * (ax * ax + ay * ay)
    c3 = ux * ax + uy * ay
    c2 = ux * ux + uy * uy + dx * ax + dy * ay
    c1 = 2.0 * (dx * ux + dy * uy)
    c0 = dx * dx + dy * dy - r * r
    return quartic_entry(c4, c3, c2, c1, c0)


@njit(cache=True)
def _in_pocket(core, s, cx, cy, k, ex, ey):
    """Whether the point e lies in the corner pocket of vertex k (outside both faces' extents)."""
    h = core.shape[0]
    if h == 1:
        return True
    vx, vy = _vertex(core, s, cx, cy, k)
    px, py = _vertex(core, s, cx, cy, (k - 1) % h)
    nx, ny = _vertex(core, s, cx, cy, (k + 1) % h)
    dx = ex - vx
    dy = ey - vy
    return dx * (vx - px) + dy * (vy - py) >= 0.0 and dx * (nx - vx) + dy * (ny - vy) <= 0.0


@njit(cache=True)
def rounded_arc(core, cnorm, s, cx, cy, r, path, now):
    """M = P ⊕ disc(r) (contact.rounded_sweep's frame) against the parabola `path` (an Arc): the
    next contact at or after now (module docstring)."""
    qx, qy, ux, uy = path.qx, path.qy, path.ux, path.uy
    ax, ay = path.ax, path.ay
    px = qx + now * (ux + 0.5 * ax * now)
    py = qy + now * (uy + 0.5 * ay * now)
    vx = ux + ax * now
    vy = uy + ay * now
    depth, code, nx, ny = rounded_penetration(core, cnorm, s, cx, cy, r, px, py)
    if depth >= -TIE_PX and _pressing(code, nx, ny, vx, vy, ax, ay):
        return now, code, nx, ny
    h = core.shape[0]
    best = INF
    bx = by = 0.0
    if h > 1:
        for f in range(h):
            fx = s * cnorm[f, 0]
            fy = s * cnorm[f, 1]
            wx, wy = _vertex(core, s, cx, cy, f)
            d = _entry(fx * (px - wx) + fy * (py - wy) - r, fx * vx + fy * vy, fx * ax + fy * ay)
            if d < best:
                ex = px + d * (vx + 0.5 * ax * d)
                ey = py + d * (vy + 0.5 * ay * d)
                if _pocket(core, s, cx, cy, f, ex, ey) < 0:
                    best, bx, by = d, fx, fy
    for k in range(h):
        wx, wy = _vertex(core, s, cx, cy, k)
        d = _corner_entry(wx, wy, px, py, vx, vy, ax, ay, r)
        if d < best:
            ex = px + d * (vx + 0.5 * ax * d)
            ey = py + d * (vy + 0.5 * ay * d)
            if _in_pocket(core, s, cx, cy, k, ex, ey):
                length = math.sqrt((ex - wx) ** 2 + (ey - wy) ** 2)
                best, bx, by = d, (ex - wx) / length, (ey - wy) / length
    if best == INF:
        return NONE
    code, bx, by = classify(bx, by)
    return now + best, code, bx, by


@njit(cache=True)
def arc_contact(path, A, B, now):
    """The exact model's next contact of A and B (Cores; a box is its 4-vertex polygon) on the
    curved relative path `path` (an Arc): (t, code, nx, ny), t = inf when none (module
    docstring)."""
    if A.kind == KIND_CIRCLE or B.kind == KIND_CIRCLE:
        core, cnorm, s, cx, cy, r = _rounded_frame(
            A.kind, A.radius, A.verts, A.normals, B.radius, B.verts, B.normals
        )
        return rounded_arc(core, cnorm, s, cx, cy, r, path, now)
    return polygon_arc(A.verts, A.normals, B.verts, B.normals, path, now)
