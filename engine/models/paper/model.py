"""The paper's model, reproduced exactly in integers (docs/models.md#paper; paper sections
II.D-II.F).

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
overlap. The broad phase (broadphase.py: sort-and-sweep or a grid, chosen by the scene) lists the
pairs whose reach boxes, each grown by its object's own margin, overlap. An object's margin on an
axis is how far its counter can carry it in the next few ticks (|V| x the steps it fires in them:
a pair or a wall only reverses a step or takes it back), at most _MARGIN_MAX_PX, so a slow object's
box grows little and one that will not step in that window not at all; the range of positions its
grown box allows is its *fence*. The list is kept until some object is past its fence (every
position held since then lies in its grown box), and only then made anew, whole. Each tick then
keeps the listed pairs whose reach boxes overlap now, sorts those few by (a, b) and applies the
rule to them in that order, testing each on the current positions: exactly the all-pairs loop of
the paper. Pairs of two static objects are never listed, and with no movable object the pair stage
is skipped (`skip=False` turns both skips off; `broadphase`, "sweep", "grid" or "cells", forces a
method instead of the scene's choice).

The tick loop is one numba kernel run without reference counting (it allocates nothing); when the
event log or the candidate list needs more room it stops at a stage boundary, the buffer grows in
Python, and the next call resumes the same tick where it stopped. `Model.profile` runs the same
kernel one stage at a time (STAGES) to time each. For scenes of threads.PARALLEL_MIN_OBJECTS
objects or more the move stage (with the walls), the pair tests of the cells broad phase and the
narrow stage split their work among threads in fixed contiguous chunks joined in chunk order (the
wall events in id order, the near pairs sorted), so any thread count gives the same bytes. The
state is int32 when the world allows it (half the memory each tick streams through).
"""

from __future__ import annotations

import time

import numpy as np

from collide2d.engine.broadphase import (
    KEY_MASK,
    KEY_SHIFT,
    choose,
    find_split,
    marker,
    workspace,
)
from collide2d.engine.events import (
    AXIS_X,
    AXIS_XY,
    AXIS_Y,
    EV_PAIR,
    EV_WALL,
    ROW_TICK,
    SIDE_BOTTOM,
    SIDE_LEFT,
    SIDE_RIGHT,
    SIDE_TOP,
    event_records,
    grown,
    new_log,
    put_row,
)
from collide2d.engine.jit import njit, prange
from collide2d.engine.models.paper.records import Lists, Plan, State
from collide2d.engine.motion import paper_rate
from collide2d.engine.sort import sort_keys
from collide2d.engine.splitchoice import SplitChoice
from collide2d.engine.threads import chunks_for, join_shares
from collide2d.engine.world import Bodies, WorldSpec

# The kernel writes the event log of events.py without its times: `t` is added in Python as the
# tick's end, tick / fps.
# Room for events and candidate pairs before the buffers grow (rows; they double when full).
_INITIAL_ROWS = 1024
# The candidate list is made with each object's reach box grown by its own margin (px, per axis):
# the farthest its counter lets it move in the next _WINDOW_TICKS ticks (its step times the steps
# its counter fires in them), at most _MARGIN_MAX_PX; the list is kept until some object has moved
# past its margin from where it was when the list was made (its *fence*). A slow object's box
# grows little, an object that will not step in the window not at all, and one fast object makes
# only its own box large, not everyone's.
_WINDOW_TICKS = 16
_MARGIN_MAX_PX = 32
# A step longer than _MARGIN_MAX_PX takes its object past its fence, so the list is made anew at
# every tick such a step fires. Counters all start at 0 and only ever count ticks, so those ticks
# are known (the multiples of those steps' periods): when the next one is at most
# _WINDOW_MAX_TICKS ticks away, the window reaches just up to it instead, which saves making the
# list once more shortly before it.
_WINDOW_MAX_TICKS = 24
# The state, reach boxes and fences are kept in int32 when the world, steps, margins and sides keep
# them within this (px).
REACH_INT32_MAX = 2**30

