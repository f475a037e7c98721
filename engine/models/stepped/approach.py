"""The stepped model's contact after a step (docs/models.md#stepped-contact-normal-and-push): its
normal from the direction of approach.

A step of dt seconds ends with B's corner at offset q from A's, moving at u relative to A. The pair
is swept back along u to where it was dt ago (`contact.box_sweep`, `contact.sweep`): when its
shapes started overlapping within the step (or cut a corner of each other within it,
`box_clip`), the normal is the one where the line entered and the push twice the depth gone in
since that instant, so each object ends where a bounce at the contact instant would have put it.
When the motion cannot tell, the overlap decides (`box_overlap_axis` for boxes, the
minimum-penetration contact for exact shapes). The geometry itself is engine/contact.py's.
"""

from __future__ import annotations

from collide2d.engine.contact import TIE_PX, _slab, box_sweep, penetration, sweep
from collide2d.engine.events import AXIS_X, AXIS_XY, AXIS_Y
from collide2d.engine.jit import njit


@njit(cache=True)
def box_clip(qx, qy, ux, uy, wa, ha, wb, hb, dt):
    """Whether boxes A and B, at offset q - u dt when a step of dt seconds began and q at its end,
    cut a corner of each other within the step: their overlap (of positive length, beyond TIE_PX
    of travel) began and ended within it, and it left by the other axis than it came in by. A
    pair that passes wholly through the other along one axis within a step is no clip: that is
    tunnelling, the stepped model's own (docs/models.md#stepped-pairs)."""
    x0, x1 = _slab(qx - ux * dt, ux, -wb, wa)
    y0, y1 = _slab(qy - uy * dt, uy, -hb, ha)
    t_enter = max(x0, y0)
    t_exit = min(x1, y1)
    if not (0.0 <= t_enter < dt and t_exit <= dt):
        return False
    if t_exit - t_enter <= TIE_PX / max(abs(ux), abs(uy), 1e-300):
        return False
    return (x0 >= y0) != (x1 < y1)


@njit(cache=True)
def box_overlap_axis(qx, qy, wa, ha, wb, hb):
    """The stepped model's box contact when the motion cannot tell
    (docs/models.md#stepped-contact-normal-and-push; box_step_contact): (depth, depth_y, code, nx,
    ny).

    The axis is that of the smaller overlap width (the paper's xdiff/ydiff; both on a tie, AXIS_XY).
    depth is the push along the normal that parts the boxes (for AXIS_XY the push along x, and
    depth_y the push along y); the normal points from A to B. depth 0 when they do not overlap.
    """
    xdiff = min(wa, qx + wb) - max(0.0, qx)
    ydiff = min(ha, qy + hb) - max(0.0, qy)
    if xdiff <= 0.0 or ydiff <= 0.0:
        return 0.0, 0.0, AXIS_X, 1.0, 0.0
    right = wa - qx
    left = qx + wb
    down = ha - qy
    up = qy + hb
    dx, sx = (right, 1.0) if right <= left else (left, -1.0)
    dy, sy = (down, 1.0) if down <= up else (up, -1.0)
    if abs(xdiff - ydiff) <= TIE_PX:
        return dx, dy, AXIS_XY, sx, sy
    if xdiff < ydiff:
        return dx, 0.0, AXIS_X, sx, 0.0
    return dy, 0.0, AXIS_Y, 0.0, sy


@njit(cache=True)
def box_step_contact(qx, qy, ux, uy, wa, ha, wb, hb, dt):
    """The stepped model's box contact over a step of dt seconds that ends at offset q
    (docs/models.md#stepped-contact-normal-and-push): (push, push_y, code, nx, ny); push 0 when
    there is none.

    The pair is swept back along its relative velocity u to where it was dt ago (box_sweep). When
    its boxes started overlapping during this step or the one before (they overlap now, or cut a
    corner of each other within the step, box_clip), the normal is the axis whose overlap
    started last, its sign the side B came in from (AXIS_XY when both started within TIE_PX of
    travel), and push is twice the depth gone in along it since that instant: pushed apart that far
    (shared by inverse mass), each object ends where a bounce at the contact instant would have put
    it, as a wall reflects. For AXIS_XY push is along x and push_y along y. (A corner cut went in,
    and came out again, for the time since its contact: the push is twice that travel.) When the
    motion cannot tell (the overlap began before the previous step, or they do not move),
    box_overlap_axis decides: the smaller overlap width, pushed apart by its depth once.
    """
    xdiff = min(wa, qx + wb) - max(0.0, qx)
    ydiff = min(ha, qy + hb) - max(0.0, qy)
    now = xdiff > 0.0 and ydiff > 0.0
    if not now and not box_clip(qx, qy, ux, uy, wa, ha, wb, hb, dt):
        return 0.0, 0.0, AXIS_X, 1.0, 0.0
    t_enter, _, code, nx, ny = box_sweep(qx - ux * dt, qy - uy * dt, ux, uy, wa, ha, wb, hb)
    if not t_enter >= -dt - TIE_PX / max(abs(ux), abs(uy), 1e-300):  # -inf too
        return box_overlap_axis(qx, qy, wa, ha, wb, hb)
    if now:  # the depth on the side it came in by
        dx = wa - qx if nx > 0.0 else qx + wb
        dy = ha - qy if ny > 0.0 else qy + hb
    else:  # a corner cut: how far it went in before it came out
        ago = dt - t_enter
        dx = abs(ux) * ago
        dy = abs(uy) * ago
    if code == AXIS_XY:
        return 2.0 * dx, 2.0 * dy, code, nx, ny
    if code == AXIS_X:
        return 2.0 * dx, 0.0, code, nx, ny
    return 2.0 * dy, 0.0, code, nx, ny


@njit(cache=True)
def step_contact(qx, qy, ux, uy, dt, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb):
    """The stepped model's contact of two exact shapes over a step of dt seconds that ends at offset
    q (docs/models.md#stepped-contact-normal-and-push): (push, push_y, code, nx, ny); push 0 when
    there is none.

    As box_step_contact: when the line q + u t swept back dt seconds enters M during the step
    (sweep), the normal is that of the direction of approach where it enters, and push is twice
    the depth gone in along it since that instant (push, push_y along x and y for AXIS_XY); when
    the shapes overlapped already as the step began, or do not move, the minimum-penetration
    contact and its depth.
    """
    depth, code, nx, ny = penetration(qx, qy, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb)
    t_enter, t_exit, c, cx, cy = sweep(
        qx - ux * dt, qy - uy * dt, ux, uy, ka, wa, ha, ra, va, na, kb, wb, hb, rb, vb, nb
    )
    told = t_enter >= -dt - TIE_PX / max(abs(ux), abs(uy), 1e-300) and t_enter < dt
    if told and (depth > 0.0 or t_exit > t_enter):
        ago = dt - max(t_enter, -dt)
        if c == AXIS_XY:
            return 2.0 * abs(ux) * ago, 2.0 * abs(uy) * ago, c, cx, cy
        gone = -(ux * cx + uy * cy) * ago
        if gone > 0.0:
            return 2.0 * gone, 2.0 * gone, c, cx, cy
    if depth <= 0.0:
        return 0.0, 0.0, code, nx, ny
    return depth, depth, code, nx, ny
