"""The closed forms of the gravity part (runner/bench/gravity, PHYSICS.md): the stepped and exact
models and pymunk against them, with their run times.

Closed forms: a box dropped 100 px with e 0.5, its first three bounce instants
against `t_n = t1·(1 + 2e(1 - e^(n-1)) / (1 - e))` (each found from the state after the step that
held it: exact between contacts, the bounce lies `τ = 2h / (v + √(v² + 2g·h))` before it, h the
height above the floor and v the speed up); a box sliding at 200 px/s with mu 0.5 against
`v0² / (2·mu·g)`; each at CHART_FPS steps a second (one step a frame) by each, and the stepped
model at LADDER_FPS with LADDER_SUBSTEPS substeps a frame, with the run time
of its CLOSED_S simulated seconds, for gravity_runtime_vs_error.png (runner/bench/plots.py).
"""

from __future__ import annotations

import functools
import math
import time

import numpy as np

from collide2d.engine.models import make
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner.bench.gravity.pile import G, pymunk_space, row


def _bounce_times(states, floor, dt) -> list[float]:
    """The bounce instants from states (t, y, vy) sampled after each step (module docstring)."""
    out = []
    for (_, _, v0), (t, y, v) in zip(states, states[1:], strict=False):
        if v0 > 0.0 and v < 0.0:
            h = floor - y
            up = -v
            out.append(t - 2.0 * max(h, 0.0) / (up + math.sqrt(up * up + 2.0 * G * max(h, 0.0))))
    return out


# The closed forms' scenes (module docstring), and the rates (fps, one step a frame) each model
# runs them at for the run-time-against-error chart (gravity_runtime_vs_error.png).
DROP_E, DROP_PX, BOX_PX, FLOOR_PX = 0.5, 100.0, 10.0, 190.0
SLIDE_V0, SLIDE_MU = 200.0, 0.5
CHART_FPS = (30, 60, 120, 240)
# The stepped model's ladder of substeps at one rate, for the same chart
LADDER_FPS, LADDER_SUBSTEPS = 30, (2, 4, 8, 16, 32, 64)
CLOSED_S = 2.0  # simulated seconds of each closed-form run


def _bounce_expected() -> list[float]:
    """The first three bounce instants of the drop (module docstring), s."""
    e, t1 = DROP_E, math.sqrt(2 * DROP_PX / G)
    return [t1 * (1 + 2 * e * (1 - e ** (k - 1)) / (1 - e)) for k in (1, 2, 3)]


def _drop(fps: int):
    """The drop's world at `fps` and its box."""
    world = WorldSpec(100, int(FLOOR_PX + BOX_PX), fps, gravity=(0.0, G))
    bodies = Bodies.boxes([[45, FLOOR_PX - DROP_PX]], BOX_PX, [[0, 0]])
    return world, Bodies(**{**bodies.__dict__, "restitution": np.array([DROP_E])})


def _block(fps: int):
    """The slide's world at `fps` and its block."""
    world = WorldSpec(400, int(FLOOR_PX + BOX_PX), fps, gravity=(0.0, G))
    bodies = Bodies.boxes([[10, FLOOR_PX]], BOX_PX, [[SLIDE_V0, 0]])
    return world, Bodies(**{**bodies.__dict__, "friction": np.array([SLIDE_MU])})


def _bounce_error(states, dt) -> float:
    """The largest error of the first three bounce instants found in states (t, y, vy), s; inf
    when fewer than three are found (a bounce lost in a coarse step)."""
    found = _bounce_times(states, FLOOR_PX, dt)[:3]
    if len(found) < 3:
        return math.inf
    return max(abs(a - b) for a, b in zip(found, _bounce_expected(), strict=True))


