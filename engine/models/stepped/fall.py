"""The settling path's move (docs/models.md#stepped-gravity-restitution-and-friction): every awake
object moves for one step under uniform gravity, exactly, bouncing off the walls at the instants it
meets them.

Input: the state (`records.Fall`), the constants (`records.Physics`), the step and the world's
sides. Output: the state moved in place, a wall event per bounce (logged in id order, each
object's in the order they happened), and how far any object now is from its anchor.

Between contacts motion is exact: `x += v·dt + ½·g·dt²`, `v += g·dt`, so a free fall matches
`y0 + ½·g·t²` to round-off. The walls are axis-aligned, so each axis is a 1-D motion of constant
acceleration, and the first instant a wall is met is a quadratic's root, taken in its
cancellation-free form (gap h >= 0, rate v toward the wall negative, acceleration a):
approaching, `t = 2h / (-v + √(v² - 2ah))`; moving away and pulled back, `t = (v + √(v² -
2ah)) / -a`. At that instant the object bounces with the contact's e (the smaller of the object's
and the walls') on the wall's axis, and friction (the larger mu) takes `mu·(1+e)·|v_n|` of the
speed along the wall, never more than stops it (PHYSICS: a bounce with friction). An object
that meets a wall slower than the rest speed (only under gravity) gets e = 0, and one that is
left with no speed into a wall that gravity pulls it toward rests on it for the rest of the step:
its speed along the wall then falls at `mu·|g_n|` until it stops (a sliding block stops after
`v0²/(2·mu·g)`), and holds if friction can hold it. At e = 1 and mu = 0 a wall neither adds nor
takes energy: the bounce happens where and when the parabola meets it.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.errors import FoldLimitExceeded
from collide2d.engine.events import EV_WALL, SIDE_BOTTOM, SIDE_LEFT, SIDE_RIGHT, SIDE_TOP, log_event
from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.move import B_H, B_VX, B_VY, B_W, B_X, B_Y
from collide2d.engine.parabola import meet, slide_acceleration
from collide2d.engine.response import MAX_FOLDS_PER_STEP

INF = np.inf
# Below this speed (px/s) a bounce under gravity keeps nothing, whatever the rest speed: the
# bounces of e < 1 would otherwise come without end within one step (Zeno).
ZENO_SPEED = 1e-6
# An object farther than this (px) beyond twice its reach in a step from every wall meets none.
WALL_CLEAR_PX = 1e-6
# An object may meet walls at most this many times in one step (a runaway past it).
MAX_HITS_PER_STEP = 2 * MAX_FOLDS_PER_STEP


@njit(cache=True, inline="always")
def _acceleration(g, v, rest_other, mu, g_other):
    """An axis's acceleration: gravity, less friction against its motion while the object rests
    on a wall of the other axis (static friction holding it when at rest and strong enough)."""
    if rest_other == 0 or mu == 0.0:
        return g
    return slide_acceleration(g, v, mu, abs(g_other))


@njit(cache=True, inline="always")
def _advance(p, v, a, t, span, resting):
    """p and v after t s at acceleration a, kept in [0, span]; unchanged while resting."""
    if resting != 0:
        return p, v
    p = min(max(p + v * t + 0.5 * a * t * t, 0.0), span)
    return p, v + a * t


@njit(cache=True, inline="always")
def _clear(p, v, a, span, dt):
    """Whether an axis's walls, at 0 and span (> 0), lie beyond twice the farthest it can move in
    dt: then the step meets neither (and the move is one `_advance`, as the loop below makes it)."""
    reach = 2.0 * (abs(v) * dt + 0.5 * abs(a) * dt * dt) + WALL_CLEAR_PX
    return span > 0.0 and p > reach and span - p > reach


@njit(cache=True)
def fall_one(body, i, e, mu, P, dt, sides, hits):
    """Move object i for dt s (module docstring); its bounces go to hits (side, code of each)
    in order. Returns how many bounces were fast enough to count as events."""
    x, y = body[i, B_X], body[i, B_Y]
    vx, vy = body[i, B_VX], body[i, B_VY]
    sx = sides[0] - body[i, B_W]
    sy = sides[1] - body[i, B_H]
    gx, gy = P.gx, P.gy
    rest_x = 0  # -1 / +1: resting on the low / high wall of that axis
    rest_y = 0
    if not sx > 0.0:  # no room: pinned at 0 (as response.fold)
        x, rest_x = 0.0, 2
    if not sy > 0.0:
        y, rest_y = 0.0, 2
    if _clear(x, vx, gx, sx, dt) and _clear(y, vy, gy, sy, dt):  # no wall within reach
        x, vx = _advance(x, vx, gx, dt, sx, 0)
        y, vy = _advance(y, vy, gy, dt, sy, 0)
        body[i, B_X], body[i, B_Y], body[i, B_VX], body[i, B_VY] = x, y, vx, vy
        return 0
    under = gx != 0.0 or gy != 0.0
    left = dt
    counted = 0
    for _ in range(MAX_HITS_PER_STEP):
        ax = _acceleration(gx, vx, rest_y, mu, gy) if rest_x == 0 else 0.0
        ay = _acceleration(gy, vy, rest_x, mu, gx) if rest_y == 0 else 0.0
        t, what = left, -1  # what: 0/1 x low/high, 2/3 y low/high, 4/5 x/y stops sliding
        if rest_x == 0:
            t_lo = meet(x, vx, ax)
            t_hi = meet(sx - x, -vx, -ax)
            if t_lo < t:
                t, what = t_lo, 0
            if t_hi < t:
                t, what = t_hi, 1
            if rest_y != 0 and vx * ax < 0.0 and -vx / ax < t:
                t, what = -vx / ax, 4
        if rest_y == 0:
            t_lo = meet(y, vy, ay)
            t_hi = meet(sy - y, -vy, -ay)
            if t_lo < t:
                t, what = t_lo, 2
            if t_hi < t:
                t, what = t_hi, 3
            if rest_x != 0 and vy * ay < 0.0 and -vy / ay < t:
                t, what = -vy / ay, 5
        x, vx = _advance(x, vx, ax, t, max(sx, 0.0), rest_x)
        y, vy = _advance(y, vy, ay, t, max(sy, 0.0), rest_y)
        left -= t
        if what < 0:
            break
        if what >= 4:  # friction stopped it along that axis
            if what == 4:
                vx = 0.0
            else:
                vy = 0.0
            continue
        axis, high = what // 2, what % 2
        v = vx if axis == 0 else vy
        g = gx if axis == 0 else gy
        speed = v if high else -v  # toward the wall
        speed = max(speed, 0.0)
        k = e
        if under and (speed < P.rest or speed < ZENO_SPEED):
            k = 0.0
        if speed > 0.0 and (speed >= P.rest or not under):
            hits[counted] = 2 * axis + high
            counted += 1
        out = -k * speed if high else k * speed
        grip = mu * (1.0 + k) * speed  # friction along the wall, at most what stops it
        pulled = (g > 0.0) if high else (g < 0.0)
        if axis == 0:
            x, vx = (sx if high else 0.0), out
            if rest_y == 0:
                vy = vy - min(grip, abs(vy)) * (1.0 if vy > 0.0 else -1.0)
            if out == 0.0 and pulled:
                rest_x = 1 if high else -1
        else:
            y, vy = (sy if high else 0.0), out
            if rest_x == 0:
                vx = vx - min(grip, abs(vx)) * (1.0 if vx > 0.0 else -1.0)
            if out == 0.0 and pulled:
                rest_y = 1 if high else -1
    else:
        raise FoldLimitExceeded("an object meets the walls too many times in one step")
    body[i, B_X], body[i, B_Y], body[i, B_VX], body[i, B_VY] = x, y, vx, vy
    return counted


@njit(cache=True)
def fall(F, P, at, sides, hits, log):
    """Move every awake object for the step `at` (a Step); log = (rows, times, n_ev). Returns
    (the farthest any awake object is from its anchor on an axis, px; wall events; log)."""
    body, anchor = F.body, F.anchor
    rows, times, n_ev = log
    drift = 0.0
    events = 0
    saved = F.saved
    for i in range(body.shape[0]):
        saved[i, 0] = body[i, B_X]  # where the step began (touch.py sweeps pairs from there)
        saved[i, 1] = body[i, B_Y]
        if not F.awake[i]:
            continue
        e = min(F.restitution[i], P.restitution)
        mu = max(F.friction[i], P.friction)
        counted = fall_one(body, i, e, mu, P, at.dt, sides, hits)
        events += counted
        if at.log:
            for h in range(counted):
                side = (SIDE_LEFT, SIDE_RIGHT, SIDE_TOP, SIDE_BOTTOM)[hits[h]]
                rows, times = log_event(rows, times, n_ev, at.tick, at.t, EV_WALL, i, -1, side)
                n_ev += 1
        drift = max(drift, abs(body[i, B_X] - anchor[i, 0]), abs(body[i, B_Y] - anchor[i, 1]))
    return drift, events, (rows, times, n_ev)
