"""The stepped model's narrow phase: which listed pairs are in contact after a step, in the
order their contacts began.

Input: the state (`stepped.State`), the candidate keys (pairs of indices inside, from
`stepped_list`) and the step dt. Output: `near`, the pairs in contact as keys of object ids
ascending, sorted by `when`, the time each contact began (s from the step's start, swept back
along the pair's relative velocity; -inf when the motion cannot tell), then by key: a total
order, so the result is the same whatever order the objects are kept in inside.

A pair is in contact when its boxes overlap now with positive area, or overlapped during the step
(swept back on straight lines, both objects clear of the walls this step: a corner passed through
within it). Most listed pairs are far apart: a cheap reach test (contact.box_reach, without
branches) drops them before any sweep. Large scenes cut the keys into contiguous
runs, one per thread, each writing its own share of `near`, joined in run order before the sort.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.broadphase import KEY_MASK, KEY_SHIFT, index
from collide2d.engine.contact import axis_reach, box_sweep
from collide2d.engine.jit import njit, prange
from collide2d.engine.models.stepped_motion import B_H, B_SX, B_SY, B_VX, B_VY, B_W, B_X, B_Y
from collide2d.engine.sort import sort_by_time
from collide2d.engine.stepcontact import box_clip
from collide2d.engine.threads import join_shares, shares_total


@njit(cache=True, inline="always")
def _swept_back(body, i, dt):
    """Whether object i, moved back dt seconds on a straight line, is where it started the step:
    inside the world (an object that folded at a wall this step is not, SPEC 3.2)."""
    x = body[i, B_X] - body[i, B_VX] * dt
    y = body[i, B_Y] - body[i, B_VY] * dt
    return 0.0 <= x <= max(body[i, B_SX], 0.0) and 0.0 <= y <= max(body[i, B_SY], 0.0)


@njit(cache=True)
def _contact_range(body, ext, keys, first, last, near, when, base, room, dt):
    """The listed pairs keys[first:last] in contact during the step of dt s just taken, written
    to near[base:base + room] with the time each contact began in `when` while they fit;
    returns how many."""
    k = 0
    for c in range(index(first), index(last)):  # unsigned indices: broadphase.index
        a = index(keys[c] >> KEY_SHIFT)
        b = index(keys[c] & KEY_MASK)
        qx = body[b, B_X] - body[a, B_X]
        qy = body[b, B_Y] - body[a, B_Y]
        wa, ha, wb, hb = body[a, B_W], body[a, B_H], body[b, B_W], body[b, B_H]
        now = (-wb < qx) & (qx < wa) & (-hb < qy) & (qy < ha)
        ux = body[b, B_VX] - body[a, B_VX]
        uy = body[b, B_VY] - body[a, B_VY]
        # box_reach, from where the pair was as the step began
        reach = axis_reach(qx - ux * dt, ux, -wb, wa, dt)
        reach = reach & axis_reach(qy - uy * dt, uy, -hb, ha, dt)
        if not (now | reach):  # most pairs: one branch, nearly always taken
            continue
        t_enter, _, _, _, _ = box_sweep(qx - ux * dt, qy - uy * dt, ux, uy, wa, ha, wb, hb)
        if not now and not (
            box_clip(qx, qy, ux, uy, wa, ha, wb, hb, dt)
            and _swept_back(body, a, dt)
            and _swept_back(body, b, dt)
        ):
            continue
        if k < room:
            ea = ext[a]
            eb = ext[b]
            near[index(base + k)] = (min(ea, eb) << KEY_SHIFT) | max(ea, eb)
            when[index(base + k)] = t_enter if -dt <= t_enter < dt else -math.inf
        k += 1
    return k


@njit(cache=True)
def _overlapping(body, ext, keys, n_keys, near, when, dt):
    """The listed pairs in contact during the step (`_contact_range` over the whole list), sorted
    by the time in `when`, then by key, when they fit; returns how many (the caller grows `near`
    and `when` and asks again)."""
    room = near.shape[0]
    k = _contact_range(body, ext, keys, 0, n_keys, near, when, 0, room, dt)
    if k <= room:
        sort_by_time(when, near, k)
    return k


@njit(cache=True, parallel=True)
def _overlapping_split(body, ext, keys, n_keys, near, when, dt, chunks):
    """`_overlapping` with the listed pairs cut into `chunks` contiguous runs, one per thread: run
    c writes its pairs into its own share of `near` and `when`, then the shares are moved
    together in run order and sorted by (time, key), a total order, so the result is the same as
    `_overlapping`'s. When a share is too small the count returned is more than `near` holds, and
    the caller grows it and asks again."""
    room = near.shape[0]
    share = room // chunks
    found = np.zeros(chunks, np.int64)
    for c in prange(chunks):
        found[c] = _contact_range(
            body, ext, keys, c * n_keys // chunks, (c + 1) * n_keys // chunks,
            near, when, c * share, share, dt
        )
    total = shares_total(found, share, room)
    if total > room:
        return total
    k = join_shares(found, share, near)
    join_shares(found, share, when)
    sort_by_time(when, near, k)
    return k


@njit(cache=True)
def narrow(body, ext, keys, n_keys, near, when, dt, chunks):
    """The narrow phase: `_overlapping`, split among `chunks` threads when more than one."""
    if chunks > 1:
        return _overlapping_split(body, ext, keys, n_keys, near, when, dt, chunks)
    return _overlapping(body, ext, keys, n_keys, near, when, dt)
