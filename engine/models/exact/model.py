"""The `exact` model (docs/models.md#exact): event-driven elastic collisions, the reference for
every result.

Input: the world, the `Bodies` (copied) and the options `geometry` ("exact", the default, also
for None: circles and polygons by their real shapes; "box": every object as its box),
`max_events_per_tick`, `cell_size` (px; the grid's cell, chosen from the scene when not given:
one cell for the whole world when the grid would be at most 3 cells a side, where every cell is
in every other's 3×3 anyway and crossings would be bookkeeping for nothing, or when at most
ONE_CELL_MOVERS objects move) and `repredict`
("touched", the default; "all" predicts every moving object again after each event, the work
the local re-prediction saves, for tests and `collide2d bench`). Output, per `advance`: the
wall and pair events in the order they happened, `t` = the exact contact time; positions and
velocities at the end of the last tick.

Objects fly on straight lines between events, or under the world's gravity on parabolas (exact: `x +
v·t + ½·g·t²`). Under gravity an object whose bounce on a wall, or on a static box's face, would
rise less than `rest_height` (px, an option) rests on it (R): no speed nor gravity into it,
sliding along it against friction until it stops, or past the face's edge (`leave`), each an event
due like a wall contact (its horizon); a pair event that leaves it a speed off its support wakes
it (apply.py). Each object keeps its own clock (TLOC: its
position and velocity are valid at that time) and an invalidation counter. Two queues hold what
comes next, keyed by (time, rank, a, b) so that ties go cell crossings first (bookkeeping, never
logged), then walls by (id, side), then pairs in (a, b) order: each moving object's *horizon*, the
first of its next wall contact and its next cell crossing, filed by its time in a bucket of a
calendar queue that predicting the object again moves it out of and into in constant time
(horizonqueue.py); and the predicted contacts, in a 4-ary heap in preallocated arrays that grow when
full (heap.py), each entry recording the counters of its objects when predicted and skipped as stale
if either has changed since. The next event is, of the events at the earliest one's instant, the one
of the smallest key.

Prediction stays local. Moving objects are filed in a uniform grid (cells.py) by their box
centre. When its velocity changes (a wall, a pair; and at the first prediction) an object's
contacts are predicted against the objects in the 3×3 cells around it, and pushed when they come
no later than its next wall contact (its counter changes there, so anything later would be
stale); after a cell crossing, only against the row or column of cells it has just come next to.
So a contact between i and j is pushed before it happens: by whichever of the two last changed
velocity, if they were neighbours then, else by the crossing that made them neighbours (a centre
crosses one cell side at a time, so the cells it comes next to are that row or column). After
an event only the objects it touched are moved, counted and predicted again; a pair is swept
from the later of its two clocks, so a predicted time depends only on the pair's state, not on
when (or on which grid) it was asked. Frames sample each object at the tick's end from its own
clock.

Robust rules (contact.next_contact): touching or overlapping and approaching collide now;
overlapping and separating make no event; nothing is scheduled in the past; a pair that has just
collided is not predicted against itself again (on straight lines it cannot meet again before one
of the two has another event), so a rounding error cannot make it collide twice. Zero-time chains
(a row of touching boxes hit at one end) then run as a sequence of events at one instant. A tick
that needs more than `max_events_per_tick` events raises EventCapExceeded: a runaway is an error,
never a hang. With gravity, restitution or friction an object that meets the same partners again
and again with next to no time passing (bounces dying away that floating point never ends) stops
the run far sooner, named (NotYetExact; jam.py, an event storm).

An object with no room to move on an axis would collide again and again at one instant: one
that moves on an axis along which it touches (or overlaps) a wall or a static object on both
sides, as a box as wide as the world moving on x does. The model refuses such a scene when it is
built (`no_room` finds them; NoRoom names the object, the axis and what holds it). A jam it cannot
see up front (a row of moving objects wedged together) ends at the cap; the stopped model then
runs a few more events with the log on, and when the objects of those at the last instant are held
from both sides by a touching chain from wall or static object to wall or static object, the
error is NoRoom naming them (the hot loop keeps no record for this).

The kernel counts the wall and pair events as they happen, logged or not (`event_counts`).

The parts live in their own modules beside this one: the state layout (floats F (n, 8), ints N (n,
8), P (n, 4), R (n,), scalar state; state.py), the horizon queue (horizonqueue.py), the event queue
(a 4-ary heap; heap.py), the grid's per-cell lists (cells.py), the predictions (prediction.py), the
storm count and the words for a stop (jam.py) and the error a stopped kernel raises (stops.py, a
part of the Model class); from the shared engine, objects with no room to move (engine/noroom.py)
and the event log (engine/events.py). The events themselves are applied in apply.py (`on_cross`,
`on_wall`, `on_pair`); this module runs the main loop, `_run`: take the next event, apply it,
predict again for what it touched. The kernel `_run` (with `predict` inlined) allocates nothing:
growing the heap or the event log is done in Python between calls (the kernel stops before an event
it has no room for, and resumes)."""

