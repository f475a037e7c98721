"""The `stepped` model (docs/models.md#stepped): fixed-step elastic collisions with float state.

Input: the world, the `Bodies` (copied: the model owns its state) and the options `substeps`
(each tick split into that many equal steps of 1/(fps·substeps) s) and `geometry` ("box", the
default, also for None: every object collides as its box; "exact": by its real shape, shapes.py).
Output, per `advance`: the events of the ticks run, walls and responding pairs, `t` = the tick's
end.

Each step runs move -> walls -> pairs. Walls reflect exactly as a wall would (response.fold).
Pairs: the candidates are the pairs whose boxes overlap after the walls, or overlapped during the
step (a corner passed through within it, found by sweeping the pair back along its relative
velocity), taken in the order their contacts began (swept back the same way; ties and pairs whose
overlap began before the step, first, in ascending (a, b) order), each tested again on the current
state so that it sees what the pairs before it changed (a pair that only comes to overlap through
such a push waits for the next step). A pair in contact that approaches along the contact normal
gets the elastic exchange. The normal is the axis along which the pair started overlapping, found
from its relative velocity (approach.box_step_contact; for exact shapes the direction of
approach, approach.step_contact), and the pair is pushed apart along it, shared by inverse mass,
never out of the world, by twice the depth it went in since that instant: each object ends where a
bounce at the contact instant would have put it, as the walls reflect. Only when the motion cannot
tell (the overlap began before the previous step, or nothing moves) the axis of the smaller overlap
decides, and the push is that depth once.

Finding the overlapping pairs without testing them all (a Verlet list): the broad phase
(broadphase.py, sort-and-sweep or a grid chosen by the scene) lists the pairs whose boxes, each
grown by a margin of MARGIN_STEPS of the fastest step, overlap, and the list is kept until some
object has drifted that margin from where it was when the list was made. While no object has, any
pair overlapping now was on the list (each box moved less than the margin), so each step only
tests the listed pairs on the current boxes (and their sweeps over the step: each box's path lies
within its margin too), sorts the few in contact, and takes them in that order: exactly the
pairs, in exactly the order, of testing every pair. The same argument pair by pair lets a step
skip the listed pairs that were farther apart than twice the drift so far: the list is kept in
bands by that distance (candidates.reach_bands), within buckets by the block of rows its pairs
sit in, so that while the list holds a step tests each block's pairs right behind the block's
move, from the cache (narrow.move_narrow). Pairs of two static
objects are never listed, and with no movable object (or fewer than two objects) the pair stage is
skipped; the `skip=False` option turns both skips off, and `broadphase` ("sweep", "grid",
"cells") forces a method instead of the scene's choice (for tests and `collide2d bench`).

Events go to the one event log of events.py. The step's stages are one kernel,
`step.step` (STAGES: move, broad, narrow, response), each stage in a module of its own:
`move` (move and walls), `candidates` (the candidate list and the order the objects
are kept in), `narrow` (the listed pairs in contact, in order) and `pairs` (the
exchange and the push). `step.run` runs all of them every step of many ticks in one call,
`Model.profile` the same kernel one stage at a time to time each. The state is a `State`: one row
of 6 floats per object (position, velocity, size), so that a stage reads everything it needs of
an object from one place in memory.
"""

from __future__ import annotations

import time

import numpy as np

from collide2d.engine.broadphase import KEY_SHIFT, METHOD_SWEEP, choose, marker, workspace
from collide2d.engine.events import event_records, new_log
from collide2d.engine.models.stepped.candidates import (
    BAND_SHIFT,
    PARAMS_SIZE,
    ST_CHUNKS,
    ST_PAIRS,
    ST_WALLS,
    blocks_for,
    state_size,
)
from collide2d.engine.models.stepped.move import BODY_COLUMNS
from collide2d.engine.models.stepped.records import Lists, State, Step
from collide2d.engine.models.stepped.settle import (
    ITERATIONS,
    SLEEP_AFTER_S,
    SLOP_PX,
    Settle,
    check_options,
    settles,
)
from collide2d.engine.models.stepped.step import STAGES, run, step
from collide2d.engine.shapes import GEOMETRIES, build_cores
from collide2d.engine.sort import median
from collide2d.engine.splitchoice import SplitChoice
from collide2d.engine.threads import chunks_for
from collide2d.engine.world import Bodies, WorldSpec

__all__ = ["STAGES", "Lists", "Model", "State", "Step"]