# The kernel's scalar state (int64): ticks done, the stage of the next tick to run, candidates
# listed (-1: none yet), whether the list is to be made anew this tick (an object is past its
# fence), event rows written in this `advance`, the candidates a too small buffer needed, whether
# pairs can happen at all, wall events and pair events so far (logged or not), this tick's
# overlapping candidate pairs.
_S_TICK, _S_STAGE, _S_KEYS, _S_RELIST, _S_EVENTS, _S_NEEDED, _S_PAIRS = range(7)
_S_WALLS, _S_PAIR_EVENTS, _S_NEAR = 7, 8, 9
_S_SIZE = 10
# The stages of a tick, in the order `_run` runs them (it can stop after any of them): move takes
# the walls too, object by object.
_STAGE_MOVE, _STAGE_BROAD, _STAGE_NARROW, _STAGE_RESPONSE = range(4)
_N_STAGES = 4
# The stages `Model.profile` times, each by name with the stage it runs up to (_N_STAGES: the
# tick's end).
STAGES = (
    ("move", _STAGE_BROAD),
    ("broad", _STAGE_NARROW),
    ("narrow", _STAGE_RESPONSE),
    ("response", _N_STAGES),
)
# What a call of the kernel ends with: done, or stopped for more room (grow, call again).
_DONE, _LOG_FULL, _KEYS_FULL = range(3)

# The kernel allocates nothing and only touches arrays handed to it, so it is compiled without
# numba's reference counting (`_nrt=False`, a private numba option; tests/engine/test_kernels.py
# compiles every kernel that uses it, so an upgrade that drops it fails loudly): counting
# references at every inlined helper took most of the run time on event-heavy scenes (~85 %).
_kernel = njit(cache=True, _nrt=False)


@njit(cache=True, inline="always")
def _move(S, disp, fence, first, last, tick, log, ev, n_ev):
    """Move and walls for objects first ... last-1 of the State S, object by object in id order
    (docs/models.md#paper-walls): counters rise by one and a component whose counter reaches its
    period moves by its step; one that left the world moving outward reverses and takes that step
    back (a wall event, logged from row n_ev on). disp receives this tick's displacements; fence
    is Lists.fence. Returns (event rows, whether any object is now past its fence, wall events).
    """
    pos, step, period, count, room = S.pos, S.step, S.period, S.count, S.room
    strayed = False
    walls = 0
    for i in range(first, last):
        for ax in range(2):
            c = count[i, ax] + 1
            fire = c >= period[i, ax]
            count[i, ax] = 0 if fire else c
            d = step[i, ax] if fire else 0
            p = pos[i, ax] + d
            if ((d < 0) & (p < 0)) | ((d > 0) & (p > room[i, ax])):
                if d < 0:
                    side = SIDE_LEFT if ax == 0 else SIDE_TOP
                else:
                    side = SIDE_RIGHT if ax == 0 else SIDE_BOTTOM
                step[i, ax] = -d
                p -= d
                d = 0
                walls += 1
                if log:
                    n_ev = put_row(ev, n_ev, tick, EV_WALL, i, -1, side, -1, -1)
            pos[i, ax] = p
            disp[i, ax] = d
            strayed |= (p < fence[i, 2 * ax]) | (p > fence[i, 2 * ax + 1])
    return n_ev, strayed, walls


