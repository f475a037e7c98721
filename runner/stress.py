"""The `stress` command: hostile scenes run under every model, invariants checked every tick.

Input: the scene list built here in code (`scenes(quick)`), each a `Scene` of engine arrays (a
`WorldSpec`, `Bodies`, a tick count, the models it applies to). Output: one `CaseResult` per scene
and model with its figures (ticks run, events, largest energy and momentum drift, largest
penetration, run time) and a verdict, written as `OUT/stress/report.md` and `report.json` (each
through a temporary name and a rename, runner.outputs) and summed up on stdout; the exit status is 1
when an invariant broke, else 0.

Each case runs its model one tick at a time and after every tick checks, with one small numba
kernel (`tick_figures`) and a sort-and-sweep kernel (`max_penetration`):
- the state is finite and every object lies inside the world (within `INSIDE_TOL_PX`), static
  objects have not moved;
- energy and momentum within the model's bound: `exact` keeps kinetic energy to `EXACT_ENERGY_TOL`
  (relative) and, in scenes without static objects, momentum through every tick without a wall event
  to `EXACT_MOMENTUM_TOL`; `stepped` to the looser `STEPPED_*` bounds; `paper` keeps every velocity
  component's size exactly (only its sign changes);
- under `exact`, no two boxes overlap by more than `PENETRATION_TOL_PX` after a tick, and the
  movers of a scene with a `room` (a ring of static walls) stay in it (nothing tunnels);
- positions round to pixels exactly as `floor(x + 1/2)` (engine.raster.round_positions, checked
  against exact arithmetic);
- no hang: a runaway stops with a clear error (the exact model's event cap, the stepped model's fold
  limit); a scene that expects one counts it as a pass, any other scene as a failure;
- the same bytes twice: the case runs again in one call per `CHUNK_TICKS` and must end with the same
  positions, velocities and event records, byte for byte.

A model that is not built yet (`engine.models.ModelUnavailable`) is reported as unavailable, not as
a failure. `--quick` runs the same scenes shorter and smaller; it fits in well under a minute.
"""

from __future__ import annotations

import argparse
import hashlib
import math
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from numba import njit

from collide2d.engine.events import EV_WALL
from collide2d.engine.models import MODEL_NAMES, ModelUnavailable
from collide2d.engine.models import make as make_model
from collide2d.engine.raster import round_positions
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner import outputs

EXIT_OK = 0
EXIT_BROKEN = 1
EXIT_BAD_INPUT = 2

# Bounds of the invariants (dimensionless unless a unit is given).
EXACT_ENERGY_TOL = 1e-9  # relative kinetic energy drift under `exact`
EXACT_MOMENTUM_TOL = 1e-9  # momentum drift over wall-free ticks, relative to sqrt(2 E0 M)
STEPPED_ENERGY_TOL = 1e-6  # the stepped model's bounded drift, relative
STEPPED_MOMENTUM_TOL = 1e-6
PENETRATION_TOL_PX = 1e-9  # px, overlap allowed between two boxes after an `exact` tick
INSIDE_TOL_PX = 1e-9  # px, how far a box may stick out of the world (or its room) by rounding
# Ticks per model call in the second, unchecked run (which must give the same bytes).
CHUNK_TICKS = 65_536
REPORT_DIR = "stress"
VERDICT_PASS = "pass"
VERDICT_FAIL = "fail"
VERDICT_STOPPED = "stopped"  # a runaway the scene expects, stopped by a clear error
VERDICT_UNAVAILABLE = "unavailable"

# Columns of the figures tick_figures writes.
_FINITE, _OUTSIDE, _ENERGY, _PX, _PY, _SPEED_CHANGE, _STATIC_MOVED, _ESCAPED = range(8)
_N_FIGURES = 8


# ----------------------------------------------------------------------------- kernels


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
    energy = 0.0
    px = 0.0
    py = 0.0
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
        m = mass[i]
        energy += 0.5 * m * (vx * vx + vy * vy)
        px += m * vx
        py += m * vy
        if has_room:
            escaped = max(escaped, room[0] - x, room[1] - y, right - room[2], bottom - room[3])
    out[_FINITE] = finite
    out[_OUTSIDE] = outside
    out[_ENERGY] = energy
    out[_PX] = px
    out[_PY] = py
    out[_SPEED_CHANGE] = speed_change
    out[_STATIC_MOVED] = static_moved
    out[_ESCAPED] = escaped