from __future__ import annotations

import numpy as np

from collide2d.engine import events, models

# the cap's error, raised by way of stops.py, is the model's to name: callers import it from here
from collide2d.engine.errors import EventCapExceeded, NoRoom  # noqa: F401
from collide2d.engine.events import (
    AXIS_NAMES,
    EV_LEAVE,
    EV_PAIR,
    EV_REST,
    EV_STOP,
    EV_WAKE,
    EV_WALL,
    put_event,
)
from collide2d.engine.models.exact.apply import (
    on_cross,
    on_leave,
    on_pair,
    on_stop,
    on_wall,
    rest_on,
    start_resting,
)
from collide2d.engine.models.exact.cells import (
    build_grid,
    grid_cell,
    grid_dims,
    room_around,
    room_needed,
)
from collide2d.engine.models.exact.heap import (
    HKEY,
    INSTANT_STACK,
    MAX_OBJECTS,
    RANK_CROSS,
    RANK_PAIR,
    RANK_WALL,
    compact,
    first_of_instant,
    has_room,
    instant,
    is_valid,
    pop,
    push,
    remove,
    split_key,
)
from collide2d.engine.models.exact.horizonqueue import (
    QS_TOP,
    bucket_width,
    first_horizon,
    horizon_key,
    new_horizons,
    next_top,
)
from collide2d.engine.models.exact.jam import STORM_EVENTS, new_instants, storm_seen
from collide2d.engine.models.exact.prediction import predict, set_job
from collide2d.engine.models.exact.state import (
    AX,
    AY,
    CELL,
    INF,
    INV_MASS,
    J_EXTRA,
    J_OBJ,
    JOB_CONTACTS,
    JOB_EVENT,
    JOB_FIRST,
    JOB_ROWS,
    LEAVE,
    MU,
    PARTNER,
    S_FIRST,
    S_HEAP_N,
    S_LOGGED,
    S_PAIRS,
    S_STORM,
    S_TICK,
    S_TICK_EVENTS,
    S_WALLS,
    SF_T_NOW,
    SH,
    SHAPE,
    ST_SIZE,
    STATIC,
    STATUS_CAP,
    STATUS_CARRIED,
    STATUS_DONE,
    STATUS_HEAP_FULL,
    STATUS_LOG_FULL,
    STATUS_REST,
    STATUS_STORM,
    STOP,
    SW,
    TLOC,
    VX,
    VY,
    Cores,
    E,
    State,
    World,
    X,
    Y,
    falls,
    kernel,
    named,
    plain,
    rest_side,
    rest_support,
)
from collide2d.engine.models.exact.stops import Stops
from collide2d.engine.noroom import no_room, no_room_message
from collide2d.engine.shapes import GEOMETRIES, build_cores
from collide2d.engine.world import Bodies, WorldSpec

# Most wall and pair events one tick may take before the run is stopped as a runaway.
MAX_EVENTS_PER_TICK = models.MAX_EVENTS_PER_TICK
# After an event, predict again only the objects it touched ("touched", the model), or every
# moving object ("all": the same events and state to the bit, at the cost the local
# re-prediction saves; its heap room grows with n^2, so only for small scenes: tests and
# `collide2d bench`).
REPREDICT = ("touched", "all")
# At most this many moving objects share one cell, the whole world: testing each against the
# others costs less than the cell crossings a grid makes (the two-body chain of `collide2d bench
# --part exact`: 12 million events/s in one cell, 4 million in 4x3 cells).
ONE_CELL_MOVERS = 16
# Heap entries to start with per object (the heap drops stale entries, or doubles, when full).
HEAP_PER_OBJECT = 4
# Event log rows one event may write: a pair event and the rests it ends (wake), or a wall event
# and the rest it begins.
ROWS_PER_EVENT = 3
# A bounce on a wall that would rise less than this (px) under gravity ends it: the object rests.
REST_HEIGHT = 0.01