@njit(cache=True, parallel=True)
def _move_split(S, L, tick, log, ev, n_ev):
    """`_move` with the objects cut into len(L.found) contiguous runs, one per thread: run c logs
    its walls from row n_ev + 2 x its first object (an object meets at most two walls a tick),
    then the rows are moved together in run order, as one thread writes them. Each run also
    writes its objects' reach boxes (`_reach`) for the narrow stage, so that the threads start
    once less a tick. Returns what `_move` returns for all objects; L.found is scratch."""
    pos, size, disp, fence, reach, found = S.pos, S.size, L.disp, L.fence, L.reach, L.found
    n = pos.shape[0]
    chunks = found.shape[0]
    for c in prange(chunks):
        first = c * n // chunks
        last = (c + 1) * n // chunks
        row = n_ev + 2 * first
        end, strayed, walls = _move(S, disp, fence, first, last, tick, log, ev, row)
        _reach(pos, size, disp, reach, first, last)
        found[c, 0] = end - row
        found[c, 1] = strayed
        found[c, 2] = walls
    k = n_ev
    strayed = False
    walls = 0
    for c in range(chunks):
        row = n_ev + 2 * (c * n // chunks)
        for r in range(found[c, 0]):
            if k != row + r:
                for col in range(ev.shape[1]):
                    ev[k, col] = ev[row + r, col]
            k += 1
        strayed |= found[c, 1] != 0
        walls += found[c, 2]
    return k, strayed, walls


@njit(cache=True)
def _relist(S, L, window, cap, cell, found):
    """List the pairs whose reach boxes, each grown by its object's margin, overlap (keys
    a << KEY_SHIFT | b, a < b, in no particular order); pairs of two immovable objects are left
    out. Returns how many there are; only as many as `keys` holds are written.

    An object's margin on an axis is how far its counter can move it in the next `window` ticks
    (`_window`), |V| x the steps it fires in them (a pair or a wall only reverses or takes a step
    back), at most `cap` px, from either end of this tick's step (the pair stage may take it
    back); its fence is that range of positions. While every object stays within its fence, every
    box it holds lies in its grown reach box, so every pair that can overlap is listed. found
    (chunks,) int64 is the pair tests' scratch."""
    pos, size, step, period, count = S.pos, S.size, S.step, S.period, S.count
    disp, fence, lo, hi = L.disp, L.fence, L.lo, L.hi
    for i in range(pos.shape[0]):
        for ax in range(2):
            d = disp[i, ax]
            p = pos[i, ax]
            fires = (count[i, ax] + window) // period[i, ax]
            margin = min(min(abs(step[i, ax]), cap) * fires, cap)  # no product past int32
            low = p - max(d, 0) - margin
            high = p - min(d, 0) + margin
            fence[i, 2 * ax] = low
            fence[i, 2 * ax + 1] = high
            lo[i, ax] = low
            hi[i, ax] = high + size[i, ax]
    return find_split(L.finder, lo, hi, S.movable, cell, L.order, L.keys, L.ws, found)


@njit(cache=True, inline="always")
def _window(tick, forced, window, longest):
    """The window (ticks) of a list made at `tick`: up to the tick before the next at which a step
    of one of the periods `forced` fires (the multiples of each), when that is at most `longest`
    ticks on, else `window`."""
    ahead = longest + 1
    for p in range(forced.shape[0]):
        every = forced[p]
        ahead = min(ahead, (tick // every + 1) * every - tick - 1)
    return ahead if ahead <= longest else window


@njit(cache=True, inline="always")
def _reach(pos, size, disp, reach, first, last):
    """The reach boxes of objects first ... last-1 into reach (n, 4) = [x lo, x hi, y lo, y hi]:
    the hull of each box before and after this tick's step, all the pair stage can put it at,
    side by side in one row per object, so that testing a pair reads one row of each object
    rather than its position, displacement and size from three arrays."""
    for i in range(first, last):
        for ax in range(2):
            d = disp[i, ax]
            low = pos[i, ax] - max(d, 0)
            reach[i, 2 * ax] = low
            reach[i, 2 * ax + 1] = low + abs(d) + size[i, ax]


@njit(cache=True, inline="always")
def _near_range(keys, first, last, near, base, reach):
    """The pairs keys[first:last] whose reach boxes overlap, into near[base:], in the order
    listed; returns how many."""
    k = 0
    for c in range(first, last):
        a = keys[c] >> KEY_SHIFT
        b = keys[c] & KEY_MASK
        meet = (
            (reach[b, 0] < reach[a, 1])
            & (reach[a, 0] < reach[b, 1])
            & (reach[b, 2] < reach[a, 3])
            & (reach[a, 2] < reach[b, 3])
        )
        near[base + k] = keys[c]
        k += meet
    return k


@njit(cache=True, inline="always")
def _near(pos, size, disp, keys, n_keys, near, reach):
    """The listed pairs whose reach boxes overlap now, into `near` (as long as `keys`), sorted by
    (a, b); returns how many. reach (n, 4) receives the reach boxes (`_reach`)."""
    _reach(pos, size, disp, reach, 0, pos.shape[0])
    k = np.int64(_near_range(keys, 0, n_keys, near, 0, reach))  # np.int64: one sort_keys
    sort_keys(near, k)
    return k


@njit(cache=True, parallel=True)
def _near_split(keys, n_keys, near, reach, found):
    """`_near` on the reach boxes `_move_split` wrote, with the listed pairs cut into len(found)
    contiguous runs, one per thread, each into its own share of `near` (at least n_keys +
    len(found) long); the shares are moved together and sorted, the same pairs in the same order
    as `_near`. found (chunks,) int64 is scratch."""
    chunks = found.shape[0]
    share = (n_keys + chunks - 1) // chunks
    for c in prange(chunks):
        found[c] = _near_range(
            keys, c * n_keys // chunks, (c + 1) * n_keys // chunks, near, c * share, reach
        )
    k = join_shares(found, share, near)
    sort_keys(near, k)
    return k


@njit(cache=True, inline="always")
def _pairs(S, disp, near, n_near, tick, log, ev, n_ev, st):
    """The flip rule on every overlapping pair of `near`, in (a, b) order
    (docs/models.md#paper-pairs)."""
    pos, size, step = S.pos, S.size, S.step
    for c in range(n_near):
        a = near[c] >> KEY_SHIFT
        b = near[c] & KEY_MASK
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
        st[_S_PAIR_EVENTS] += 1
        if log:
            n_ev = put_row(ev, n_ev, tick, EV_PAIR, a, b, axis, xdiff, ydiff)
    return n_ev


@_kernel
def _run(state, settings, lists, st, stop, log, ev):
    """Run stage after stage until st[_S_TICK] * _N_STAGES + st[_S_STAGE] = stop (advance: ticks
    done x _N_STAGES, a tick's end); returns _DONE, or _LOG_FULL / _KEYS_FULL when `ev` or the
    candidate buffers need more room (grow them and call again: the tick resumes at the stage it
    stopped). state, settings, lists: the fields of a State, a Plan and a Lists, as plain tuples
    (numba reads a plain tuple's type in a fraction of the time it takes for a named tuple: a few
    microseconds a call); st: the scalar state (see _S_*)."""
    S, plan, L = State(*state), Plan(*settings), Lists(*lists)
    keys, near, disp, reach, found = L.keys, L.near, L.disp, L.reach, L.found
    chunks = plan.chunks
    n = S.pos.shape[0]
    n_ev = st[_S_EVENTS]
    while st[_S_TICK] * _N_STAGES + st[_S_STAGE] < stop:
        tick = st[_S_TICK] + 1
        stage = st[_S_STAGE]
        if stage == _STAGE_MOVE:
            # move and walls: counters fire, what left the world moving outward reverses and
            # takes its step back; the displacement kept is what a pair takes back
            if log and n_ev + 2 * n > ev.shape[0]:
                st[_S_EVENTS] = n_ev
                return _LOG_FULL
            if chunks > 1:
                n_ev, strayed, walls = _move_split(S, L, tick, log, ev, n_ev)
            else:
                n_ev, strayed, walls = _move(S, disp, L.fence, 0, n, tick, log, ev, n_ev)
            st[_S_WALLS] += walls
            # the list is made anew once an object is past its fence
            st[_S_RELIST] = st[_S_KEYS] < 0 or strayed
        elif not st[_S_PAIRS]:
            pass  # no pair can happen: the pair stages do nothing
        elif stage == _STAGE_BROAD:
            # broad: the candidate list, when it is to be made anew
            if st[_S_RELIST]:
                window = _window(tick, L.forced, plan.window, plan.longest)
                k = _relist(S, L, window, plan.cap, plan.cell, found[:chunks, 0])
                if k > keys.shape[0]:
                    st[_S_NEEDED] = k
                    st[_S_EVENTS] = n_ev
                    return _KEYS_FULL
                st[_S_KEYS] = k
                st[_S_RELIST] = 0
        elif stage == _STAGE_NARROW:
            # narrow: the listed pairs whose reach boxes overlap, in (a, b) order
            if chunks > 1:
                st[_S_NEAR] = _near_split(keys, st[_S_KEYS], near, reach, found[:, 0])
            else:
                st[_S_NEAR] = _near(S.pos, S.size, disp, keys, st[_S_KEYS], near, reach)
        else:
            # response: the rule on each of them
            if log and n_ev + st[_S_NEAR] > ev.shape[0]:
                st[_S_EVENTS] = n_ev
                return _LOG_FULL
            n_ev = _pairs(S, disp, near, st[_S_NEAR], tick, log, ev, n_ev, st)
        if stage == _STAGE_RESPONSE:
            st[_S_STAGE] = _STAGE_MOVE
            st[_S_TICK] = tick
        else:
            st[_S_STAGE] = stage + 1
    st[_S_EVENTS] = n_ev
    return _DONE


class Model:
    """The paper model over integer state: positions, sizes, steps V, periods P, counters."""

    def __init__(
        self,
        world: WorldSpec,
        bodies: Bodies,
        skip: bool = True,
        broadphase: str | None = None,
    ):
        self.world = world
        self.fps = int(world.fps)
        self.tick = 0
        pos = _whole(bodies.pos, "positions")
        size = _whole(bodies.size, "sizes")
        step, period = _rates(bodies.vel, self.fps)
        # the state in int32 when the world allows (half the memory each tick streams through)
        small = _reach_dtype(world, size, step)
        if pos.size and int(np.abs(pos).max()) > REACH_INT32_MAX // 2:
            small = np.int64  # objects placed far outside the world
        n = pos.shape[0]
        limit = np.array([world.width, world.height], np.int64)
        self._S = State(
            pos=pos.astype(small),
            size=size.astype(small),
            room=np.ascontiguousarray(limit - size).astype(small),
            step=step.astype(small),
            period=period.astype(small),
            count=np.zeros(step.shape, small),
            movable=~np.asarray(bodies.static, bool) if skip else np.ones(n, bool),
        )
        self._ev = new_log(True, _INITIAL_ROWS)[0]
        self._st = np.zeros(_S_SIZE, np.int64)
        self._st[_S_KEYS] = -1
        self._st[_S_PAIRS] = n >= 2 and (bool(self._S.movable.any()) or not skip)
        grown = self._S.size + 2 * _margins(self._S.step, self._S.period)
        method, cell = choose(world.width, world.height, grown, broadphase)
        chunks = chunks_for(n)
        self._plan = Plan(
            window=_WINDOW_TICKS,
            cap=_MARGIN_MAX_PX,
            longest=_WINDOW_MAX_TICKS,
            cell=float(cell),
            chunks=chunks,
        )
        long_steps = np.abs(self._S.step) > _MARGIN_MAX_PX
        keys = max(_INITIAL_ROWS, 2 * n)
        self._lists = Lists(
            order=np.argsort(self._S.pos[:, 0], kind="stable").astype(np.int64),
            fence=np.zeros((n, 4), small),
            keys=np.empty(keys, np.int64),
            near=np.empty(keys + chunks, np.int64),
            disp=np.zeros((n, 2), small),
            lo=np.empty((n, 2), np.int64),
            hi=np.empty((n, 2), np.int64),
            found=np.zeros((chunks, 3), np.int64),
            # each once, sorted: np.unique would import numpy.ma
            forced=np.array(sorted(set(period[long_steps].tolist())), np.int64),
            finder=marker(method),
            reach=np.empty((n, 4), small),
            ws=workspace(n, np.int64),
        )
        self._args = None
        self._split = SplitChoice(chunks)

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events they made (EVENT_DTYPE, in order; empty if not log).
        A scene that splits runs them split among threads or not, as the clock says
        (splitchoice): the same bytes either way."""
        self._st[_S_EVENTS] = 0
        self._split.run(int(ticks), lambda k, chunks: self._ticks(k, bool(log), chunks))
        n = int(self._st[_S_EVENTS])
        return event_records(self._ev, self._ev[:n, ROW_TICK] / self.fps, n)

    def advance_to_response(self, log: bool = True) -> np.ndarray:
        """Run the next tick up to its response stage, where every object has moved (and the
        walls have taken their steps back) but no pair has flipped or taken back anything yet:
        `positions()` are then the places the pair rule sees, overlaps included (the paper's
        Figure 2). `advance(1)` finishes the tick. Returns the events so far (its walls)."""
        self._st[_S_EVENTS] = 0
        self._run_to(self.tick * _N_STAGES + _STAGE_RESPONSE, bool(log))
        n = int(self._st[_S_EVENTS])
        events = event_records(self._ev, self._ev[:n, ROW_TICK] / self.fps, n).copy()
        self._st[_S_EVENTS] = 0
        return events

    def event_counts(self) -> tuple[int, int]:
        """(wall events, pair events) so far, logged or not."""
        return int(self._st[_S_WALLS]), int(self._st[_S_PAIR_EVENTS])

    def profile(self, ticks: int) -> dict[str, float]:
        """Run `ticks` ticks with the event log off, one stage of `_run` at a time, and return the
        seconds spent in each (STAGES): "move" (counters and walls), "broad" (making
        the candidate list), "narrow" (keeping the listed pairs whose reach boxes overlap),
        "response" (the flip rule). The state ends exactly as `advance(ticks, log=False)` would
        leave it. Each stage is timed from Python, so each count includes a call's overhead
        (microseconds), which dominates in small scenes. A scene that splits runs split (the
        clock does not choose here)."""
        self._chunks(self._split.chunks)
        spent = {name: 0.0 for name, _ in STAGES}
        clock = time.perf_counter
        for _ in range(int(ticks)):
            done = self.tick * _N_STAGES
            for name, until in STAGES:
                began = clock()
                self._run_to(done + until, False)
                spent[name] += clock() - began
        return spent

    def _ticks(self, ticks: int, log: bool, chunks: int) -> None:
        """Run `ticks` ticks, the split stages cut into `chunks` (1: not split); their events
        are added to the log."""
        self._chunks(chunks)
        self._run_to((self.tick + ticks) * _N_STAGES, log)

    def _chunks(self, chunks: int) -> None:
        """Cut the split stages into `chunks` from now on (1: not split)."""
        if self._plan.chunks != chunks:
            self._plan = self._plan._replace(chunks=int(chunks))
            self._args = None

    def _run_to(self, stop: int, log: bool) -> None:
        """Run `_run` to `stop` (ticks done x _N_STAGES + stage), growing the buffers it asks
        to grow."""
        while True:
            if self._args is None:  # `_run` takes them as plain tuples
                self._args = (tuple(self._S), tuple(self._plan), tuple(self._lists))
            status = _run(*self._args, self._st, stop, log, self._ev)
            if status == _DONE:
                break
            if status == _LOG_FULL:
                self._ev = grown(self._ev, 2 * self._S.pos.shape[0])
            else:
                rows = 2 * int(self._st[_S_NEEDED])
                self._lists = self._lists._replace(
                    keys=np.empty(rows, np.int64),
                    near=np.empty(rows + self._split.chunks, np.int64),
                )
                self._args = None
        self.tick = int(self._st[_S_TICK])

    def positions(self) -> np.ndarray:
        return self._S.pos.astype(np.float64)

    def velocities(self) -> np.ndarray:
        """Velocities in px/s: V / P * fps per component."""
        return self._S.step / self._S.period * float(self.fps)


def _reach_dtype(world: WorldSpec, size: np.ndarray, step: np.ndarray):
    """int32 for the state, reach boxes and fences when every value they can hold (a position in
    the world, less or plus a step and a margin, plus a side; a period) fits it with room to
    spare, so that they take half the cache; else int64."""
    far = max(int(world.width), int(world.height)) + _MARGIN_MAX_PX
    far += 2 * (int(np.abs(step).max()) if step.size else 0) + (int(size.max()) if size.size else 0)
    return np.int32 if far <= REACH_INT32_MAX else np.int64


def _margins(step: np.ndarray, period: np.ndarray) -> np.ndarray:
    """Each object's margins (n, 2) px as a list made at a random moment would give them on
    average (|V| x _WINDOW_TICKS / P, at most _MARGIN_MAX_PX), for choosing the broad phase."""
    return np.minimum(np.abs(step) * _WINDOW_TICKS / period, _MARGIN_MAX_PX)


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