@njit(cache=True)
def max_penetration(pos, size):
    """(depth px, a, b): the deepest overlap of two boxes, min(overlap width, overlap height).

    pos, size (n, 2) float64, px. Sort-and-sweep on x: cost n log n plus the pairs whose x
    intervals meet. Touching boxes have depth 0. (0.0, -1, -1) when no two boxes overlap.
    """
    n = pos.shape[0]
    order = np.argsort(pos[:, 0], kind="mergesort")
    worst = 0.0
    wa = -1
    wb = -1
    for k in range(n):
        i = order[k]
        xi = pos[i, 0]
        yi = pos[i, 1]
        ri = xi + size[i, 0]
        bi = yi + size[i, 1]
        for m in range(k + 1, n):
            j = order[m]
            xj = pos[j, 0]
            if xj >= ri:
                break
            ox = min(ri, xj + size[j, 0]) - max(xi, xj)
            oy = min(bi, pos[j, 1] + size[j, 1]) - max(yi, pos[j, 1])
            d = min(ox, oy)
            if d > worst:
                worst = d
                wa = min(i, j)
                wb = max(i, j)
    return worst, wa, wb


def exact_round(pos: np.ndarray) -> np.ndarray:
    """(n, 2) int64 floor(x + 1/2) of float positions (n, 2), computed without rounding error.

    x - floor(x) is exact for |x| < 2**52, so comparing it with 1/2 decides the rounding exactly
    (x + 0.5 in floating point rounds 0.49999999999999994 up to 1).
    """
    whole = np.floor(pos)
    return (whole + (pos - whole >= 0.5)).astype(np.int64)


# ----------------------------------------------------------------------------- scenes


@dataclass(frozen=True)
class Scene:
    """One hostile scene: the world, the objects and how long to run, and what to expect.

    models: the models it applies to (the paper model needs whole-pixel positions).
    expect_stop: models that must stop it with a clear error (a runaway), not run it through.
    room: (x0, y0, x1, y1) px that movers must stay inside (checked under `exact`), or None.
    """

    name: str
    about: str
    world: WorldSpec
    bodies: Bodies
    ticks: int
    models: tuple[str, ...] = MODEL_NAMES
    expect_stop: tuple[str, ...] = ()
    room: tuple[float, float, float, float] | None = None


def _grid(nx: int, ny: int, x0: float, y0: float, step_x: float, step_y: float) -> np.ndarray:
    """(nx * ny, 2) corners of an nx x ny grid, row by row, px."""
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    return np.stack([x0 + step_x * gx.ravel(), y0 + step_y * gy.ravel()], axis=1).astype(float)


