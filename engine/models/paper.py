"""The paper's model, reproduced exactly in integers (SPEC 3.1; paper sections II.D-II.F).

Inputs: a WorldSpec and Bodies whose positions, sizes and velocities the scenario loader has already
checked (whole pixels; every velocity a whole number of pixels per whole number of ticks). Output:
integer positions, step velocities, and the events of each tick.

One tick, every object in id order:
  move   each velocity component steps V pixels every P ticks (a counter per component);
  walls  a box that left the world while moving outward on an axis reverses that component and
         takes back this tick's displacement on it;
  pairs  every overlapping pair of boxes, in ascending (a, b) order, each pair seeing what the pairs
         before it changed: the flip rule on xdiff (overlap width) and ydiff (overlap height) —
         xdiff > ydiff reverses both vertical components (axis y), ydiff > xdiff both horizontal
         (axis x), a tie both (axis xy) — then each object's displacement of this tick is taken
         back, at most once per object per axis per tick, whatever it hit;
  record walls first, then pairs, as they happened.

Broad phase without changing the rule: during the pair stage each coordinate of an object is either
where it was before the tick or where it moved to (taking back is the only change), so two objects
can overlap at some point of the stage only if their *reach boxes* — the hull of both positions —
overlap. A sort-and-sweep over the reach boxes' x intervals (the order kept from tick to tick and
mended by insertion sort) gives every such pair; the candidates are sorted by (a, b) and tested on
the current positions in that order, which is exactly the all-pairs loop of the paper.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from engine.events import (
    AXIS_X,
    AXIS_XY,
    AXIS_Y,
    EV_PAIR,
    EV_WALL,
    EVENT_DTYPE,
    SIDE_BOTTOM,
    SIDE_LEFT,
    SIDE_RIGHT,
    SIDE_TOP,
)
from engine.motion import paper_rate
from engine.world import Bodies, WorldSpec

# Columns of the kernel's event rows (int64); `t` is added in Python as tick / fps.
_TICK, _TYPE, _A, _B, _CODE, _XDIFF, _YDIFF = range(7)
_EVENT_COLS = 7
# A candidate pair (a, b) is kept as one sortable key, a << _KEY_SHIFT | b (ids below 2**32).
_KEY_SHIFT = 32
_KEY_MASK = (1 << _KEY_SHIFT) - 1
# Room for events and candidate pairs before the kernel grows its buffers (rows).
_INITIAL_ROWS = 1024
# An insertion sort that has to shift more than this many places per object falls back to a full
# sort (a scene that reshuffled, e.g. objects crossing the world in one tick).
_SHIFTS_PER_OBJECT = 8
# Candidate lists up to this long are sorted by insertion (faster than the library sort there).
_INSERTION_SORT_MAX = 64
# The candidate list is made with every reach box grown by a margin (px) and kept until some object
# has drifted that far from where it was made: a few of the fastest steps, within these bounds.
_MARGIN_STEPS = 8
_MARGIN_MIN_PX = 2
_MARGIN_MAX_PX = 32


@njit(cache=True)
def _grow(buf, needed):
    """buf with at least `needed` rows, its content kept (doubling)."""
    if needed <= buf.shape[0]:
        return buf
    rows = max(needed, 2 * buf.shape[0])
    out = np.empty((rows, buf.shape[1]), buf.dtype)
    out[: buf.shape[0]] = buf
    return out


@njit(cache=True)
def _grow1(buf, needed):
    """1-D buf with at least `needed` entries, its content kept (doubling)."""
    if needed <= buf.shape[0]:
        return buf
    out = np.empty(max(needed, 2 * buf.shape[0]), buf.dtype)
    out[: buf.shape[0]] = buf
    return out


@njit(cache=True, inline="always")
def _record(ev, n_ev, tick, kind, a, b, code, xdiff, ydiff):
    """Write one event row at n_ev (the caller made room); returns the new count."""
    ev[n_ev, _TICK] = tick
    ev[n_ev, _TYPE] = kind
    ev[n_ev, _A] = a
    ev[n_ev, _B] = b
    ev[n_ev, _CODE] = code
    ev[n_ev, _XDIFF] = xdiff
    ev[n_ev, _YDIFF] = ydiff
    return n_ev + 1


@njit(cache=True, inline="always")
def _move(pos, step, period, count, disp, anchor, size, limit):
    """Counters rise by one; a component whose counter reaches its period moves by its step.

    Returns (how far, px, anything now is from `anchor` at most; whether any box left the world).
    """
    drift = 0
    left = False
    for i in range(pos.shape[0]):
        for ax in range(2):
            c = count[i, ax] + 1
            fire = c >= period[i, ax]
            count[i, ax] = 0 if fire else c
            d = step[i, ax] if fire else 0
            p = pos[i, ax] + d
            pos[i, ax] = p
            disp[i, ax] = d
            drift = max(drift, abs(p - anchor[i, ax]))
            left |= (p < 0) | (p + size[i, ax] > limit[ax])
    return drift, left


@njit(cache=True, inline="always")
def _walls(pos, size, step, disp, limit, tick, log, ev, n_ev):
    """Reverse and take back each component that left the world moving outward (SPEC 3.1)."""
    for i in range(pos.shape[0]):
        for ax in range(2):
            d = disp[i, ax]
            if d < 0 and pos[i, ax] < 0:
                side = SIDE_LEFT if ax == 0 else SIDE_TOP
            elif d > 0 and pos[i, ax] + size[i, ax] > limit[ax]:
                side = SIDE_RIGHT if ax == 0 else SIDE_BOTTOM
            else:
                continue
            step[i, ax] = -step[i, ax]
            pos[i, ax] -= d
            disp[i, ax] = 0
            if log:
                n_ev = _record(ev, n_ev, tick, EV_WALL, i, -1, side, -1, -1)
    return n_ev


@njit(cache=True)
def _sort_order(order, key, sorted_key):
    """Mend `order` so key[order] ascends, and set sorted_key = key[order].

    Insertion sort on the order kept from the last tick (nearly sorted: objects move a few pixels
    a tick), or a full sort when it is far off.
    """
    n = order.shape[0]
    for s in range(n):
        sorted_key[s] = key[order[s]]
    budget = _SHIFTS_PER_OBJECT * n + 16
    shifts = 0
    for i in range(1, n):
        cur = order[i]
        k = sorted_key[i]
        j = i - 1
        while j >= 0 and sorted_key[j] > k:
            order[j + 1] = order[j]
            sorted_key[j + 1] = sorted_key[j]
            j -= 1
        shifts += i - 1 - j
        order[j + 1] = cur
        sorted_key[j + 1] = k
        if shifts > budget:
            order[:] = np.argsort(key, kind="mergesort")
            for s in range(n):
                sorted_key[s] = key[order[s]]
            return


@njit(cache=True)
def _candidates(pos, size, disp, movable, margin, order, lo, hi, cand):
    """Pairs (a < b, as keys a << _KEY_SHIFT | b, ascending) whose reach boxes, grown by
    `margin` px on every side, overlap; pairs of two immovable objects are left out.

    lo: (3, n) and hi: (2, n) scratch for the reach boxes and the sorted x starts. Returns how
    many candidates there are; only as many as `cand` holds are written (the caller grows the
    buffer and asks again).
    """
    n = pos.shape[0]
    for i in range(n):
        for ax in range(2):
            d = disp[i, ax]
            lo[ax, i] = pos[i, ax] - max(d, 0) - margin
            hi[ax, i] = pos[i, ax] - min(d, 0) + size[i, ax] + margin
    hix, loy, hiy, sorted_lox = hi[0], lo[1], hi[1], lo[2]
    _sort_order(order, lo[0], sorted_lox)
    k = 0
    for s in range(n):
        a = order[s]
        ha = hix[a]
        for t in range(s + 1, n):
            if sorted_lox[t] >= ha:
                break
            b = order[t]
            # branch-free: write the key, keep it only if the y intervals meet too
            meet = (loy[b] < hiy[a]) & (loy[a] < hiy[b]) & (movable[a] | movable[b])
            if k < cand.shape[0]:
                cand[k] = (min(a, b) << _KEY_SHIFT) | max(a, b)
            k += meet
    if k <= cand.shape[0]:
        _sort_keys(cand[:k])
    return k


@njit(cache=True)
def _sort_keys(keys):
    """Sort in place: insertion sort for the usual handful, the library sort past that."""
    if keys.shape[0] > _INSERTION_SORT_MAX:
        keys.sort()
        return
    for i in range(1, keys.shape[0]):
        key = keys[i]
        j = i - 1
        while j >= 0 and keys[j] > key:
            keys[j + 1] = keys[j]
            j -= 1
        keys[j + 1] = key


@njit(cache=True, inline="always")
def _pairs(pos, size, step, disp, cand, n_cand, tick, log, ev, n_ev):
    """The flip rule on every overlapping candidate pair, in (a, b) order (SPEC 3.1)."""
    for c in range(n_cand):
        a = cand[c] >> _KEY_SHIFT
        b = cand[c] & _KEY_MASK
        xdiff = min(pos[a, 0] + size[a, 0], pos[b, 0] + size[b, 0]) - max(pos[a, 0], pos[b, 0])
        ydiff = min(pos[a, 1] + size[a, 1], pos[b, 1] + size[b, 1]) - max(pos[a, 1], pos[b, 1])
        if (xdiff <= 0) | (ydiff <= 0):
            continue
        if xdiff > ydiff:
            axis = AXIS_Y
        elif ydiff > xdiff:
            axis = AXIS_X
        else:
            axis = AXIS_XY
        for i in (a, b):
            if axis != AXIS_Y:
                step[i, 0] = -step[i, 0]
            if axis != AXIS_X:
                step[i, 1] = -step[i, 1]
            for ax in range(2):
                pos[i, ax] -= disp[i, ax]
                disp[i, ax] = 0
        if log:
            n_ev = _record(ev, n_ev, tick, EV_PAIR, a, b, axis, xdiff, ydiff)
    return n_ev


@njit(cache=True)
def _run(pos, size, step, period, count, movable, limit, tick0, nticks, log, cands, ev):
    """Run `nticks` ticks; returns (event rows, their count, candidate keys).

    `cands` = (order, anchor, keys, state, margin): the candidate list kept from call to call —
    the sweep order, the positions it was made at, its keys, state[0] = how many (-1: none yet).
    """
    order, anchor, keys, state, margin = cands
    n = pos.shape[0]
    disp = np.zeros((n, 2), np.int64)
    lo = np.empty((3, n), np.int64)
    hi = np.empty((2, n), np.int64)
    n_ev = 0
    for k in range(nticks):
        tick = tick0 + k + 1
        # move: counters fire, this tick's displacement is kept to be taken back
        drift, left = _move(pos, step, period, count, disp, anchor, size, limit)
        # walls: reverse and take back what left the world moving outward
        if left:
            if log and n_ev + 2 * n > ev.shape[0]:
                ev = _grow(ev, n_ev + 2 * n)
            n_ev = _walls(pos, size, step, disp, limit, tick, log, ev, n_ev)
        # pairs: the candidate list (made anew once anything drifted a margin from where it
        # was made; drift is measured before the walls take steps back, which only errs early),
        # then the flip rule on every overlapping pair in (a, b) order
        if state[0] < 0 or drift >= margin:
            state[0] = _candidates(pos, size, disp, movable, margin, order, lo, hi, keys)
            if state[0] > keys.shape[0]:
                keys = np.empty(2 * state[0], np.int64)
                state[0] = _candidates(pos, size, disp, movable, margin, order, lo, hi, keys)
            anchor[:] = pos
        if log and n_ev + state[0] > ev.shape[0]:
            ev = _grow(ev, n_ev + state[0])
        n_ev = _pairs(pos, size, step, disp, keys, state[0], tick, log, ev, n_ev)
    return ev, n_ev, keys


class Model:
    """The paper model over integer state: positions, sizes, steps V, periods P, counters."""

    def __init__(self, world: WorldSpec, bodies: Bodies, substeps: int = 1, geometry: str = "box"):
        if substeps != 1:
            raise ValueError("the paper model has no substeps")
        if geometry != "box":
            raise ValueError("the paper model collides every shape as its box (geometry: box)")
        self.world = world
        self.fps = int(world.fps)
        self.tick = 0
        self.pos = _whole(bodies.pos, "positions")
        self.size = _whole(bodies.size, "sizes")
        self.step, self.period = _rates(bodies.vel, self.fps)
        self.count = np.zeros_like(self.step)
        self.movable = ~np.asarray(bodies.static, bool)
        self.limit = np.array([world.width, world.height], np.int64)
        self._ev = np.empty((_INITIAL_ROWS, _EVENT_COLS), np.int64)
        self._order = np.argsort(self.pos[:, 0], kind="mergesort").astype(np.int64)
        self._anchor = self.pos.copy()
        self._keys = np.empty(_INITIAL_ROWS, np.int64)
        self._list_state = np.array([-1], np.int64)
        self._margin = _margin(self.step)

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events they made (EVENT_DTYPE, in order; empty if not log)."""
        cands = (self._order, self._anchor, self._keys, self._list_state, self._margin)
        ev, n_ev, self._keys = _run(
            self.pos,
            self.size,
            self.step,
            self.period,
            self.count,
            self.movable,
            self.limit,
            self.tick,
            int(ticks),
            bool(log),
            cands,
            self._ev,
        )
        self._ev = ev
        self.tick += int(ticks)
        return _event_records(ev[:n_ev], self.fps)

    def positions(self) -> np.ndarray:
        return self.pos.astype(np.float64)

    def velocities(self) -> np.ndarray:
        """Velocities in px/s: V / P * fps per component."""
        return self.step / self.period * float(self.fps)


