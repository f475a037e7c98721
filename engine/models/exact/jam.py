"""A jam that stops the exact model: the moving objects held on an axis, named in words.

After a tick stopped at the event cap, `jammed` finds the moving objects held from both sides by
a touching chain from wall or static object to wall or static object (they cannot move on that
axis, so the model would collide them again and again with no time passing); `listing` names
them for the message. Objects with no room already when a scene is built are found by
engine/noroom.py.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.events import AXIS_X
from collide2d.engine.models.exact.state import SH, STATIC, SW, TLOC, VX, VY, X, Y


def listing(word: str, ids: list[int], most: int = 8) -> str:
    """ "object 3", "objects 1 and 2", "objects 1, 2, 3, ... (12 in all)"."""
    if len(ids) == 1:
        return f"{word} {ids[0]}"
    shown = [str(i) for i in ids[:most]]
    if len(ids) > most:
        return f"{word}s {', '.join(shown)}, ... ({len(ids)} in all)"
    return f"{word}s {', '.join(shown[:-1])} and {shown[-1]}"


def jammed(F, N, world, ids: list[int], axis: int, t: float) -> list[int]:
    """The moving objects of `ids` (in the exact model's state F, N and its World record) held
    on `axis` at time t from both sides by a chain of boxes of `ids` that touch (or overlap) along
    the axis and overlap on the other, from a wall or a static object to a wall or a static
    object: they cannot move on that axis."""
    k = 0 if axis == AXIS_X else 1
    ids = np.array(ids, np.int64)
    lo = F[ids, X : Y + 1] + F[ids, VX : VY + 1] * (t - F[ids, TLOC : TLOC + 1])
    hi = lo + F[ids, SW : SH + 1]
    side = (world.width, world.height)[k]
    tol = 1e-9 * max(world.width, world.height)
    fixed = N[ids, STATIC] != 0
    o = 1 - k
    beside = (lo[:, None, o] < hi[None, :, o]) & (lo[None, :, o] < hi[:, None, o])
    # below[j, i]: j touches i from below along the axis
    below = beside & (lo[:, None, k] < lo[None, :, k]) & (hi[:, None, k] >= lo[None, :, k] - tol)
    held = []
    for start, links in ((lo[:, k] <= tol, below), (hi[:, k] >= side - tol, below.T)):
        reached = fixed | start
        while True:
            more = reached | (links & reached[:, None]).any(axis=0)
            if (more == reached).all():
                break
            reached = more
        held.append(reached)
    return [int(i) for i in ids[held[0] & held[1] & ~fixed]]