# --- the kernel ----------------------------------------------------------------------------------


@kernel
def _run(state, jobs, stack, tick_to, log, cap, everyone, rows, times):
    """Run ticks until tick_to: first (once) predict every object's first events; then take due
    events in order, apply each, predict again for the objects it touched. (Objects not touched
    keep their clocks; positions() moves them to the tick's end.)

    With `everyone` (the `repredict="all"` option) every other moving object is predicted again
    as well after each event (contacts only, against all but the partner of its last pair
    event): the work the local re-prediction saves. The events and the state are the same, to
    the bit: a prediction reads only the pair's state, and only an event changes it.

    Under gravity, restitution or friction each moving object's events at one instant with the
    one before, with a partner it has just met, are counted in S.instants (jam.recurs): more than
    st[S_STORM] of them (0: none counted) are an event storm.

    Returns a status: STATUS_DONE; STATUS_HEAP_FULL / STATUS_LOG_FULL (grow, call again: nothing
    was lost); STATUS_CAP (a runaway; stops mid-tick, before the event past the cap, so that a call
    with a higher cap would resume); STATUS_STORM (a storm, stopped as at the cap, the object it
    was seen on in jobs' row 0). st[S_LOGGED] counts the rows written, st[S_WALLS] and st[S_PAIRS]
    every event, logged or not. `state` is the State record as plain tuples
    (state.plain).
    """
    S = named(state)
    F, N, cells, HT, HI, HN = S.F, S.N, S.cells, S.HT, S.HI, S.HN
    st, stf, world, Q = S.st, S.stf, S.world, S.Q
    QT, QS = Q.time, Q.state
    n = F.shape[0]
    extra_room = n * n if everyone else 0
    # (The loop's steps are written out here, not as inlined helpers: helpers cost ~15 % of the
    # events per second of a two-body chain, measured with numba 0.68. Each pass makes the
    # prediction jobs of one step, then runs them at the one place that inlines `predict`.)
    while True:
        n_jobs = 0
        t = stf[SF_T_NOW]
        first = st[S_FIRST] < n
        if first:  # the first predictions, at time 0: each pair once
            i = st[S_FIRST]
            if N[i, STATIC] == 0:
                room = room_around(
                    N[i, CELL] % world.gnx, N[i, CELL] // world.gnx, N, cells, S.s_start, world
                )
                if not has_room(room, HT, HI, HN, st, N):
                    return STATUS_HEAP_FULL
                set_job(jobs, 0, i, -1, JOB_FIRST)
                n_jobs = 1
            st[S_FIRST] += 1
        else:
            if st[S_TICK] >= tick_to:
                return STATUS_DONE
            tick = st[S_TICK] + 1
            t_end = tick / world.fps
            top = QS[QS_TOP]
            if top < 0:
                top = next_top(Q)
            t_horizon = QT[top] if top >= 0 else INF
            t_pair = HT[0] if st[S_HEAP_N] > 0 else INF
            # a stale contact is dropped once it could come first (past the first horizon's
            # instant it cannot, whether stale or not)
            if (
                st[S_HEAP_N] > 0
                and t_pair <= t_horizon + instant(t_horizon)
                and not is_valid(HI, 0, N)
            ):
                pop(HT, HI, HN, st)
                continue
            t_first = min(t_pair, t_horizon)
            if t_first > t_end + instant(t_end):  # t = k/fps is tick k's
                stf[SF_T_NOW] = t_end
                st[S_TICK] = tick
                st[S_TICK_EVENTS] = 0
                continue
            # take the next event: of the valid events at the first one's instant, the one of the
            # smallest key (a horizon's key is smaller than any contact's), once the heap has room
            # for what it may push
            horizon = t_horizon <= t_first + instant(t_first)
            if horizon:
                k = first_horizon(Q, t_first + instant(t_first))
                key = horizon_key(Q, k)
            else:
                k = first_of_instant(HT, HI, st, N, stack)
                key = HI[k, HKEY]
            rank, a, b, code = split_key(key)
            room = room_needed(rank, a, b, S) + extra_room
            if HT.shape[0] - st[S_HEAP_N] < room:
                if compact(HT, HI, HN, st, N) < room:
                    return STATUS_HEAP_FULL
                continue  # the entries moved: pick again
            if log and st[S_LOGGED] + ROWS_PER_EVENT > rows.shape[0]:
                return STATUS_LOG_FULL
            # apply it: refile (a cell crossing), reflect (a wall) or exchange (a pair); count, log.
            # (A horizon stays in its slot: predicting the object again replaces it.)
            if horizon:
                t = QT[k]
            else:
                e = remove(HT, HI, HN, st, k)
                t = e.t
            stf[SF_T_NOW] = t
            if rank == RANK_CROSS:
                n_jobs = on_cross(a, b, N, cells, world, jobs)
            else:
                st[S_TICK_EVENTS] += 1
                over = st[S_TICK_EVENTS] > cap
                stormy = -1 if over else storm_seen(rank, a, b, t, S)  # the object it is seen on
                if over or stormy >= 0:  # put it back: a call with a higher cap resumes
                    st[S_TICK_EVENTS] -= 1
                    if not horizon:
                        push(HT, HI, HN, st, e)
                    if stormy >= 0:
                        set_job(jobs, 0, stormy, -1, JOB_EVENT)
                        return STATUS_STORM
                    return STATUS_CAP
                # what a (and b) rested on before: -1 nothing (nothing rests without gravity)
                rest_a = S.R[a] if falls(world) else -1
                rest_b = S.R[b] if falls(world) and rank == RANK_PAIR else -1
                if rank == RANK_WALL and b == STOP:
                    n_jobs = on_stop(a, t, S, jobs)
                    kind, b, code = EV_STOP, rest_support(rest_a), rest_side(rest_a)
                elif rank == RANK_WALL and b == LEAVE:
                    n_jobs = on_leave(a, t, S, jobs)
                    kind, b, code = EV_LEAVE, rest_support(rest_a), rest_side(rest_a)
                    if n_jobs < 0:  # a circle that would slide round the corner: stopped
                        set_job(jobs, 0, a, b, JOB_EVENT)
                        return STATUS_REST
                elif rank == RANK_WALL:
                    n_jobs = on_wall(a, b, t, S, jobs)
                    kind, b = EV_WALL, -1
                else:
                    n_jobs = on_pair(a, b, code, e.nx, e.ny, t, S, jobs)
                    kind = EV_PAIR
                    if n_jobs == -2:  # it knocks a body that carries another: stopped, named
                        return STATUS_CARRIED
                    if n_jobs < 0:  # a body would rest on the other: on a box that stays
                        n_jobs = rest_on(a, b, e.nx, e.ny, t, S, jobs)
                        if n_jobs < 0:  # on anything else it cannot: stopped, the pair named
                            set_job(jobs, 0, a, b, JOB_EVENT)
                            return STATUS_REST
                        a = jobs[0, J_OBJ]
                        kind, b, code = EV_REST, rest_support(S.R[a]), rest_side(S.R[a])
                if n_jobs > 0:  # a pair that was not approaching is no event
                    if kind == EV_WALL:
                        st[S_WALLS] += 1
                    elif kind == EV_PAIR:
                        st[S_PAIRS] += 1
                    if log:
                        put_event(rows, times, st[S_LOGGED], tick, t, kind, a, b, code)
                        st[S_LOGGED] += 1
                        # the modes the event changed: a rest it began, the rests it ended
                        if kind == EV_WALL and rest_a < 0 and S.R[a] >= 0:
                            put_event(rows, times, st[S_LOGGED], tick, t, EV_REST, a, -1, code)
                            st[S_LOGGED] += 1
                        for i, was in ((a, rest_a), (b, rest_b)):
                            if kind == EV_PAIR and was >= 0 and S.R[i] < 0:
                                put_event(
                                    rows,
                                    times,
                                    st[S_LOGGED],
                                    tick,
                                    t,
                                    EV_WAKE,
                                    i,
                                    rest_support(was),
                                    rest_side(was),
                                )
                                st[S_LOGGED] += 1
        # predict again for what the step touched (and after an event with `everyone`, for
        # every other moving object: contacts only, not against the partner of its last pair)
        extra = 0 if everyone and not first and n_jobs > 0 else n
        k = 0
        while True:
            if k < n_jobs:
                job = k
                k += 1
            else:
                while extra < n and (
                    N[extra, STATIC] != 0
                    or extra == jobs[0, J_OBJ]
                    or (n_jobs > 1 and extra == jobs[1, J_OBJ])
                ):
                    extra += 1
                if extra >= n:
                    break
                set_job(jobs, J_EXTRA, extra, N[extra, PARTNER], JOB_CONTACTS)
                job = J_EXTRA
                extra += 1
            predict(jobs, job, t, S)