def _margin(step: np.ndarray) -> int:
    """The candidate list's margin in px: a few of the fastest steps, within set bounds."""
    fastest = int(np.abs(step).max()) if step.size else 0
    return int(min(max(_MARGIN_STEPS * fastest, _MARGIN_MIN_PX), _MARGIN_MAX_PX))


def _whole(values: np.ndarray, what: str) -> np.ndarray:
    """The values as int64, refusing any that are not whole numbers."""
    values = np.asarray(values, np.float64)
    whole = np.rint(values)
    if not np.array_equal(whole, values):
        raise ValueError(f"the paper model needs whole-pixel {what}")
    return whole.astype(np.int64)


def _rates(vel: np.ndarray, fps: int) -> tuple[np.ndarray, np.ndarray]:
    """Steps V and periods P (int64, (n, 2)) for every velocity component, via paper_rate."""
    values, inverse = np.unique(np.asarray(vel, np.float64), return_inverse=True)
    table = np.array([paper_rate(float(v), fps) for v in values], np.int64).reshape(-1, 2)
    rates = table[inverse.reshape(-1)].reshape(vel.shape[0], 2, 2)
    return rates[:, :, 0].copy(), rates[:, :, 1].copy()


def _event_records(rows: np.ndarray, fps: int) -> np.ndarray:
    """Kernel rows -> EVENT_DTYPE records, `t` = the tick's end time in seconds."""
    out = np.zeros(rows.shape[0], EVENT_DTYPE)
    out["tick"] = rows[:, _TICK]
    out["t"] = rows[:, _TICK] / fps
    out["type"] = rows[:, _TYPE]
    out["a"] = rows[:, _A]
    out["b"] = rows[:, _B]
    out["code"] = rows[:, _CODE]
    out["xdiff"] = rows[:, _XDIFF]
    out["ydiff"] = rows[:, _YDIFF]
    return out
