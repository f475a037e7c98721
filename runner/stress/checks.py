"""The stress checks: the bounds each model must keep, and the per-tick checks of one case.

`tick_figures` (numba) reads one state in one pass: finite or not, how far a box sticks out of the
world or a mover out of its room, kinetic energy and momentum (`engine.invariants.energy_momentum`),
the largest change of a velocity component's size, the largest move of a static object.
`exact_round` is the pixel rounding done in exact arithmetic. `Checker` holds one case's start
state and bounds, checks each tick's state (also the deepest overlap, through
`engine.invariants.max_penetration`, and the rounding to pixels) and keeps the largest figures and
the first problem.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.events import EV_WALL
from collide2d.engine.invariants import energy_momentum, max_penetration
from collide2d.engine.jit import njit
from collide2d.engine.picture.raster import round_positions
from collide2d.runner.stress.scenes import Scene

# Bounds of the invariants (dimensionless unless a unit is given).
EXACT_ENERGY_TOL = 1e-9  # relative kinetic energy drift under `exact`
EXACT_MOMENTUM_TOL = 1e-9  # momentum drift over wall-free ticks, relative to sqrt(2 E0 M)
STEPPED_ENERGY_TOL = 1e-6  # the stepped model's bounded drift, relative
STEPPED_MOMENTUM_TOL = 1e-6
PENETRATION_TOL_PX = 1e-9  # px, overlap allowed between two boxes after an `exact` tick
INSIDE_TOL_PX = 1e-9  # px, how far a box may stick out of the world (or its room) by rounding

# Columns of the figures tick_figures writes.
_FINITE, _OUTSIDE, _ENERGY, _PX, _PY, _SPEED_CHANGE, _STATIC_MOVED, _ESCAPED = range(8)
_N_FIGURES = 8


@njit(cache=True)
def tick_figures(pos, vel, size, mass, static, pos0, speed0, width, height, room, out):
    """Figures of one state, written into out (8,) float64.

    pos, vel, size (n, 2) float64 (px, px/s, px); mass (n,) (inf for statics); static (n,) bool;
    pos0 (n, 2) the start positions; speed0 (n, 2) the start |velocity| per component; width,
    height the world (px); room (4,) x0, y0, x1, y1 (px) that movers must stay in (x1 < x0: none).
    out: 1 when every value is finite (else 0); the largest distance any box sticks out of the world
    (px, 0 inside); kinetic energy; momentum x, y (movers only); the largest change of a velocity
    component's size (px/s); the largest move of a static object (px); the largest distance a mover
    sticks out of the room (px).
    """
    finite = 1.0
    outside = 0.0
    speed_change = 0.0
    static_moved = 0.0
    escaped = 0.0
    has_room = room[2] >= room[0]
    for i in range(pos.shape[0]):
        x = pos[i, 0]
        y = pos[i, 1]
        vx = vel[i, 0]
        vy = vel[i, 1]
        if not (np.isfinite(x) and np.isfinite(y) and np.isfinite(vx) and np.isfinite(vy)):
            finite = 0.0
            continue
        right = x + size[i, 0]
        bottom = y + size[i, 1]
        outside = max(outside, -x, -y, right - width, bottom - height)
        speed_change = max(speed_change, abs(abs(vx) - speed0[i, 0]), abs(abs(vy) - speed0[i, 1]))
        if static[i]:
            static_moved = max(static_moved, abs(x - pos0[i, 0]), abs(y - pos0[i, 1]))
            continue
        if has_room:
            escaped = max(escaped, room[0] - x, room[1] - y, right - room[2], bottom - room[3])
    energy, px, py = energy_momentum(mass, static, vel)
    out[_FINITE] = finite
    out[_OUTSIDE] = outside
    out[_ENERGY] = energy
    out[_PX] = px
    out[_PY] = py
    out[_SPEED_CHANGE] = speed_change
    out[_STATIC_MOVED] = static_moved
    out[_ESCAPED] = escaped


def exact_round(pos: np.ndarray) -> np.ndarray:
    """(n, 2) int64 floor(x + 1/2) of float positions (n, 2), computed without rounding error.

    x - floor(x) is exact for |x| < 2**52, so comparing it with 1/2 decides the rounding exactly
    (x + 0.5 in floating point rounds 0.49999999999999994 up to 1).
    """
    whole = np.floor(pos)
    return (whole + (pos - whole >= 0.5)).astype(np.int64)


class Checker:
    """The per-tick invariants of one case; collects the figures and the first problem."""

    def __init__(self, scene: Scene, model: str, pos0: np.ndarray, vel0: np.ndarray):
        b = scene.bodies
        self.scene = scene
        self.model = model
        self.size = np.ascontiguousarray(b.size, np.float64)
        self.mass = np.ascontiguousarray(b.mass, np.float64)
        self.static = np.ascontiguousarray(b.static, bool)
        self.pos0 = np.ascontiguousarray(pos0, np.float64).copy()
        self.speed0 = np.abs(np.ascontiguousarray(vel0, np.float64))
        self.room = np.array(scene.room if scene.room else (0.0, 0.0, -1.0, -1.0), np.float64)
        self.width = float(scene.world.width)
        self.height = float(scene.world.height)
        self.out = np.zeros(_N_FIGURES)
        self.problems: list[str] = []
        self._figures(pos0, vel0)
        self.energy0 = float(self.out[_ENERGY])
        movers = ~self.static
        self.momentum_scale = math.sqrt(2.0 * self.energy0 * float(np.sum(self.mass[movers])))
        self.momentum = self.out[[_PX, _PY]].copy()
        self.unexplained = np.zeros(2)  # momentum change summed over wall-free ticks
        world = scene.world
        # gravity, restitution or friction: the total energy must never rise above where it
        # began (kinetic plus potential, relative to the origin); momentum is not kept
        self.settling = bool(
            world.has_gravity
            or world.restitution < 1.0
            or world.friction > 0.0
            or np.any(b.restitution < 1.0)
            or np.any(b.friction > 0.0)
        )
        self.gravity = np.array(world.gravity, np.float64)
        self.total0 = self._total(pos0)
        self.total_scale = abs(self.total0) + float(np.sum(self.mass[~self.static])) * (
            float(np.hypot(*self.gravity)) * max(self.width, self.height)
        )
        self.check_momentum = model != "paper" and not self.static.any() and not self.settling
        self.energy_drift = 0.0
        self.momentum_drift = 0.0 if self.check_momentum else None
        self.penetration = 0.0
        self.energy_tol = EXACT_ENERGY_TOL if model == "exact" else STEPPED_ENERGY_TOL
        self.momentum_tol = EXACT_MOMENTUM_TOL if model == "exact" else STEPPED_MOMENTUM_TOL
        self.tick(0, pos0, vel0, None)

    def _total(self, pos) -> float:
        """Kinetic energy (the last figures) plus potential, -m·(g·p), of the movers."""
        movers = ~self.static
        potential = -float(np.sum(self.mass[movers] * (np.asarray(pos)[movers] @ self.gravity)))
        return float(self.out[_ENERGY]) + potential

    def _figures(self, pos, vel) -> None:
        tick_figures(
            np.ascontiguousarray(pos, np.float64),
            np.ascontiguousarray(vel, np.float64),
            self.size,
            self.mass,
            self.static,
            self.pos0,
            self.speed0,
            self.width,
            self.height,
            self.room,
            self.out,
        )

    def fail(self, tick: int, message: str) -> None:
        self.problems.append(f"tick {tick}: {message}")

    def tick(self, k: int, pos: np.ndarray, vel: np.ndarray, events) -> bool:
        """Check the state after tick k (0: the start); False once an invariant broke."""
        self._pos = pos
        self._figures(pos, vel)
        out = self.out
        if out[_FINITE] != 1.0:
            self.fail(k, "a position or velocity is not finite")
            return False
        if out[_OUTSIDE] > INSIDE_TOL_PX:
            self.fail(k, f"a box sticks out of the world by {out[_OUTSIDE]:.6g} px")
        if out[_STATIC_MOVED] > 0.0:
            self.fail(k, f"a static object moved by {out[_STATIC_MOVED]:.6g} px")
        self._conservation(k, events)
        depth, a, b = max_penetration(np.ascontiguousarray(pos, np.float64), self.size)
        self.penetration = max(self.penetration, depth)
        if self.model == "exact":
            if depth > PENETRATION_TOL_PX:
                self.fail(k, f"objects {a} and {b} overlap by {depth:.6g} px after the tick")
            if out[_ESCAPED] > INSIDE_TOL_PX:
                self.fail(k, f"a mover left its room by {out[_ESCAPED]:.6g} px (tunnelled)")
        wrong = np.nonzero(np.any(exact_round(pos) != round_positions(pos), axis=1))[0]
        if wrong.shape[0]:
            i = int(wrong[0])
            self.fail(
                k, f"object {i} at {pos[i].tolist()!r} rounds to the wrong pixel (floor(x + 1/2))"
            )
        return not self.problems

    def _conservation(self, k: int, events) -> None:
        out = self.out
        if self.model == "paper":
            if out[_SPEED_CHANGE] != 0.0:
                self.fail(k, f"a velocity component changed size by {out[_SPEED_CHANGE]:.6g} px/s")
            if self.energy0 > 0:
                self.energy_drift = max(
                    self.energy_drift, abs(out[_ENERGY] - self.energy0) / self.energy0
                )
            return
        if self.settling:
            rise = (self._total(self._pos) - self.total0) / max(self.total_scale, 1e-300)
            self.energy_drift = max(self.energy_drift, rise)
            if rise > self.energy_tol:
                self.fail(k, f"total energy rose by {rise:.3g} (bound {self.energy_tol:g})")
            return
        if self.energy0 > 0:
            drift = abs(out[_ENERGY] - self.energy0) / self.energy0
            self.energy_drift = max(self.energy_drift, drift)
            if drift > self.energy_tol:
                self.fail(k, f"kinetic energy drifted by {drift:.3g} (bound {self.energy_tol:g})")
        if not self.check_momentum or events is None:
            return
        now = out[[_PX, _PY]].copy()
        if not np.any(events["type"] == EV_WALL):
            self.unexplained += now - self.momentum
        self.momentum = now
        if self.momentum_scale > 0:
            drift = float(np.hypot(*self.unexplained)) / self.momentum_scale
            self.momentum_drift = max(self.momentum_drift, drift)
            if drift > self.momentum_tol:
                self.fail(
                    k,
                    f"momentum drifted by {drift:.3g} over wall-free ticks "
                    f"(bound {self.momentum_tol:g})",
                )
