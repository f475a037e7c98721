"""Objects with no room to move, found when a scene is built, before anything runs.

An object that moves on an axis along which it touches (or overlaps) a wall or a static object on
both sides would collide again and again at one instant. `no_room` finds such objects when a
scene is built (the exact model refuses them, and so does the scenario reader);
`no_room_message` says it in words. A jam that stops the exact model later is found by the model
itself (models/exact/jam.py).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from collide2d.engine.broadphase import choose, find_pairs
from collide2d.engine.events import AXIS_NAMES, AXIS_X, AXIS_Y
from collide2d.engine.world import KIND_BOX, Bodies, WorldSpec

# Static objects are searched for a wedge among the boxes grown by this much (px) along the axis.
WEDGE_REACH_PX = 0.5


class Wedge(NamedTuple):
    """An object with no room to move on an axis: `obj` moves on `axis` (AXIS_X or AXIS_Y) and
    touches (or overlaps) `low` on its low side and `high` on its high side; each is a static
    object's id, or WALL for the world's wall on that side."""

    obj: int
    axis: int
    low: int
    high: int


WALL = -1
_NONE = -2


def no_room(world: WorldSpec, bodies: Bodies, geometry: str | None = "exact") -> list[Wedge]:
    """Every moving object with no room on an axis it moves on, in (id, axis) order: its velocity
    on the axis is not 0, and along that axis it touches or overlaps a wall or a static object
    on both sides (a static one only when its box overlaps the mover's box on the other axis with
    positive length). Under `geometry: exact` a static object holds a mover only when both are
    boxes (other shapes touch by their real outline); the walls hold every shape by its box.
    Such an object would collide again and again with no time passing. Linear work in n but for
    one broad-phase pass when there are static objects."""
    geometry = "exact" if geometry is None else geometry
    static = np.asarray(bodies.static, bool)
    pos = np.asarray(bodies.pos, np.float64).reshape(-1, 2)
    size = np.asarray(bodies.size, np.float64).reshape(-1, 2)
    vel = np.asarray(bodies.vel, np.float64).reshape(-1, 2)
    boxy = np.ones(len(static), bool) if geometry == "box" else bodies.kind == KIND_BOX
    found = []
    for axis, side in ((AXIS_X, float(world.width)), (AXIS_Y, float(world.height))):
        k = 0 if axis == AXIS_X else 1
        moving = ~static & (vel[:, k] != 0.0)
        if not moving.any():
            continue
        low = np.where(moving & (pos[:, k] <= 0.0), WALL, _NONE)
        high = np.where(moving & (pos[:, k] + size[:, k] >= side), WALL, _NONE)
        holders = static & boxy
        if holders.any() and (moving & boxy & ((low == _NONE) | (high == _NONE))).any():
            _static_holders(pos, size, moving & boxy, holders, k, world, low, high)
        for i in np.flatnonzero((low != _NONE) & (high != _NONE)):
            found.append(Wedge(int(i), axis, int(low[i]), int(high[i])))
    return sorted(found)


def _static_holders(pos, size, movers, holders, k, world, low, high):
    """Fill low/high (where _NONE) with the lowest id of a static box that holds each mover from
    below / above along axis k: it overlaps the mover's box on the other axis, and on axis k it
    reaches to the mover's low edge (touching or overlapping) without reaching past its high edge
    (from below), or the other way round (from above). A static box holding it from both sides
    (the mover inside it on that axis) is neither: once they collide they separate."""
    sel = np.flatnonzero(movers | holders)
    lo = pos[sel].copy()
    hi = lo + size[sel]
    lo[:, k] -= WEDGE_REACH_PX
    hi[:, k] += WEDGE_REACH_PX
    method, cell = choose(world.width, world.height, hi - lo)
    pairs = sel[find_pairs(method, lo, hi, movers[sel], cell)]
    a, b = pairs[:, 0], pairs[:, 1]
    mixed = movers[a] != movers[b]
    a, b = a[mixed], b[mixed]
    m = np.where(movers[a], a, b)
    s = np.where(movers[a], b, a)
    m_lo, s_lo = pos[m, k], pos[s, k]
    m_hi, s_hi = m_lo + size[m, k], s_lo + size[s, k]
    none = np.iinfo(np.int64).max
    for side, held in (
        (low, (s_lo < m_lo) & (m_lo <= s_hi) & (s_hi < m_hi)),
        (high, (m_lo < s_lo) & (s_lo <= m_hi) & (m_hi < s_hi)),
    ):
        first = np.full(len(side), none, np.int64)
        np.minimum.at(first, m[held], s[held])
        take = (side == _NONE) & (first != none)
        side[take] = first[take]


def no_room_message(found: list[Wedge], bodies: Bodies, names=None) -> str:
    """What `no_room` found, in words: the first object (`names[i]` when given, shown beside its
    id) and what holds it, then how many more."""
    w = found[0]
    k = 0 if w.axis == AXIS_X else 1
    axis = AXIS_NAMES[w.axis]
    name = names[w.obj] if names is not None and names[w.obj] else None
    who = f"object {w.obj}" + (f" ({name})" if name else "")
    sides = ("left", "right") if w.axis == AXIS_X else ("top", "bottom")
    wide = "wide" if w.axis == AXIS_X else "tall"

    def holder(j, side):
        return f"the {side} wall" if j == WALL else f"static object {j}"

    if w.low == WALL and w.high == WALL:
        span = f"it is as {wide} as the world"
    else:
        span = (
            f"it is as {wide} as the space between {holder(w.low, sides[0])} and "
            f"{holder(w.high, sides[1])} (or wider)"
        )
    v = float(np.asarray(bodies.vel, np.float64).reshape(-1, 2)[w.obj, k])
    also = [f for f in found[1:] if f.obj == w.obj]
    both = f" (and on {AXIS_NAMES[also[0].axis]})" if also else ""
    more = len({f.obj for f in found}) - 1
    rest = f"; {more} more such object{'s' if more > 1 else ''}" if more else ""
    return (
        f"{who} has no room to move on {axis}{both}: {span}, and it moves on {axis} "
        f"(v{axis} = {v:g} px/s), so under the exact model it would collide again and again "
        f"with no time passing; give it room or no velocity on {axis}{rest}"
    )
