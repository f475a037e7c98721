"""Why the exact model stops, named in words: a jam, a runaway, a rest it cannot follow.

After a tick stopped at the event cap, `jam_error` looks at the events that would come next at the
instant it stopped: `jammed` finds the moving objects held from both sides by a touching chain
from wall or static object to wall or static object (they cannot move on that axis, so the model
would collide them again and again with no time passing), and the error names them (NoRoom), else
it is a runaway (EventCapExceeded). `rest_error` names a pair where one would rest on the other,
or slide round it, and `carried_error` a body knocked into motion while another rests on it,
which the model does not follow (NotYetExact). `listing` names objects for the
messages. Objects with no room already when a scene is built are found by engine/noroom.py.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.errors import EventCapExceeded, NoRoom, NotYetExact
from collide2d.engine.events import AXIS_NAMES, AXIS_X, AXIS_Y, EV_PAIR, SIDE_LEFT, SIDE_RIGHT
from collide2d.engine.models.exact.heap import INSTANT_REL, INSTANT_S
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


def jam_error(rows, times, t: float, F, N, world, said: str) -> EventCapExceeded | NoRoom:
    """The error of a tick stopped at the cap, from the events logged after it (rows, times of
    the event log) and the state: NoRoom when the objects of the events at the instant t are
    jammed on an axis, naming them; else EventCapExceeded (`said`: what stopped)."""
    same = np.abs(times - t) <= max(INSTANT_S, abs(t) * INSTANT_REL)
    last = rows[same][:, 2:5]  # a, b, code
    involved = sorted({int(i) for i in last[:, :2].ravel() if i >= 0})
    walls = rows[same][:, 1] != EV_PAIR  # an object's own event: its side in code
    x_side = (last[:, 2] == SIDE_LEFT) | (last[:, 2] == SIDE_RIGHT)
    on = {
        AXIS_X: (walls & x_side) | (~walls & (last[:, 2] != AXIS_Y)),
        AXIS_Y: (walls & ~x_side) | (~walls & (last[:, 2] != AXIS_X)),
    }
    for axis in (AXIS_X, AXIS_Y):
        objects = jammed(F, N, world, involved, axis, t) if on[axis].any() else []
        if objects:
            one = len(objects) == 1
            against = " and the walls" if walls.any() else ""
            return NoRoom(
                f"{listing('object', objects)} {'has' if one else 'have'} no room to move on "
                f"{AXIS_NAMES[axis]}: {'it collides' if one else 'they collide'} with "
                f"{'its neighbours' if one else 'each other'}{against} again and again at "
                f"t = {t!r} s with no time passing ({said})",
                tuple(objects),
                AXIS_NAMES[axis],
            )
    return EventCapExceeded(said)


def carried_error(a: int, b: int, tick: int, t: float) -> NotYetExact:
    """The error of a run stopped in `tick` at time t where object a, which object b rests on,
    is knocked into motion: b's support would move under it."""
    return NotYetExact(
        f"object {a}, which object {b} rests on, is knocked into motion in tick {tick} at t = "
        f"{t!r} s: the exact model rests bodies on supports that stay still (the walls, static "
        "boxes, and bodies resting still on them); use model: stepped",
        (a, b),
    )


def rest_error(a: int, b: int, tick: int, t: float) -> NotYetExact:
    """The error of a run stopped in `tick` at time t where, of objects a and b pressed together
    by gravity with no speed between them, one would rest on the other or slide round it."""
    return NotYetExact(
        f"objects {a} and {b} meet with no speed between them while gravity presses them "
        f"together, in tick {tick} at t = {t!r} s: one would rest on the other or slide round "
        "it, which the exact model does only on the walls, the flat faces of static boxes and "
        "the tops of boxes resting still; use model: stepped",
        (a, b),
    )
