"""Why the exact model stops, named in words: a jam, a runaway, a storm, a rest it cannot follow.

After a tick stopped at the event cap, `jam_error` looks at the events that would come next at the
instant it stopped: `jammed` finds the moving objects held from both sides by a touching chain
from wall or static object to wall or static object (they cannot move on that axis, so the model
would collide them again and again with no time passing), and the error names them (NoRoom), else
it is a runaway (EventCapExceeded). Under gravity, restitution or friction the kernel also counts,
as it goes, each moving object's events close in time to its event before with a partner it has
just met (`storm_seen`, `recurs`): an inelastic collapse (a body pinched between a wall and
another, bounces that die away at one instant but never in floating point) is seen after
STORM_EVENTS such repeats, long before the cap, and `storm_error` names the objects of the
contacts that recur and the tick (NotYetExact, or NoRoom when they are jammed;
docs/models.md#event-storms). `rest_error` names a pair where one
would rest on the other, or slide round it, and `carried_error` a body knocked into motion while
another rests on it, which the model does not follow (NotYetExact). `listing` names objects for
the messages. Objects with no room already when a scene is built are found by engine/noroom.py.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.errors import EventCapExceeded, NoRoom, NotYetExact
from collide2d.engine.events import (
    AXIS_NAMES,
    AXIS_X,
    AXIS_Y,
    EV_PAIR,
    EV_WALL,
    SIDE_LEFT,
    SIDE_NAMES,
    SIDE_RIGHT,
)
from collide2d.engine.models.exact.heap import INSTANT_REL, INSTANT_S, RANK_PAIR, instant
from collide2d.engine.models.exact.state import S_STORM, SH, STATIC, SW, TLOC, VX, VY, X, Y, hot

# An event storm (docs/models.md#event-storms): a moving object taking part in more than this many
# events, each at one instant with the one before it (heap.instant: time stands still, or moves
# on by a rounding) or within STORM_GAP of it, and with a partner (an object, a wall, its own stop
# or leave) among the last RECUR partners it met, stops the run. A zero-time chain or a body many
# others land on at once meets each partner once or twice; a storm meets the same two or three
# for ever. STORM_GAP (s): a body pinched with no gap at all still moves the clock on at each
# impact, by the 1e-9 px contacts are decided to over its speed (1e-12 s at 1,000 px/s, 1e-9 s
# at 1 px/s); a thousand repeats each within a nanosecond is a billion events a second.
STORM_EVENTS = 1000
STORM_GAP = 1e-9
RECUR = 3
# The columns of the model's `instants` (n, 2 + RECUR) float64: the time of an object's last
# event (s), its repeats in the run of events up to it, each close to the one before, and the
# partners of its last RECUR events in that run (newest first; NO_PARTNER: none). A
# partner is an object's id, or -1 - side for a wall (and -1 - STOP, -1 - LEAVE for a rest's own
# stop and leave).
I_T, I_COUNT, I_PARTNERS = 0, 1, 2
NO_PARTNER = -100.0


def listing(word: str, ids: list[int], most: int = 8) -> str:
    """ "object 3", "objects 1 and 2", "objects 1, 2, 3, ... (12 in all)"."""
    if len(ids) == 1:
        return f"{word} {ids[0]}"
    shown = [str(i) for i in ids[:most]]
    if len(ids) > most:
        return f"{word}s {', '.join(shown)}, ... ({len(ids)} in all)"
    return f"{word}s {', '.join(shown[:-1])} and {shown[-1]}"


def new_instants(n: int) -> np.ndarray:
    """The `instants` record of n objects that have had no event yet."""
    instants = np.full((n, I_PARTNERS + RECUR), NO_PARTNER)
    instants[:, I_T] = -np.inf
    instants[:, I_COUNT] = 0.0
    return instants


@hot
def storm_seen(rank, a, b, t, S):
    """Count the event (rank, a, b) at time t for its moving objects (`recurs`), under gravity,
    restitution or friction, when the model counts storms (st[S_STORM] > 0): the object a storm
    is seen on, or -1. A partner is the other object, or -1 - side (a wall, a stop, a leave)."""
    storm, N, instants = S.st[S_STORM], S.N, S.instants
    seen = -1
    if storm <= 0 or S.world.elastic:
        return seen
    partner = float(b) if rank == RANK_PAIR else -1.0 - b
    if N[a, STATIC] == 0 and recurs(a, partner, t, instants, storm):
        seen = a
    if rank == RANK_PAIR and N[b, STATIC] == 0:
        if recurs(b, float(a), t, instants, storm) and seen < 0:
            seen = b
    return seen


@hot
def recurs(i, partner, t, instants, storm):
    """Count moving object i's event at time t with `partner` (instants: the record above):
    whether it has now met partners it has just met more than `storm` times, each at one
    instant with its event before or within STORM_GAP of it."""
    if abs(t - instants[i, I_T]) > max(instant(t), STORM_GAP):  # time has moved on: afresh
        instants[i, I_COUNT] = 0.0
        for k in range(I_PARTNERS, I_PARTNERS + RECUR):
            instants[i, k] = NO_PARTNER
    else:
        for k in range(I_PARTNERS, I_PARTNERS + RECUR):
            if instants[i, k] == partner:
                instants[i, I_COUNT] += 1.0
                break
    for k in range(I_PARTNERS + RECUR - 1, I_PARTNERS, -1):
        instants[i, k] = instants[i, k - 1]
    instants[i, I_PARTNERS] = partner
    instants[i, I_T] = t
    return instants[i, I_COUNT] > storm


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
    return _no_room(rows[_at(times, t)], t, F, N, world, said) or EventCapExceeded(said)


def storm_error(first: int, rows, times, t: float, F, N, world, tick: int) -> NotYetExact | NoRoom:
    """The error of a run stopped in `tick` at time t by an event storm seen on object `first`,
    from the events logged from there on (rows, times of the event log) and the state: the
    objects of the contacts that recur, those of the storm (each event close to the one before)
    linked to `first` through pairs and rests, and the walls they meet; NoRoom when they are
    jammed on an axis."""
    rows = rows[_storm_at(times, t)]
    group = {first}
    while True:
        linked = {int(i) for a, b in rows[:, 2:4] if a in group or b in group for i in (a, b)}
        if linked - {-1} <= group:
            break
        group |= linked - {-1}
    rows = rows[np.isin(rows[:, 2], list(group))]
    said = (
        f"an event storm in tick {tick}: object {first} met the same partners more than "
        f"{STORM_EVENTS} times at one instant"
    )
    stuck = _no_room(rows, t, F, N, world, said)
    if stuck is not None:
        return stuck
    objects = sorted(group)
    walls = sorted({int(c) for k, c in rows[:, [1, 4]] if k == EV_WALL})
    met = "".join(f" and the {SIDE_NAMES[w]} wall" for w in walls)
    return NotYetExact(
        f"{listing('object', objects)}{met} collide again and again in tick {tick} at t = {t!r} s "
        f"with no time passing: an event storm (object {first} met the same partners more than "
        f"{STORM_EVENTS} times at that instant), bounces that die away at one instant without "
        "end in floating point; the exact model cannot carry them on; use model: stepped",
        tuple(objects),
    )


def _at(times, t: float) -> np.ndarray:
    """Which of the logged `times` are at the instant t."""
    return np.abs(times - t) <= max(INSTANT_S, abs(t) * INSTANT_REL)


def _storm_at(times, t: float) -> np.ndarray:
    """Which of the logged `times`, from t on, follow one another as a storm's do: each at one
    instant with the one before, or within STORM_GAP of it (recurs)."""
    gaps = np.abs(np.diff(np.concatenate(([t], times))))
    close = gaps <= np.maximum(STORM_GAP, np.maximum(INSTANT_S, np.abs(times) * INSTANT_REL))
    return np.cumprod(close).astype(bool)


def _no_room(rows, t: float, F, N, world, said: str) -> NoRoom | None:
    """NoRoom naming the moving objects of the events `rows` (logged at the instant t) that are
    jammed on an axis (`jammed`), if any (`said`: what stopped)."""
    last = rows[:, 2:5]  # a, b, code
    involved = sorted({int(i) for i in last[:, :2].ravel() if i >= 0})
    walls = rows[:, 1] != EV_PAIR  # an object's own event: its side in code
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
    return None


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
