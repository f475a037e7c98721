"""The settling pile of the gravity part (runner/bench/gravity): the stepped model's settling path
against pymunk under gravity, per step.

A settling pile (`pile`): n boxes of 8 px, e 0.3 and mu 0.3, on a grid ASPECT times as wide as it is
tall (8 rows at 1,000, 25 at 10,000), dropped into a box just wider, at 60 fps with 4 substeps:
nothing falls more than half a box in a step (at 2 substeps the 25 rows land harder than the contact
passes hold: boxes overlap by up to 7.7 px and some never sleep). pymunk steps the same scene at the
same 1/240 s: rotation off (infinite moment), its default 10 iterations and 0.1 px slop, elasticity
and friction √0.3 on every shape (pymunk multiplies the two sides': 0.3 on every contact). Each
times its first simulated second (the pile falling and landing: `moving`), one after the other in
this run; then the stepped model runs on until its pile sleeps and times one more second
(`settled`). Rows are one figure each (`value`, described by `note`: `row`).
"""

from __future__ import annotations

import math
import time

import numpy as np

from collide2d.engine.models import make
from collide2d.engine.world import Bodies, WorldSpec

G = 980.0
FPS = 60
SUBSTEPS = 4
SIZE = 8.0
PITCH = 10.0
E = 0.3
MU = 0.3
SETTLE_LIMIT_S = 12  # the stepped pile must sleep within this
ASPECT = 16  # the pile's grid is this many times as wide as it is tall


def pile(n: int) -> tuple[WorldSpec, Bodies]:
    """The settling pile of n boxes (module docstring)."""
    rows = max(1, int(round(math.sqrt(n / ASPECT))))
    cols = -(-n // rows)
    width = int(cols * PITCH) + 4
    height = int(rows * PITCH * 1.6) + 20
    k = np.arange(n)
    rng = np.random.default_rng(1)
    pos = np.stack([k % cols, k // cols], axis=1) * PITCH + rng.uniform(0, PITCH - SIZE, (n, 2))
    bodies = Bodies.boxes(pos + 2.0, SIZE, rng.uniform(-20, 20, (n, 2)))
    bodies = Bodies(**{**bodies.__dict__, "restitution": np.full(n, E), "friction": np.full(n, MU)})
    return WorldSpec(width, height, FPS, gravity=(0.0, G)), bodies


def pymunk_space(world: WorldSpec, bodies: Bodies, e: float, mu: float):
    """The scene as a pymunk space (module docstring)."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, G)
    space.iterations = 10
    w, h = world.width, world.height
    corners = ((0, 0), (w, 0), (w, h), (0, h))
    for k in range(4):
        wall = pymunk.Segment(space.static_body, corners[k], corners[(k + 1) % 4], 0.0)
        wall.elasticity = math.sqrt(e)
        wall.friction = math.sqrt(mu)
        space.add(wall)
    for (x, y), (bw, bh), (vx, vy) in zip(
        bodies.pos.tolist(), bodies.size.tolist(), bodies.vel.tolist(), strict=True
    ):
        body = pymunk.Body(1.0, math.inf)
        body.position = (x + bw / 2, y + bh / 2)
        body.velocity = (vx, vy)
        shape = pymunk.Poly.create_box(body, (bw, bh))
        shape.elasticity = math.sqrt(e)
        shape.friction = math.sqrt(mu)
        space.add(body, shape)
    return space


def _ms_per_step(run, steps: int) -> float:
    began = time.perf_counter()
    run(steps)
    return (time.perf_counter() - began) / steps * 1e3


def row(scene, model, n, value, note) -> dict:
    """One figure of the gravity part, its note led by the model's name."""
    return {
        "part": "gravity",
        "scene": scene,
        "model": model,
        "n": n,
        "value": value,
        "note": f"{model}: {note}",
    }


def timings(n: int, echo) -> list[dict]:
    """Per-step times of the settling pile of n boxes: stepped and pymunk moving, stepped
    settled."""
    world, bodies = pile(n)
    steps = FPS * SUBSTEPS
    model = make("stepped", world, bodies, substeps=SUBSTEPS)
    model.advance(1)  # compiled (or loaded) before the clock starts
    ours = _ms_per_step(lambda k: model.advance(k // SUBSTEPS, log=False), steps)
    each = f"ms per step (1/{FPS * SUBSTEPS} s)"
    rows = [row(f"pile-{n}", "stepped", n, ours, f"{each}, the first second")]
    slept = 1.0 + 1.0 / FPS
    while not model._settle.asleep().all() and slept < SETTLE_LIMIT_S:
        model.advance(FPS // 2, log=False)
        slept += 0.5
    settled = _ms_per_step(lambda k: model.advance(k // SUBSTEPS, log=False), steps)
    asleep = int(model._settle.asleep().sum())
    rows.append(
        row(
            f"pile-{n}",
            "stepped",
            n,
            settled,
            f"ms per step settled ({asleep}/{n} asleep after {slept:.1f} s)",
        )  # fmt: skip
    )
    rows.append(
        row(f"pile-{n}", "stepped", n, settled / ours, "settled / moving per step (target <= 0.1)")
    )
    echo(f"gravity  stepped  n={n:<6d} moving {ours:8.3f} ms/step, settled {settled:8.4f} ms/step")
    try:
        space = pymunk_space(world, bodies, E, MU)
    except ImportError:
        return rows
    dt = 1.0 / (FPS * SUBSTEPS)
    space.step(dt)

    def stepping(k):
        for _ in range(k):
            space.step(dt)

    peer = _ms_per_step(stepping, steps)
    rows.append(row(f"pile-{n}", "pymunk", n, peer, f"{each}, the first second"))
    target = 5 if n < 5000 else 10
    rows.append(
        row(
            f"pile-{n}",
            "stepped",
            n,
            peer / ours,
            f"pymunk / stepped per step (target >= {target})",
        )
    )
    echo(f"gravity  pymunk   n={n:<6d} moving {peer:8.3f} ms/step; stepped {peer / ours:.2f}x")
    return rows