def _long_run(quick: bool) -> Scene:
    pos = _grid(6, 4, 20, 20, 50, 50)
    n = pos.shape[0]
    k = np.arange(n)
    vel = np.stack([(10 + 10 * (k % 3)) * (-1.0) ** k, (10 + 10 * (k % 2)) * (-1.0) ** (k // 2)], 1)
    return Scene(
        "long_run",
        "24 boxes bouncing in a 320x240 world for 10^6 ticks",
        WorldSpec(320, 240, 10),
        Bodies.boxes(pos, 10, vel, mass=1.0 + k % 4),
        20_000 if quick else 1_000_000,
    )


def _cross_in_one_tick(quick: bool) -> Scene:
    pos = [[5, 10], [100, 50], [50, 100], [150, 80], [170, 10]]
    size = [[10, 10], [10, 10], [1, 1], [20, 20], [5, 5]]
    vel = [[5000, 0], [0, -3000], [2170, 1330], [-70, 40], [-4990, 2510]]
    return Scene(
        "cross_in_one_tick",
        "objects crossing the whole 200x120 world several times in one tick",
        WorldSpec(200, 120, 10),
        Bodies(**_box_fields(pos, size, vel, mass=[1, 2, 0.5, 10, 1])),
        2_000 if quick else 20_000,
    )


def _mass_ratios(quick: bool) -> Scene:
    # Lane k (a 1-D strip, no vertical motion) holds a box of mass 10^k near the middle, nearly at
    # rest, and a box of mass 10^-k on each side bouncing between it and a wall: mass ratios up to
    # 1e24. (A heavy box that drives a light one into a wall would need about pi * sqrt(M / m)
    # collisions, 10^12 here, and stop the exact model at its event cap: the physics, not a bug.)
    k = np.repeat(np.arange(13), 3)
    slot = np.tile(np.arange(3), 13)
    pos = np.stack([np.choose(slot, [40.0, 195.0, 330.0]), 5.0 + 15.0 * k], 1)
    vel = np.stack([np.choose(slot, [100.0, 0.0, -150.0]), np.zeros(k.shape[0])], 1)
    vel[(slot == 1) & (k == 12)] = [0.25, 0.0]
    mass = 10.0 ** np.where(slot == 1, k, -k)
    return Scene(
        "mass_ratios",
        "masses 1e-12 ... 1e12 side by side: light boxes bouncing off heavy ones (ratios to 1e24)",
        WorldSpec(400, 200, 100),
        Bodies.boxes(pos, 10, vel, mass=mass),
        3_000 if quick else 20_000,
    )


def _tiny_beside_huge(quick: bool) -> Scene:
    tiny = np.concatenate(
        [_grid(8, 8, 20, 20, 50, 50), _grid(8, 8, 2620, 2620, 45, 45), [[499, 600], [700, 2500]]]
    )
    n = tiny.shape[0]
    k = np.arange(n)
    pos = np.concatenate([[[500.0, 500.0]], tiny])
    size = np.concatenate([[[2000.0, 2000.0]], np.ones((n, 2))])
    vel = np.concatenate(
        [[[1.0, -1.0]], np.stack([37.0 * (-1.0) ** k, 23.0 * (-1.0) ** (k // 2)], 1)]
    )
    vel[-2] = [200.0, 0.0]  # touching the huge box's left side, moving into it
    vel[-1] = [0.0, -300.0]  # just under it, moving up into it
    mass = np.concatenate([[1e6], np.full(n, 1e-3)])
    return Scene(
        "tiny_beside_huge",
        "1x1 boxes beside a 2000x2000 box, some touching it",
        WorldSpec(3000, 3000, 10),
        Bodies(**_box_fields(pos, size, vel, mass=mass)),
        2_000 if quick else 20_000,
    )


def _dense_packing(quick: bool) -> Scene:
    side = 10 if quick else 15
    block = _grid(side, side, 25, 25, 10, 10)
    cradle = _grid(5, 1, 50, 5, 10, 10)
    pos = np.concatenate([block, cradle])
    rng = np.random.default_rng(0)
    vel = rng.choice([-10.0, 0.0, 10.0], size=(pos.shape[0], 2))
    vel[-5:] = 0.0
    vel[-5] = [20.0, 0.0]  # Newton's cradle: the first of five touching boxes hits the row
    return Scene(
        "dense_packing",
        f"{side}x{side} touching boxes with random velocities and a Newton's cradle",
        WorldSpec(200, 200, 10),
        Bodies.boxes(pos, 10, vel),
        1_000 if quick else 5_000,
    )


def _far_from_origin(quick: bool) -> Scene:
    n = 10
    k = np.arange(n)
    pos = np.concatenate([np.stack([999_000.0 + 90 * k, 20.0 + 15 * k], 1), [[3.0, 50.0]]])
    vel = np.concatenate(
        [np.stack([123.456 * (-1.0) ** k, 7.25 * (-1.0) ** (k // 2)], 1), [[1e7, 3.5]]]
    )
    return Scene(
        "far_from_origin",
        "a 1e6 px wide world: boxes near x = 1e6 and one crossing it every tick",
        WorldSpec(1_000_000, 200, 10),
        Bodies.boxes(pos, 10, vel),
        2_000 if quick else 20_000,
    )


def _half_pixel(quick: bool) -> Scene:
    def below(x):
        return float(np.nextafter(x, -np.inf))

    def above(x):
        return float(np.nextafter(x, np.inf))

    pos = [
        [10.5, 10.5],
        [below(30.5), above(10.5)],
        [50.5, 40.0],
        [70.0, 60.5],
        [below(10.5), above(80.5)],
        [below(1.5), below(50.5)],
        [below(0.5), 90.0],
    ]
    vel = [[4.0, 4.0], [-4.0, 12.0], [2.0, 0.0], [0.0, -6.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    static = [False, False, False, False, False, True, False]
    return Scene(
        "half_pixel",
        "positions at and next to .5 px, moving by half pixels (rounding to pixels)",
        WorldSpec(100, 100, 8),
        Bodies.boxes(pos, 5, vel, static=static),
        2_000 if quick else 20_000,
        models=("stepped", "exact"),
    )


def _static_walls(quick: bool) -> Scene:
    ring = np.concatenate(
        [
            _grid(20, 1, 20, 20, 10, 10),  # top
            _grid(20, 1, 20, 210, 10, 10),  # bottom
            _grid(1, 18, 20, 30, 10, 10),  # left
            _grid(1, 18, 210, 30, 10, 10),  # right
        ]
    )
    movers = _grid(4, 4, 50, 50, 40, 40)
    k = np.arange(movers.shape[0])
    vel = np.stack(
        [(200.0 - 40 * (k % 4)) * (-1.0) ** k, (60.0 + 20 * (k % 5)) * (-1.0) ** (k // 4)], 1
    )
    pos = np.concatenate([ring, movers])
    size = np.concatenate([np.full((ring.shape[0], 2), 10.0), np.full((movers.shape[0], 2), 6.0)])
    static = np.concatenate([np.ones(ring.shape[0], bool), np.zeros(movers.shape[0], bool)])
    allvel = np.concatenate([np.zeros((ring.shape[0], 2)), vel])
    return Scene(
        "static_walls",
        "a room walled by 76 static boxes, 16 fast movers inside",
        WorldSpec(240, 240, 20),
        Bodies(**_box_fields(pos, size, allvel, static=static)),
        3_000 if quick else 20_000,
        room=(30.0, 30.0, 210.0, 210.0),
    )


def _runaway(quick: bool) -> Scene:
    return Scene(
        "runaway",
        "one box at 1e9 px/s in a 40x40 world: a clear stop, never a hang",
        WorldSpec(40, 40, 1),
        Bodies.boxes([[15.0, 15.0]], 10, [[1e9, 0.0]]),
        3,
        expect_stop=("stepped", "exact"),
    )


def _box_fields(pos, size, vel, *, mass=None, static=None) -> dict:
    """Bodies fields of boxes with per-object sizes (Bodies.boxes broadcasts one size)."""
    b = Bodies.boxes(pos, 1.0, vel, mass=mass, static=static)
    fields = {f: getattr(b, f) for f in b.__dataclass_fields__}
    fields["size"] = np.asarray(size, np.float64).reshape(-1, 2).copy()
    return fields


SCENES = (
    _long_run,
    _cross_in_one_tick,
    _mass_ratios,
    _tiny_beside_huge,
    _dense_packing,
    _far_from_origin,
    _half_pixel,
    _static_walls,
    _runaway,
)


def scenes(quick: bool = False) -> list[Scene]:
    """Every stress scene, quick (shorter, smaller) or full."""
    return [build(quick) for build in SCENES]


# ----------------------------------------------------------------------------- one case


@dataclass
class CaseResult:
    """What one scene under one model did. Drifts are relative; None where not measured."""

    scene: str
    model: str
    verdict: str
    ticks: int  # asked for
    ticks_run: int = 0
    events: int = 0
    energy_drift: float | None = None
    momentum_drift: float | None = None
    penetration_px: float | None = None
    run_time_s: float = 0.0  # the checked run, tick by tick (not the second run)
    problems: list[str] = field(default_factory=list)
    note: str = ""


class _Checker:
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
        self.check_momentum = model != "paper" and not self.static.any()
        self.energy_drift = 0.0
        self.momentum_drift = 0.0 if self.check_momentum else None
        self.penetration = 0.0
        self.energy_tol = EXACT_ENERGY_TOL if model == "exact" else STEPPED_ENERGY_TOL
        self.momentum_tol = EXACT_MOMENTUM_TOL if model == "exact" else STEPPED_MOMENTUM_TOL
        self.tick(0, pos0, vel0, None)

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


def _stop_message(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}"


def _build(scene: Scene, model: str):
    return make_model(model, scene.world, scene.bodies, substeps=1, geometry="box")


def run_case(scene: Scene, model: str) -> CaseResult:
    """Run `scene` under `model` tick by tick with every check, then again for the same bytes."""
    result = CaseResult(scene.name, model, VERDICT_PASS, scene.ticks)
    began = time.perf_counter()
    try:
        sim = _build(scene, model)
    except ModelUnavailable as exc:
        result.verdict = VERDICT_UNAVAILABLE
        result.note = str(exc)
        return result
    except Exception as exc:  # a model refusing the scene is a finding, never a crash
        result.verdict = VERDICT_FAIL
        result.problems.append(f"the model refused the scene: {_stop_message(exc)}")
        return result
    pos, vel = sim.positions(), sim.velocities()
    checker = _Checker(scene, model, pos, vel)
    digest = hashlib.sha256()
    stopped = None
    try:
        while sim.tick < scene.ticks and not checker.problems:
            events = sim.advance(1, True)
            digest.update(events.tobytes())
            result.events += int(events.shape[0])
            pos, vel = sim.positions(), sim.velocities()
            checker.tick(sim.tick, pos, vel, events)
    except Exception as exc:  # a model's error is a finding to report, never a crash
        stopped = _stop_message(exc)
    result.ticks_run = int(sim.tick)
    result.run_time_s = time.perf_counter() - began
    result.energy_drift = checker.energy_drift
    result.momentum_drift = checker.momentum_drift
    result.penetration_px = checker.penetration
    result.problems = list(checker.problems)
    first = (pos.tobytes(), vel.tobytes(), digest.hexdigest(), stopped)
    second = _rerun(scene, model, result.ticks_run, stopped is not None)
    differ = [w for w, a, b in zip(_RUN_PARTS, first, second, strict=True) if a != b]
    if differ:
        result.problems.append(
            f"a second run differs in its {', '.join(differ)} (not the same bytes twice)"
        )
    if stopped is not None:
        result.note = stopped
        if model not in scene.expect_stop:
            result.problems.append(f"tick {result.ticks_run + 1}: stopped: {stopped}")
        elif not result.problems:
            result.verdict = VERDICT_STOPPED
    elif model in scene.expect_stop and not result.problems:
        result.problems.append("ran through a runaway that should stop with a clear error")
    if result.problems:
        result.verdict = VERDICT_FAIL
    return result


_RUN_PARTS = ("positions", "velocities", "events", "stop")


def _rerun(scene: Scene, model: str, ticks: int, then_stop: bool):
    """The same case again, unchecked, `CHUNK_TICKS` per call: positions and velocities after
    `ticks`, the digest of their events, and (with then_stop) the error of the next tick."""
    sim = _build(scene, model)
    digest = hashlib.sha256()
    stopped = None
    try:
        while sim.tick < ticks:
            events = sim.advance(min(CHUNK_TICKS, ticks - sim.tick), True)
            digest.update(events.tobytes())
    except Exception as exc:
        stopped = _stop_message(exc)
    pos, vel = sim.positions(), sim.velocities()
    if then_stop and stopped is None:
        try:
            sim.advance(1, True)
        except Exception as exc:
            stopped = _stop_message(exc)
    return pos.tobytes(), vel.tobytes(), digest.hexdigest(), stopped


def run_suite(quick: bool, only_scenes=(), only_models=(), echo=None) -> list[CaseResult]:
    """Every scene under every model it applies to (filtered by name when asked)."""
    results = []
    for scene in scenes(quick):
        if only_scenes and scene.name not in only_scenes:
            continue
        for model in scene.models:
            if only_models and model not in only_models:
                continue
            result = run_case(scene, model)
            results.append(result)
            if echo is not None:
                echo(_line(result))
    return results


# ----------------------------------------------------------------------------- report


def _num(x: float | None) -> str:
    return "—" if x is None else f"{x:.3g}"


def _line(r: CaseResult) -> str:
    return (
        f"{r.scene:<18} {r.model:<8} {r.verdict:<11} {r.ticks_run:>8}/{r.ticks:<8} "
        f"{r.events:>9} {_num(r.energy_drift):>9} {_num(r.momentum_drift):>9} "
        f"{_num(r.penetration_px):>9} {r.run_time_s:>7.2f}s"
    )


HEADER = (
    f"{'scene':<18} {'model':<8} {'verdict':<11} {'ticks run':>17} {'events':>9} "
    f"{'energy':>9} {'momentum':>9} {'overlap':>9} {'time':>8}"
)


def report_markdown(results: list[CaseResult], quick: bool, total_s: float) -> str:
    """The report as markdown: the table, then every problem and note."""
    broken = [r for r in results if r.verdict == VERDICT_FAIL]
    lines = [
        "# collide2d stress report",
        "",
        f"Mode: {'quick' if quick else 'full'}. Cases: {len(results)}, failed: {len(broken)}. "
        f"Total run time: {total_s:.1f} s.",
        "",
        f"Bounds: exact energy {EXACT_ENERGY_TOL:g} and momentum {EXACT_MOMENTUM_TOL:g} "
        f"(relative), stepped {STEPPED_ENERGY_TOL:g} and {STEPPED_MOMENTUM_TOL:g}, paper keeps "
        f"every velocity component's size; overlap after an exact tick at most "
        f"{PENETRATION_TOL_PX:g} px. "
        "Momentum is measured over ticks without wall events, in scenes without static objects.",
        "",
        "| scene | model | verdict | ticks run | events | energy drift | momentum drift "
        "| largest overlap (px) | run time (s) |",
        "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in results:
        lines.append(
            f"| {r.scene} | {r.model} | {r.verdict} | {r.ticks_run} / {r.ticks} | {r.events} "
            f"| {_num(r.energy_drift)} | {_num(r.momentum_drift)} | {_num(r.penetration_px)} "
            f"| {r.run_time_s:.2f} |"
        )
    notes = [r for r in results if r.problems or r.note]
    if notes:
        lines += ["", "## Problems and notes", ""]
        for r in notes:
            for p in r.problems:
                lines.append(f"- **{r.scene} / {r.model}**: {p}")
            if r.note:
                lines.append(f"- {r.scene} / {r.model}: {r.note}")
    run = {r.scene for r in results}
    lines += ["", "## Scenes", ""]
    lines += [f"- `{s.name}`: {s.about}." for s in scenes(quick) if s.name in run]
    return "\n".join(lines) + "\n"


def report_json(results: list[CaseResult], quick: bool, total_s: float) -> dict:
    """The report as a JSON object: mode, verdict, bounds, scene descriptions, every case."""
    return {
        "mode": "quick" if quick else "full",
        "ok": all(r.verdict != VERDICT_FAIL for r in results),
        "run_time_s": round(total_s, 3),
        "bounds": {
            "exact_energy": EXACT_ENERGY_TOL,
            "exact_momentum": EXACT_MOMENTUM_TOL,
            "stepped_energy": STEPPED_ENERGY_TOL,
            "stepped_momentum": STEPPED_MOMENTUM_TOL,
            "penetration_px": PENETRATION_TOL_PX,
        },
        "scenes": {s.name: s.about for s in scenes(quick)},
        "cases": [{k: _json_number(v) for k, v in asdict(r).items()} for r in results],
    }


def _json_number(v):
    """Floats that JSON cannot hold (inf, nan) as text; anything else as it is."""
    return repr(v) if isinstance(v, float) and not math.isfinite(v) else v


def report_dir(out_root) -> Path:
    """OUT/stress, refusing to write through a symbolic link."""
    target = Path(out_root) / REPORT_DIR
    if target.is_symlink():
        raise ValueError(f"report folder {target} is a symbolic link; refusing to write through it")
    return target


# ----------------------------------------------------------------------------- command


def cmd_stress(args: argparse.Namespace) -> int:
    try:
        target = report_dir(args.out)
    except ValueError as exc:
        print(f"collide2d stress: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    known = [s.name for s in scenes(True)]
    unknown = [s for s in args.scene or () if s not in known]
    if unknown:
        print(
            f"collide2d stress: error: unknown scene {unknown[0]!r}; expected one of "
            f"{', '.join(known)}",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    target.mkdir(parents=True, exist_ok=True)
    echo = None if args.quiet else print
    if echo is not None:
        echo(HEADER)
    began = time.perf_counter()
    results = run_suite(args.quick, args.scene or (), args.model or (), echo)
    total = time.perf_counter() - began
    outputs.atomic_write_text(target / "report.md", report_markdown(results, args.quick, total))
    outputs.write_json(target / "report.json", report_json(results, args.quick, total))
    broken = [r for r in results if r.verdict == VERDICT_FAIL]
    for r in broken:
        for p in r.problems:
            print(f"{r.scene} / {r.model}: {p}", file=sys.stderr)
    if not args.quiet:
        print(
            f"stress: {len(results)} cases, {len(broken)} failed, in {total:.1f}s -> "
            f"{target / 'report.md'}"
        )
    return EXIT_BROKEN if broken else EXIT_OK


def register(subparsers) -> None:
    """Add the `stress` subcommand to an argparse subparsers object."""
    p = subparsers.add_parser(
        "stress",
        help="run hostile scenes under every model and check invariants every tick",
        description="Run the stress scenes under every model where they apply, checking every "
        "tick: finite state, objects inside the world, energy and momentum within the model's "
        "bound, no overlap after an exact tick, a clear stop for runaways, the same bytes twice. "
        "Writes OUT/stress/report.md and report.json; exit 1 when an invariant breaks.",
    )
    p.add_argument("--quick", action="store_true", help="shorter, smaller scenes (for CI)")
    p.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    p.add_argument("--scene", action="append", metavar="NAME", help="run only this scene (repeat)")
    p.add_argument(
        "--model", action="append", choices=MODEL_NAMES, help="run only this model (repeat)"
    )
    p.add_argument("--quiet", action="store_true", help="print only problems")
    p.set_defaults(func=cmd_stress)