def _ours_closed(name: str, fps: int, substeps: int = 1) -> tuple[float, float, float, float]:
    """(bounce error s, its run time s, slide relative error, its run time s) of the model `name`
    (stepped, with `substeps`; or exact) at `fps`."""
    options = {"substeps": substeps} if name == "stepped" else {}
    world, bodies = _drop(fps)
    model = make(name, world, bodies, **options, **({"sleep": False} if name == "stepped" else {}))
    states = [(0.0, FLOOR_PX - DROP_PX, 0.0)]
    began = time.perf_counter()
    for k in range(1, int(CLOSED_S * fps)):
        model.advance(1, log=False)
        states.append((k / fps, model.positions()[0, 1], model.velocities()[0, 1]))
    bounce_s = time.perf_counter() - began
    world, block = _block(fps)
    model = make(name, world, block, **options)
    began = time.perf_counter()
    model.advance(int(CLOSED_S * fps), log=False)
    slide_s = time.perf_counter() - began
    slide = SLIDE_V0 * SLIDE_V0 / (2 * SLIDE_MU * G)
    err = abs(model.positions()[0, 0] - 10 - slide) / slide
    return _bounce_error(states, 1.0 / fps), bounce_s, err, slide_s


def _pymunk_closed(fps: int) -> tuple[float, float, float, float]:
    """As `_ours_closed`, pymunk stepping at 1/fps s."""
    dt = 1.0 / fps
    world, bodies = _drop(fps)
    space = pymunk_space(world, bodies, DROP_E, 0.0)
    (ball,) = space.bodies
    states = [(0.0, FLOOR_PX - DROP_PX, 0.0)]
    began = time.perf_counter()
    for k in range(1, int(CLOSED_S * fps)):
        space.step(dt)
        states.append((k * dt, ball.position.y - BOX_PX / 2, ball.velocity.y))
    bounce_s = time.perf_counter() - began
    world, block = _block(fps)
    space = pymunk_space(world, block, 1.0, SLIDE_MU)
    (sled,) = space.bodies
    x0 = sled.position.x
    began = time.perf_counter()
    for _ in range(int(CLOSED_S * fps)):
        space.step(dt)
    slide_s = time.perf_counter() - began
    slide = SLIDE_V0 * SLIDE_V0 / (2 * SLIDE_MU * G)
    return _bounce_error(states, dt), bounce_s, abs(sled.position.x - x0 - slide) / slide, slide_s


def closed_forms(echo, rates=CHART_FPS, ladder=LADDER_SUBSTEPS) -> list[dict]:
    """Errors against the closed forms (module docstring), and the run time of each, for the
    stepped model, the exact model and pymunk (when installed) at each of `rates` fps; then the
    stepped model at LADDER_FPS with each of `ladder` substeps."""
    runs = {name: functools.partial(_ours_closed, name) for name in ("stepped", "exact")}
    try:
        import pymunk  # noqa: F401

        runs["pymunk"] = _pymunk_closed
    except ImportError:
        pass
    for name in ("stepped", "exact"):
        _ours_closed(name, rates[0])  # compiled (or loaded) before any clock starts
    rows = []
    for name, run in runs.items():
        for fps in rates:
            bounce, bounce_s, slide, slide_s = run(fps)
            notes = (
                ("bounce", bounce, bounce_s, "largest error of the first 3 bounce instants, s"),
                ("slide", slide, slide_s, "relative error of the slide distance"),
            )
            for scene, value, seconds, note in notes:
                one = row(scene, name, 1, value, f"{note}, at {fps} fps")
                one.update(fps=fps, run_time_s=seconds)
                rows.append(one)
            echo(
                f"gravity  {name:<8s} fps={fps:<4d} bounce {bounce:.2e} s "
                f"({bounce_s * 1e3:.1f} ms), slide {slide:.2e} ({slide_s * 1e3:.1f} ms)"
            )
    for k in ladder:
        bounce, bounce_s, slide, slide_s = _ours_closed("stepped", LADDER_FPS, k)
        for scene, value, seconds in (("bounce", bounce, bounce_s), ("slide", slide, slide_s)):
            one = row(scene, "stepped", 1, value, f"at {LADDER_FPS} fps x {k} substeps")
            one.update(fps=LADDER_FPS, substeps=k, run_time_s=seconds)
            rows.append(one)
        echo(f"gravity  stepped  fps={LADDER_FPS}x{k:<3d} bounce {bounce:.2e} s, slide {slide:.2e}")
    return rows