# The candidate list's margin, px: this many of the fastest object's step (|v|·dt), within
# [MARGIN_MIN_PX, MARGIN_MAX_SIDES x the median box side]. A wider margin remakes the list less
# often but lists more pairs; tuned on the standard scene of `collide2d bench`.
MARGIN_STEPS = 7.0
MARGIN_MIN_PX = 0.5
MARGIN_MAX_SIDES = 1.5
# The list is remade once an object has drifted within this much (px, and this share of the
# world's side) of the margin: room for the rounding of the drift and of the grown boxes.
DRIFT_SLACK_PX = 1e-6
DRIFT_SLACK_REL = 1e-12
# Candidate slots to start with per object (the buffers double when full).
CANDIDATES_PER_OBJECT = 4


class Model:
    """Fixed-step elastic model; see the module docstring. Surface as in engine.models.
    Its state is a `State` (records.py), in the broad phase's order."""

    def __init__(
        self,
        world: WorldSpec,
        bodies: Bodies,
        substeps: int = 1,
        geometry: str | None = None,
        skip: bool = True,
        broadphase: str | None = None,
        iterations: int = ITERATIONS,
        slop: float = SLOP_PX,
        rest_speed: float | None = None,
        sleep: bool = True,
        sleep_after: float = SLEEP_AFTER_S,
    ):
        if bodies.n >= 1 << (BAND_SHIFT - KEY_SHIFT):
            raise ValueError(f"at most {(1 << (BAND_SHIFT - KEY_SHIFT)) - 1} objects")
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be a whole number >= 1, got {substeps!r}")
        geometry = "box" if geometry is None else geometry
        if geometry not in GEOMETRIES:
            raise ValueError(f"unknown geometry {geometry!r}; expected one of {GEOMETRIES}")
        self.world = world
        self.substeps = int(substeps)
        self.geometry = geometry
        self.tick = 0
        # gravity, restitution or friction: the settling path (settle.py); else the elastic one
        self._settle = None
        if settles(world, bodies):
            self._settle = Settle(
                world, bodies, substeps, geometry, iterations, slop, rest_speed, sleep, sleep_after
            )
            return
        check_options(iterations, slop, rest_speed, sleep, sleep_after)
        n = bodies.n
        static = np.ascontiguousarray(bodies.static, bool).copy()
        pos = np.ascontiguousarray(bodies.pos, np.float64).copy()
        vel = np.ascontiguousarray(bodies.vel, np.float64).copy()
        vel[static] = 0.0
        size = np.ascontiguousarray(bodies.size, np.float64).copy()
        movable = ~static if skip else np.ones(n, bool)
        body = np.empty((n, BODY_COLUMNS))
        body[:, 0:2] = pos
        body[:, 2:4] = vel
        body[:, 4:6] = size
        self._S = State(
            body=body,
            inv_mass=np.array(bodies.inv_mass, np.float64),
            static=static,
            movable=movable,
            ext=np.arange(n, dtype=np.int64),
            rank=np.arange(n, dtype=np.int64),
            anchor=pos.copy(),
        )
        self._state = tuple(self._S)  # as `step.run` takes it
        cores = build_cores(bodies, geometry)
        self._cores = (cores.shape, cores.radius, cores.start, cores.verts, cores.normals)
        self._bp = _broad_phase(world, pos, vel, size, movable, substeps, skip, broadphase)
        self._split = SplitChoice(self._bp.state[ST_CHUNKS])

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events in the order they happened (empty when log is False).
        A scene that splits runs them split among threads or not, as the clock says
        (splitchoice): the same bytes either way."""
        if self._settle is not None:
            events = self._settle.advance(int(ticks), log)
            self.tick = self._settle.tick
            return events
        parts = self._split.run(int(ticks), lambda k, chunks: self._advance(k, log, chunks))
        return parts[0] if len(parts) == 1 else np.concatenate(parts)

    def _advance(self, ticks: int, log: bool, chunks: int) -> np.ndarray:
        """`advance`, its split stages cut into `chunks` (1: not split)."""
        self._bp.state[ST_CHUNKS] = chunks
        world = (float(self.world.width), float(self.world.height), float(self.world.fps))
        rows, times = new_log(log)
        rows, times, n, grown = run(
            world,
            self.substeps,
            self.tick,
            int(ticks),
            bool(log),
            self._state,
            self.geometry == "exact",
            self._cores,
            rows,
            times,
            tuple(self._bp),
        )
        self._grown(grown)
        self.tick += int(ticks)
        return event_records(rows, times, n)

    def event_counts(self) -> tuple[int, int]:
        """(wall events, pair events) so far, logged or not."""
        if self._settle is not None:
            return self._settle.event_counts()
        state = self._bp.state
        return int(state[ST_WALLS]), int(state[ST_PAIRS])

    def profile(self, ticks: int) -> dict[str, float]:
        """Run `ticks` ticks with the event log off, one stage of `step` at a time, and return
        the seconds spent in each (STAGES): "move" (motion and walls), "broad" (making the
        candidate list), "narrow" (testing the listed pairs), "response" (exchange and
        separation). The state ends exactly as `advance(ticks, log=False)` would leave it. Each
        stage is timed from Python, so each count includes a call's overhead (microseconds),
        which dominates in small scenes. A scene that splits runs split (the clock does not
        choose here). The move and the narrow phase, which `advance` runs together block by block
        while the list holds (narrow.move_narrow), run here one after the other, so that
        each has a time of its own. On the settling path (settle.py) the whole step is timed as
        "move"."""
        if self._settle is not None:
            began = time.perf_counter()
            self.advance(ticks, log=False)
            return dict.fromkeys(STAGES, 0.0) | {"move": time.perf_counter() - began}
        self._bp.state[ST_CHUNKS] = self._split.chunks
        fps = float(self.world.fps)
        width, height = float(self.world.width), float(self.world.height)
        dt = 1.0 / (fps * self.substeps)
        exact = self.geometry == "exact"
        rows, times = new_log(False)
        spent = dict.fromkeys(STAGES, 0.0)
        clock = time.perf_counter
        for tick in range(self.tick + 1, self.tick + int(ticks) + 1):
            t = tick / fps
            for _ in range(self.substeps):
                for stage, name in enumerate(STAGES):
                    began = clock()
                    at = (dt, width, height, exact, tick, t, False)
                    rows, times, _, grown = step(
                        stage, stage + 1, self._state, at, self._cores, rows, times, 0,
                        tuple(self._bp),
                    )  # fmt: skip
                    self._grown(grown)
                    spent[name] += clock() - began
        self.tick += int(ticks)
        return spent

    def _grown(self, grown: tuple) -> None:
        """Take the buffers a step handed back (keys, spare, near, when): those that grew."""
        keys, spare, near, when = grown
        self._bp = self._bp._replace(keys=keys, spare=spare, near=near, when=when)

    def positions(self) -> np.ndarray:
        """(n, 2) float64 top-left corners, px."""
        if self._settle is not None:
            return self._settle.positions()
        return self._by_id(self._S.body[:, 0:2])

    def velocities(self) -> np.ndarray:
        """(n, 2) float64 velocities, px/s."""
        if self._settle is not None:
            return self._settle.velocities()
        return self._by_id(self._S.body[:, 2:4])

    def _by_id(self, a: np.ndarray) -> np.ndarray:
        out = np.empty(a.shape)
        out[self._S.ext] = a
        return out


def _reorder_scratch(n: int) -> tuple:
    """The reorder's scratch (candidates._reorder): rows, ids, flags, inverse masses."""
    return (np.empty((n, BODY_COLUMNS)), np.empty(n, np.int64), np.empty(n, np.uint8), np.empty(n))


