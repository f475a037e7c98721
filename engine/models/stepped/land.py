"""The settling path's landing on static objects
(docs/models.md#stepped-gravity-restitution-and-friction): a body that a step's move carried far
into a static object is put back where it met it, as a wall stops a body where it meets it.

Input: the state (`records.Fall`, its `saved` holding where each object began the step), the
constants (`records.Physics`), the candidate list and the exact shapes (`records.Touch`) and the
step dt. Output: each such body moved back in place, its speed cut so that its energy does not
rise, and how many were.

The move (fall.py) meets the walls exactly but static objects not at all: the contacts after it
(touch.py) find a body inside one and the solver pushes it out by the depth past slop, within the
energy given up so far (solver.py). That holds while a step's travel is small beside the body.
A body that moves more than half its size in one step (a fall of many of its sizes under extreme
gravity, a throw at a huge speed) may go into a static object deeper than the push can take back:
the push may have no energy to spend (an elastic bounce gives up none; where the floor or a wall
stopped the move inside a static object that stands on it, the wall took the fall's speed and the
solver spends it on the parting speed), and the overlap's normal can point the wrong way. So a
body that moved so far and ends the step inside a static object past slop goes back along its
step, taken as the straight line from where it began to where the move left it:

- to the instant it met the static object's outline, when the two were apart as the step began
  (`contact.sweep`, by the boxes or by the real shapes under `geometry: exact`), and it went in
  past slop since;
- to where it began, when they overlapped already and it ended deeper in by more than slop (a
  body resting on it, or one that the pushes of the last step left in it: the move never takes it
  deeper);

the earliest of these when there are several static objects. Its speed is then cut so that its
energy does not rise: the potential energy the way back raised comes off its kinetic energy, down
to 0. (The point it goes back to lies between where it began and where it ended, so its potential
energy there is at most the larger of the two, and standing still there it has no more energy
than as the step began.) The contacts then find it touching the static object's face, or as deep
as it began, and treat it as landed there.

A body that passes wholly through a static object within one step is not found: that is the
stepped model's tunnelling (docs/models.md#stepped-pairs). Only static objects stop a body so: a
body that went far into another body, moving or asleep, is left to the contacts. A body slower
than half its size a step is left to the contacts as ever, so every scene whose bodies never
move so fast runs to the same bytes as without this stage.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.broadphase import KEY_MASK, KEY_SHIFT
from collide2d.engine.contact import box_penetration, box_sweep, penetration, sweep
from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.move import B_H, B_VX, B_VY, B_W, B_X, B_Y
from collide2d.engine.models.stepped.touch import N_KEYS, relist

# A body that moved farther than this share of its own size on an axis in one step is put back
# when it ended the step inside a static object past slop.
FAR_SHARE = 0.5
# At most this many rounds of putting back in one step (each goes back along what is left of the
# step: one more for each static object the step passed through before the one it ended in).
MAX_ROUNDS = 16


@njit(cache=True)
def land(F, P, T, keys, dt):
    """Put back each awake body that the step took far into a static object (module docstring);
    returns (the candidate list, how many bodies were put back). keys: the candidate list
    (T.counts[N_KEYS] of them), listing every pair that touches now; made anew for where the
    bodies put back now are. Where a body goes back to may lie inside another static object that
    its step passed through (the list held only those near where it ended): it then goes back
    again, to where it met that one, until it lies in none it was not in as the step began."""
    body, saved, awake = F.body, F.saved, F.awake
    n = body.shape[0]
    if not _any_far(body, saved, awake):
        return keys, 0
    far = np.zeros(n, np.bool_)
    for i in range(n):
        far[i] = awake[i] and _far(body, saved, i)
    met = np.empty(n)  # the instant each body goes back to, s into what is left of the step
    total = 0
    for _ in range(MAX_ROUNDS):
        met[:] = np.inf
        for c in range(T.counts[N_KEYS]):
            a = keys[c] >> KEY_SHIFT
            b = keys[c] & KEY_MASK
            if F.static[a] == F.static[b]:
                continue
            i, s = (b, a) if F.static[a] else (a, b)
            if far[i]:
                met[i] = min(met[i], _met(body, saved, P, T, i, s, dt))
        put = 0
        for i in range(n):
            if met[i] < np.inf:
                _put_back(body, saved, P, i, met[i] / dt)
                put += 1
        if put == 0:
            break
        total += put
        keys = relist(F, P, T, keys)
    return keys, total


@njit(cache=True)
def _any_far(body, saved, awake):
    """Whether some awake object moved farther than FAR_SHARE of its size in the step."""
    for i in range(body.shape[0]):
        if awake[i] and _far(body, saved, i):
            return True
    return False


@njit(cache=True, inline="always")
def _far(body, saved, i):
    """Whether object i moved farther than FAR_SHARE of its size on an axis in the step."""
    return (
        abs(body[i, B_X] - saved[i, 0]) > FAR_SHARE * body[i, B_W]
        or abs(body[i, B_Y] - saved[i, 1]) > FAR_SHARE * body[i, B_H]
    )


@njit(cache=True, inline="always")
def depth(T, body, i, s, qx, qy):
    """How deep body i and static object s overlap with s at offset q from i, px (<= 0: apart),
    by the boxes or by the real shapes."""
    wa, ha, wb, hb = body[i, B_W], body[i, B_H], body[s, B_W], body[s, B_H]
    if not T.exact:
        return box_penetration(qx, qy, wa, ha, wb, hb)[0]
    shape, radius, start, verts, normals = T.cores
    return penetration(
        qx, qy, shape[i], wa, ha, radius[i], verts[start[i] : start[i + 1]],
        normals[start[i] : start[i + 1]], shape[s], wb, hb, radius[s],
        verts[start[s] : start[s + 1]], normals[start[s] : start[s + 1]],
    )[0]  # fmt: skip


@njit(cache=True)
def _met(body, saved, P, T, i, s, dt):
    """The instant of the step (s after it began) that body i goes back to for static object s
    (module docstring); inf when it stays where the move left it."""
    qx = body[s, B_X] - body[i, B_X]  # s from i at the step's end, and its velocity relative to i
    qy = body[s, B_Y] - body[i, B_Y]
    ux = -(body[i, B_X] - saved[i, 0]) / dt
    uy = -(body[i, B_Y] - saved[i, 1]) / dt
    wa, ha, wb, hb = body[i, B_W], body[i, B_H], body[s, B_W], body[s, B_H]
    if not (min(wa, qx + wb) - max(0.0, qx) > 0.0 and min(ha, qy + hb) - max(0.0, qy) > 0.0):
        return np.inf  # the boxes do not overlap: nor do the shapes in them
    q0x, q0y = qx - ux * dt, qy - uy * dt
    began = depth(T, body, i, s, q0x, q0y)
    if began > 0.0:  # inside as the step began: back there when it ended deeper
        return 0.0 if depth(T, body, i, s, qx, qy) > began + P.slop else np.inf
    if T.exact:
        shape, radius, start, verts, normals = T.cores
        t_enter, t_exit, _, nx, ny = sweep(
            q0x, q0y, ux, uy, shape[i], wa, ha, radius[i], verts[start[i] : start[i + 1]],
            normals[start[i] : start[i + 1]], shape[s], wb, hb, radius[s],
            verts[start[s] : start[s + 1]], normals[start[s] : start[s + 1]],
        )  # fmt: skip
    else:
        t_enter, t_exit, _, nx, ny = box_sweep(q0x, q0y, ux, uy, wa, ha, wb, hb)
    if not (0.0 <= t_enter < dt < t_exit):  # not met in the step, or not inside at its end
        return np.inf
    if not -(ux * nx + uy * ny) * (dt - t_enter) > P.slop:  # in along the normal, past slop
        return np.inf
    return t_enter


@njit(cache=True)
def _put_back(body, saved, P, i, share):
    """Move body i back to `share` (0 to 1) of the way along its step, its kinetic energy less
    the potential energy that raised (down to 0)."""
    x = saved[i, 0] + share * (body[i, B_X] - saved[i, 0])
    y = saved[i, 1] + share * (body[i, B_Y] - saved[i, 1])
    raised = -(P.gx * (x - body[i, B_X]) + P.gy * (y - body[i, B_Y]))  # per unit mass
    body[i, B_X], body[i, B_Y] = x, y
    vx, vy = body[i, B_VX], body[i, B_VY]
    kinetic = 0.5 * (vx * vx + vy * vy)
    if raised > 0.0 and kinetic > 0.0:
        scale = math.sqrt(max(kinetic - raised, 0.0) / kinetic)
        body[i, B_VX], body[i, B_VY] = scale * vx, scale * vy
