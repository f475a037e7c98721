"""The `stepped` model (SPEC 3.2): fixed-step elastic collisions with float state.

Input: the world, the `Bodies` (copied: the model owns its state) and the options `substeps`
(each tick split into that many equal steps of 1/(fps·substeps) s) and `geometry` ("box", the
default, also for None: every object collides as its box; "exact": by its real shape, shapes.py).
Output, per `advance`: the events of the ticks run, walls and responding pairs, `t` = the tick's
end.

Each step runs move -> walls -> pairs. Walls reflect exactly as a wall would (response.fold).
Pairs: the candidates are the pairs whose boxes overlap after the walls (broadphase.sweep_pairs),
taken in ascending (a, b) order, each tested again on the current state so that it sees what the
pairs before it changed (a pair that only comes to overlap through such a push waits for the next
step). A pair that overlaps and approaches along the contact normal gets the elastic exchange and
is pushed apart along the normal, shared by inverse mass, never out of the world.

The event log helpers (`log_event`, `event_records`) serve the exact model too.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from engine.broadphase import sweep_pairs
from engine.contact import box_overlap_axis, penetration
from engine.events import (
    EV_PAIR,
    EV_WALL,
    EVENT_DTYPE,
    SIDE_BOTTOM,
    SIDE_LEFT,
    SIDE_RIGHT,
    SIDE_TOP,
)
from engine.response import exchange, fold, separate
from engine.shapes import GEOMETRIES, build_cores
from engine.world import Bodies, WorldSpec

# Rows of a fresh event buffer; it doubles when full.
LOG_ROWS = 1024


# --- event log buffers (shared with the exact model) -------------------------------------------


@njit(cache=True)
def log_event(rows, times, n, tick, t, kind, a, b, code):
    """Write event n into the buffers, doubling them when full; returns the (rows, times) to use.

    rows (k, 5) int64: tick, type, a, b, code; times (k,) float64: t in seconds.
    """
    if n >= rows.shape[0]:
        grown = np.empty((max(2 * rows.shape[0], 16), 5), np.int64)
        grown[:n] = rows[:n]
        grown_t = np.empty(grown.shape[0])
        grown_t[:n] = times[:n]
        rows, times = grown, grown_t
    rows[n, 0] = tick
    rows[n, 1] = kind
    rows[n, 2] = a
    rows[n, 3] = b
    rows[n, 4] = code
    times[n] = t
    return rows, times


def new_log(log: bool) -> tuple[np.ndarray, np.ndarray]:
    """Empty event buffers (rows, times) for one `advance`."""
    k = LOG_ROWS if log else 1
    return np.empty((k, 5), np.int64), np.empty(k)


def event_records(rows: np.ndarray, times: np.ndarray, n: int) -> np.ndarray:
    """The first n buffered events as an EVENT_DTYPE array (xdiff/ydiff -1: not the paper model)."""
    out = np.zeros(n, dtype=EVENT_DTYPE)
    out["tick"] = rows[:n, 0]
    out["t"] = times[:n]
    out["type"] = rows[:n, 1]
    out["a"] = rows[:n, 2]
    out["b"] = rows[:n, 3]
    out["code"] = rows[:n, 4]
    out["xdiff"] = -1
    out["ydiff"] = -1
    return out


# --- the stages of one step ---------------------------------------------------------------------


@njit(cache=True)
def _move(pos, vel, static, dt):
    """Straight-line motion for dt seconds."""
    for i in range(pos.shape[0]):
        if not static[i]:
            pos[i, 0] += vel[i, 0] * dt
            pos[i, 1] += vel[i, 1] * dt


@njit(cache=True)
def _log_folds(rows, times, n_ev, tick, t, i, low, high, first_low, side_low, side_high):
    """Log one wall event per fold, alternating from the wall hit first."""
    at_low = first_low
    for _ in range(low + high):
        rows, times = log_event(
            rows, times, n_ev, tick, t, EV_WALL, i, -1, side_low if at_low else side_high
        )
        n_ev += 1
        at_low = not at_low
    return rows, times, n_ev


@njit(cache=True)
def _walls(pos, vel, size, static, width, height, tick, t, log, rows, times, n_ev):
    """Reflect every object back into the world, in id order; log each fold."""
    for i in range(pos.shape[0]):
        if static[i]:
            continue
        x, vx, low, high, first_low = fold(pos[i, 0], vel[i, 0], width - size[i, 0])
        pos[i, 0] = x
        vel[i, 0] = vx
        if log:
            rows, times, n_ev = _log_folds(
                rows, times, n_ev, tick, t, i, low, high, first_low, SIDE_LEFT, SIDE_RIGHT
            )
        y, vy, low, high, first_low = fold(pos[i, 1], vel[i, 1], height - size[i, 1])
        pos[i, 1] = y
        vel[i, 1] = vy
        if log:
            rows, times, n_ev = _log_folds(
                rows, times, n_ev, tick, t, i, low, high, first_low, SIDE_TOP, SIDE_BOTTOM
            )
    return rows, times, n_ev


@njit(cache=True)
def _contact(a, b, pos, size, exact, shape, radius, start, verts, normals):
    """(depth, depth_y, code, nx, ny) of a pair now; depth <= 0 when they do not overlap."""
    qx = pos[b, 0] - pos[a, 0]
    qy = pos[b, 1] - pos[a, 1]
    if not exact:
        return box_overlap_axis(qx, qy, size[a, 0], size[a, 1], size[b, 0], size[b, 1])
    depth, code, nx, ny = penetration(
        qx,
        qy,
        shape[a],
        size[a, 0],
        size[a, 1],
        radius[a],
        verts[start[a] : start[a + 1]],
        normals[start[a] : start[a + 1]],
        shape[b],
        size[b, 0],
        size[b, 1],
        radius[b],
        verts[start[b] : start[b + 1]],
        normals[start[b] : start[b + 1]],
    )
    return depth, depth, code, nx, ny


@njit(cache=True)
def _pairs(
    pos, vel, size, inv_mass, static, width, height, exact, cores, tick, t, log, rows, times, n_ev
):
    """Respond to every overlapping, approaching pair in ascending (a, b) order; log each."""
    shape, radius, start, verts, normals = cores
    candidates = sweep_pairs(pos, pos + size, static)
    for m in range(candidates.shape[0]):
        a = candidates[m, 0]
        b = candidates[m, 1]
        depth, depth_y, code, nx, ny = _contact(
            a, b, pos, size, exact, shape, radius, start, verts, normals
        )
        if depth <= 0.0:
            continue
        vax, vay, vbx, vby, changed = exchange(
            vel[a, 0], vel[a, 1], vel[b, 0], vel[b, 1], inv_mass[a], inv_mass[b], code, nx, ny
        )
        if not changed:
            continue
        vel[a, 0], vel[a, 1], vel[b, 0], vel[b, 1] = vax, vay, vbx, vby
        separate(
            pos, size, a, b, inv_mass[a], inv_mass[b], code, nx, ny, depth, depth_y, width, height
        )
        if log:
            rows, times = log_event(rows, times, n_ev, tick, t, EV_PAIR, a, b, code)
            n_ev += 1
    return rows, times, n_ev


@njit(cache=True)
def _run(
    world, substeps, tick0, ticks, log, pos, vel, size, inv_mass, static, exact, cores, rows, times
):
    """Run ticks tick0+1 ... tick0+ticks; returns the event buffers and the number written."""
    width, height, fps = world
    dt = 1.0 / (fps * substeps)
    n_ev = 0
    for tick in range(tick0 + 1, tick0 + ticks + 1):
        t = tick / fps
        for _ in range(substeps):
            _move(pos, vel, static, dt)
            rows, times, n_ev = _walls(
                pos, vel, size, static, width, height, tick, t, log, rows, times, n_ev
            )
            rows, times, n_ev = _pairs(
                pos,
                vel,
                size,
                inv_mass,
                static,
                width,
                height,
                exact,
                cores,
                tick,
                t,
                log,
                rows,
                times,
                n_ev,
            )
    return rows, times, n_ev


class Model:
    """Fixed-step elastic model; see the module docstring. Surface as in engine.models."""

    def __init__(
        self, world: WorldSpec, bodies: Bodies, substeps: int = 1, geometry: str | None = None
    ):
        if int(substeps) != substeps or substeps < 1:
            raise ValueError(f"substeps must be a whole number >= 1, got {substeps!r}")
        geometry = "box" if geometry is None else geometry
        if geometry not in GEOMETRIES:
            raise ValueError(f"unknown geometry {geometry!r}; expected one of {GEOMETRIES}")
        self.world = world
        self.substeps = int(substeps)
        self.geometry = geometry
        self.tick = 0
        self._static = np.ascontiguousarray(bodies.static, bool).copy()
        self._pos = np.ascontiguousarray(bodies.pos, np.float64).copy()
        self._vel = np.ascontiguousarray(bodies.vel, np.float64).copy()
        self._vel[self._static] = 0.0
        self._size = np.ascontiguousarray(bodies.size, np.float64).copy()
        self._inv_mass = np.ascontiguousarray(bodies.inv_mass, np.float64)
        cores = build_cores(bodies, geometry)
        self._cores = (cores.shape, cores.radius, cores.start, cores.verts, cores.normals)

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events in the order they happened (empty when log is False)."""
        world = (float(self.world.width), float(self.world.height), float(self.world.fps))
        rows, times = new_log(log)
        rows, times, n = _run(
            world,
            self.substeps,
            self.tick,
            int(ticks),
            bool(log),
            self._pos,
            self._vel,
            self._size,
            self._inv_mass,
            self._static,
            self.geometry == "exact",
            self._cores,
            rows,
            times,
        )
        self.tick += int(ticks)
        return event_records(rows, times, n)

    def positions(self) -> np.ndarray:
        """(n, 2) float64 top-left corners, px."""
        return self._pos.copy()

    def velocities(self) -> np.ndarray:
        """(n, 2) float64 velocities, px/s."""
        return self._vel.copy()