class Model(Stops):
    """Event-driven elastic model; see the module docstring. Surface as in engine.models."""

    def __init__(
        self,
        world: WorldSpec,
        bodies: Bodies,
        geometry: str | None = None,
        max_events_per_tick: int = MAX_EVENTS_PER_TICK,
        cell_size: float | None = None,
        repredict: str = "touched",
        rest_height: float = REST_HEIGHT,
    ):
        geometry = "exact" if geometry is None else geometry
        if geometry not in GEOMETRIES:
            raise ValueError(f"unknown geometry {geometry!r}; expected one of {GEOMETRIES}")
        if int(max_events_per_tick) != max_events_per_tick or max_events_per_tick < 1:
            raise ValueError(f"max_events_per_tick must be >= 1, got {max_events_per_tick!r}")
        if bodies.n >= MAX_OBJECTS:
            raise ValueError(f"the exact model handles fewer than {MAX_OBJECTS} objects")
        if cell_size is not None and not cell_size > 0:
            raise ValueError(f"cell_size must be > 0 px, got {cell_size!r}")
        if repredict not in REPREDICT:
            raise ValueError(f"repredict must be one of {REPREDICT}, got {repredict!r}")
        if not rest_height >= 0:
            raise ValueError(f"rest_height must be >= 0 px, got {rest_height!r}")
        stuck = no_room(world, bodies, geometry)
        if stuck:
            raise NoRoom(
                no_room_message(stuck, bodies),
                tuple(w.obj for w in stuck),
                AXIS_NAMES[stuck[0].axis],
            )
        self.repredict = repredict
        self.world = world
        self.geometry = geometry
        self.max_events_per_tick = int(max_events_per_tick)
        self.tick = 0
        self._broken = None
        n = bodies.n
        static = np.asarray(bodies.static, bool)
        cores = build_cores(bodies, geometry)
        self._F = np.zeros((n, 8))
        self._F[:, X : Y + 1] = bodies.pos
        self._F[:, VX : VY + 1] = np.where(static[:, None], 0.0, bodies.vel)
        self._F[:, SW : SH + 1] = bodies.size
        self._F[:, INV_MASS] = bodies.inv_mass
        self._P = np.zeros((n, 4))
        self._P[~static, AX : AY + 1] = world.gravity
        self._P[:, E] = bodies.restitution
        self._P[:, MU] = bodies.friction
        self._R = np.full(n, -1, np.int64)
        self._instants = new_instants(n)
        self.gravity = world.has_gravity
        self._N = np.zeros((n, 8), np.int64)
        self._N[:, PARTNER] = -1
        self._N[:, STATIC] = static
        self._N[:, SHAPE] = cores.shape
        self._C = Cores(cores.radius, cores.start, cores.verts, cores.normals)
        if cell_size is None:
            cell_size = grid_cell(world.width, world.height, bodies.size, static)
            few = int((~static).sum()) <= ONE_CELL_MOVERS
            if few or max(grid_dims(world.width, world.height, cell_size)) <= 3:
                # every cell is in every other's 3x3 (or there are few to test): one cell sees
                # the same neighbours (or few) and spares the cell crossings (the grid never
                # changes the answer)
                cell_size = float(max(world.width, world.height))
        self.cell_size = float(cell_size)
        gnx, gny = grid_dims(world.width, world.height, self.cell_size)
        plain = world.restitution == 1.0 and world.friction == 0.0  # the walls'
        self._world = World(
            float(world.width),
            float(world.height),
            float(world.fps),
            self.cell_size,
            gnx,
            gny,
            float(world.restitution),
            float(world.friction),
            float(world.gravity[0]),
            float(world.gravity[1]),
            float(rest_height),
            bool(plain and not self.gravity and np.all(self._P[:, E : MU + 1] == (1.0, 0.0))),
        )
        start_resting(self._F, self._N, self._P, self._R, self._world)
        self._G = build_grid(self._F, self._N, self.cell_size, gnx, gny)
        cap = max(64, HEAP_PER_OBJECT * n)
        self._heap = [np.empty(cap), np.empty((cap, 3), np.int64), np.empty((cap, 2))]
        self._plain = None  # the state as the kernel takes it, made again when the heap grows
        self._horizons = new_horizons(
            static, bucket_width(self._F, static, self.cell_size, world.width, world.height)
        )
        self._st = np.zeros(ST_SIZE, np.int64)
        self._stf = np.zeros(1)
        self._jobs = np.zeros((JOB_ROWS, 3), np.int64)  # scratch: the prediction jobs of one event
        self._stack = np.zeros(INSTANT_STACK, np.int64)  # scratch: walking one instant's entries

    def _state(self) -> State:
        """The arrays the kernels share."""
        cells, s_start, s_items = self._G
        HT, HI, HN = self._heap
        return State(self._F, self._N, self._P, self._R, self._instants, self._C, cells,
                     s_start, s_items, HT, HI, HN, self._horizons, self._st, self._stf,
                     self._world)  # fmt: skip

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events in the order they happened (empty when log is False)."""
        if self._broken:
            raise self._broken
        rows, times = events.new_log(log)
        self._st[S_LOGGED] = 0
        target = self.tick + int(ticks)
        while True:
            status = self._call(target, bool(log), self.max_events_per_tick, rows, times)
            if status == STATUS_HEAP_FULL:
                self._grow_heap()
            elif status == STATUS_LOG_FULL:
                rows, times = events.grown(rows), events.grown(times)
            elif status != STATUS_DONE:  # stopped: at the cap, a storm or a rest (stops.py)
                self._broken = self._stopped(status)
                raise self._broken
            else:
                break
        self.tick = int(self._st[S_TICK])
        return events.event_records(rows, times, int(self._st[S_LOGGED]))

    def _call(self, target, log, cap, rows, times, storm=None) -> int:
        """One call of the kernel `_run` on the model's state, counting storms past `storm`
        repeats (default jam.STORM_EVENTS; 0: none); its status. (Interpreted, a time past
        float64's range, as a subnormal speed gives, is inf as compiled, and inf - inf is nan as
        compiled: no numpy warning.)"""
        everyone = self.repredict == "all"
        self._st[S_STORM] = STORM_EVENTS if storm is None else storm
        with np.errstate(over="ignore", invalid="ignore"):
            if self._plain is None:
                self._plain = plain(self._state())
            state = self._plain
            return _run(state, self._jobs, self._stack, target, log, cap, everyone, rows, times)

    def _grow_heap(self) -> None:
        """Twice the heap's room, its entries kept."""
        self._heap = [events.grown(a) for a in self._heap]
        self._plain = None

    def event_counts(self) -> tuple[int, int]:
        """(wall events, pair events) so far, logged or not."""
        return int(self._st[S_WALLS]), int(self._st[S_PAIRS])

    def rests(self) -> dict[int, tuple[int, int]]:
        """{object: (side, support)} of the objects resting now: the side each presses into
        (SIDE_*) and the object it rests on, -1 for a wall (docs/models.md#exact-under-gravity)."""
        side, support = rest_side.py_func, rest_support.py_func  # (plain Python: nothing compiles)
        return {int(i): (side(int(r)), support(int(r))) for i, r in enumerate(self._R) if r >= 0}

    def positions(self) -> np.ndarray:
        """(n, 2) float64 top-left corners at the last tick's end, px (each object carried from
        its own clock; kept inside the world against the last rounding)."""
        F = self._F
        t = self.tick / self._world.fps
        dt = t - F[:, TLOC : TLOC + 1]
        pos = F[:, X : Y + 1] + F[:, VX : VY + 1] * dt
        if self.gravity:
            pos += 0.5 * self._P[:, AX : AY + 1] * dt * dt
        limit = np.array([self._world.width, self._world.height]) - F[:, SW : SH + 1]
        return np.minimum(np.maximum(pos, 0.0), limit)

    def velocities(self) -> np.ndarray:
        """(n, 2) float64 velocities at the last tick's end, px/s."""
        F = self._F
        if not self.gravity:
            return F[:, VX : VY + 1].copy()
        t = self.tick / self._world.fps
        return F[:, VX : VY + 1] + self._P[:, AX : AY + 1] * (t - F[:, TLOC : TLOC + 1])
