"""The settling path's last word on a body it could not keep out of a static object
(docs/limits.md#runaways): one that falls asleep inside a static object stops the run, naming it.

Input: the state (`records.Fall`), the constants (`records.Physics`), the candidate list and its
counts (`records.Touch`), the objects that fell asleep this step and the tick. Output:
`Touch.sunk` holding the body, the static object, the tick and the depth of the deepest such body
this step (`inside` returns whether there was one; settle.run then stops), and `sunk_error`, the
error the model raises for it.

The move puts back a body that a step took far into a static object (land.py), and the contacts
push out what is left past slop (solver.py). Neither can always: the pushes spend only the energy
given up so far, and steps long for the gravity (a step's fall |g|·dt² many pixels), or bodies
much heavier than the one under them pressing it down, can leave a body deep in a static object,
or take it through to the floor under it. A body left so is not kept as if at rest: the moment
it falls asleep more than SUNK_PX past slop inside a static object (by the boxes, or by the real
shapes under `geometry: exact`), the run stops, as the other runaways do.
"""

from __future__ import annotations

import math

from collide2d.engine.broadphase import KEY_MASK, KEY_SHIFT
from collide2d.engine.errors import Runaway
from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.land import depth
from collide2d.engine.models.stepped.move import B_X, B_Y
from collide2d.engine.models.stepped.touch import N_KEYS, N_RELIST

# A body asleep deeper than this (px) past slop inside a static object stops the run.
SUNK_PX = 1.0
# The candidate list's margin is taken as this much less (px), for rounding.
LIST_SLACK_PX = 1e-9


class Sunk(Runaway, RuntimeError):
    """A body fell asleep inside a static object (stepped model); `objects` is (the body, the
    static object)."""

    def __init__(self, message: str, objects: tuple[int, ...] = ()):
        super().__init__(message)
        self.objects = tuple(objects)


@njit(cache=True)
def inside(F, P, T, keys, tick, fell):
    """Whether an object that fell asleep this step (marked in `fell`, (n,) bool, cleared here)
    lies inside a static object more than SUNK_PX past slop; the deepest such goes to T.sunk
    (body, static object, tick, depth). keys: the candidate list. It lists every static object
    that such a body touches when the body, awake at the list's making, has since moved less than
    the list's margin (twice half of it: both boxes were grown by half); a body that moved more
    (a step's gravity, |g|·dt², pushed out past half the margin) or woke in this step is tested
    against every static object instead."""
    body, static = F.body, F.static
    n = body.shape[0]
    reach = 2.0 * P.half - LIST_SLACK_PX
    for i in range(n):  # the bodies the list may not cover, each against every static object
        if not fell[i]:
            continue
        moved = max(abs(body[i, B_X] - F.anchor[i, 0]), abs(body[i, B_Y] - F.anchor[i, 1]))
        if moved < reach and T.counts[N_RELIST] == 0:
            continue
        fell[i] = False
        for s in range(n):
            if static[s]:
                _test(F, P, T, i, s, tick)
    for c in range(T.counts[N_KEYS]):  # the others, through the list
        a = keys[c] >> KEY_SHIFT
        b = keys[c] & KEY_MASK
        if static[a] != static[b] and (fell[a] or fell[b]):
            _test(F, P, T, b if static[a] else a, a if static[a] else b, tick)
    for i in range(n):
        fell[i] = False
    return T.sunk[0] >= 0.0


@njit(cache=True, inline="always")
def _test(F, P, T, i, s, tick):
    """Note body i in T.sunk when it lies inside static object s more than SUNK_PX past slop and
    deeper than any noted so far."""
    body = F.body
    d = depth(T, body, i, s, body[s, B_X] - body[i, B_X], body[s, B_Y] - body[i, B_Y])
    if d > P.slop + SUNK_PX and not (T.sunk[0] >= 0.0 and d <= T.sunk[3]):
        T.sunk[0], T.sunk[1], T.sunk[2], T.sunk[3] = i, s, tick, d


def sunk_error(sunk, gravity, dt: float) -> Sunk:
    """The error for T.sunk: the body, the static object, the tick and how deep, and what a step
    of gravity moves a body (|g|·dt², px) at the step dt."""
    i, s, tick, deep = int(sunk[0]), int(sunk[1]), int(sunk[2]), float(sunk[3])
    fall = math.hypot(*gravity) * dt * dt
    return Sunk(
        f"object {i} fell asleep {deep:.3g} px inside static object {s} in tick {tick}: its "
        f"contacts could not push it out in steps of {dt:.3g} s (a step's gravity moves a body "
        f"{fall:.3g} px; bodies much heavier than one under them press it in too); use substeps",
        (i, s),
    )