def _broad_phase(world, pos, vel, size, movable, substeps, skip, broadphase):
    """The candidate list's state and scratch (a `Lists`): its margin from the
    fastest step and the box sizes, the method and cell from the scene or `broadphase`
    (broadphase.choose)."""
    n = pos.shape[0]
    possible = n >= 2 and (bool(movable.any()) or not skip)
    fastest = float(np.abs(vel).max()) / (world.fps * substeps) if n else 0.0
    median_side = median(size.max(axis=1)) if n else 1.0
    margin = min(MARGIN_STEPS * fastest, MARGIN_MAX_SIDES * median_side)
    margin = max(margin, MARGIN_MIN_PX) if np.isfinite(margin) else MARGIN_MIN_PX
    method, cell = choose(world.width, world.height, size + 2.0 * margin, broadphase)
    slack = DRIFT_SLACK_PX + DRIFT_SLACK_REL * max(world.width, world.height)
    state = np.zeros(state_size(blocks_for(n)), np.int64)  # ST_*
    state[: ST_CHUNKS + 1] = [-1, method, int(possible), 0, 0, 0, chunks_for(n)]
    order = np.arange(n, dtype=np.int64)
    if method == METHOD_SWEEP:
        order = np.argsort(pos[:, 0], kind="stable").astype(np.int64)
    return Lists(
        keys=np.empty(max(16, CANDIDATES_PER_OBJECT * n), np.int64),
        near=np.empty(max(16, n), np.int64),
        order=order,
        lo=np.empty_like(pos),
        hi=np.empty_like(pos),
        folds=np.empty((2 * n, 4), np.int64),
        state=state,
        params=np.array([margin, cell, slack] + [0.0] * (PARAMS_SIZE - 3)),  # P_*
        ws=workspace(n),
        when=np.empty(max(16, n)),
        finder=marker(method),
        scratch=_reorder_scratch(n),
        spare=np.empty(max(16, CANDIDATES_PER_OBJECT * n), np.int64),
    )
