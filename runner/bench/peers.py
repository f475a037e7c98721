"""The peers parts of `collide2d bench`: pymunk steps the same scenes (the `bench` extra): the
standard scene (`peers`), and a settling pile under gravity (`gravity`).

pymunk steps at 1/STANDARD_FPS s with boxes of mass 1 and infinite moment, elasticity 1, friction 0
and four static walls: the standard scene run by the pymunk model (`engine.models.pymunk`, the
adapter behind `model: pymunk`, with no collision callback), so the bench times what a scenario
runs; the faster of its bounding-box tree and its spatial hash is
kept (`PymunkTimer`). The scaling part times pymunk in turn with the stepped model (`timer`,
`scaling`'s `peer`): each round one pymunk run between the stepped model's two, so that a
machine whose speed drifts over minutes (a shared virtual machine's does, by a quarter) slows
both sides of the ratio alike (timed apart, minutes after the stepped model, the ratio took that
drift in); `peers` then divides the stepped model's steps/s by pymunk's.

The gravity part (`--part gravity`, `gravity`): the stepped model's settling path against pymunk
under gravity, the stepped and exact models and pymunk against the closed forms (PHYSICS.md), and
the exact model's events per second under gravity (exact.py's `gravity`, run by the part).

A settling pile (`pile`): n boxes of 8 px, e 0.3 and mu 0.3, on a grid ASPECT times as wide as it is
tall (8 rows at 1,000, 25 at 10,000), dropped into a box just wider, at 60 fps with 4 substeps:
nothing falls more than half a box in a step (at 2 substeps the 25 rows land harder than the contact
passes hold: boxes overlap by up to 7.7 px and some never sleep). pymunk steps the same scene at the
same 1/240 s: rotation off (infinite moment), its default 10 iterations and 0.1 px slop, elasticity
and friction √0.3 on every shape (pymunk multiplies the two sides': 0.3 on every contact). Each
times its first simulated second (the pile falling and landing: `moving`), one after the other in
this run; then the stepped model runs on until its pile sleeps and times one more second
(`settled`).

Closed forms: a box dropped 100 px with e 0.5, its first three bounce instants
against `t_n = t1·(1 + 2e(1 - e^(n-1)) / (1 - e))` (each found from the state after the step that
held it: exact between contacts, the bounce lies `τ = 2h / (v + √(v² + 2g·h))` before it, h the
height above the floor and v the speed up); a box sliding at 200 px/s with mu 0.5 against
`v0² / (2·mu·g)`; each at CHART_FPS steps a second (one step a frame) by each, and the stepped
model at LADDER_FPS with LADDER_SUBSTEPS substeps a frame, with the run time
of its CLOSED_S simulated seconds, for gravity_runtime_vs_error.png (runner/bench/plots.py). Rows
are one figure each (`value`, described by `note`).
"""

from __future__ import annotations

import functools
import math
import time

import numpy as np

from collide2d.engine.models import make
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner.bench.scenes import STANDARD_FPS, STANDARD_SIZE_PX, standard_scene
from collide2d.runner.bench.timing import PROBE_S, QUICK_TARGET_S, TARGET_S, median

# pymunk's spatial hash gets cells of this many box sides and this many cells per object.
PYMUNK_HASH_SIDES = 2.0
PYMUNK_HASH_CELLS_PER_OBJECT = 10
PYMUNK_WARMUP_STEPS = 10


def pymunk_available() -> bool:
    try:
        import pymunk  # noqa: F401
    except ImportError:
        return False
    return True


def _pymunk_model(scenario, hashed: bool):
    """The standard scene as the pymunk model (`engine.models.pymunk`, the adapter `model:
    pymunk` runs): boxes of mass 1 and infinite moment (no rotation), elasticity 1, friction 0,
    four static walls, no gravity; no collision callback (pymunk's own speed)."""
    from collide2d.engine.models.pymunk import Model

    spatial_hash = None
    if hashed:
        n = scenario.bodies.n
        spatial_hash = (
            PYMUNK_HASH_SIDES * STANDARD_SIZE_PX,
            max(1000, PYMUNK_HASH_CELLS_PER_OBJECT * n),
        )
    return Model(scenario.world, scenario.bodies, spatial_hash=spatial_hash, events=False)


class PymunkTimer:
    """pymunk on the standard scene with n boxes, its broad phase chosen: both its default tree
    and its spatial hash step a probe of about PROBE_S s (or `target`, when shorter) after a
    warm-up, and the faster is kept (`how` names it). Each `sample()` then times one run of
    about `target` s of it and returns steps/s."""

    def __init__(self, n: int, target: float):
        from collide2d.runner.scenario.load import loads

        scenario = loads(standard_scene(n, "stepped"))
        self.dt = 1.0 / STANDARD_FPS
        best = 0.0
        for hashed in (False, True):
            model = _pymunk_model(scenario, hashed)
            model.advance(PYMUNK_WARMUP_STEPS, log=False)
            began = time.perf_counter()
            steps = 0
            while time.perf_counter() - began < min(target, PROBE_S) or steps < 2:
                model.advance(1, log=False)
                steps += 1
            rate = steps / (time.perf_counter() - began)
            if rate > best:
                best = rate
                self.model = model
                self.how = "spatial hash" if hashed else "bounding-box tree"
        self.ticks = max(2, int(target * best))

    def sample(self) -> float:
        """Steps/s of one timed run."""
        began = time.perf_counter()
        self.model.advance(self.ticks, log=False)
        return self.ticks / (time.perf_counter() - began)


def timer(quick: bool):
    """The peer timers the scaling part interleaves with the stepped model's runs: n -> a
    `PymunkTimer` of this run's length (`peers`' own)."""
    target = QUICK_TARGET_S if quick else TARGET_S / 2
    return lambda n: PymunkTimer(n, target)


def pymunk_steps_per_second(n: int, target: float, repeats: int) -> tuple[float, str]:
    """pymunk's steps/s on the standard scene with n boxes, the median of `repeats` timed runs of
    about `target` s, and its broad phase (`PymunkTimer`)."""
    clock = PymunkTimer(n, target)
    return median([clock.sample() for _ in range(repeats)]), clock.how


def peers(ns: list[int], ours: dict[int, float], timed: dict, echo) -> list[dict]:
    """pymunk on the standard scene at each N, and the stepped model's ratio to it: `ours` the
    stepped model's steps/s by N and `timed` pymunk's (steps/s, broad phase) by N, both from this
    run's scaling part, which timed them in turn (`timer`)."""
    import pymunk

    rows = []
    for n in ns:
        rate, how = timed[n]
        how += ", timed in turn with the stepped model's runs"
        row = {
            "part": "peers",
            "scene": "standard",
            "model": f"pymunk {pymunk.version}",
            "n": n,
            "fps": STANDARD_FPS,
            "steps_per_s": rate,
            "body_steps_per_s": rate * n,
            "ns_per_body_step": 1e9 / (rate * n),
            "peer_steps_per_s": rate,
            "note": how,
            "ratio": ours[n] / rate,
        }
        rows.append(row)
        echo(
            f"peers    pymunk  n={n:<7d} {rate:12,.1f} steps/s ({how}), "
            f"stepped/pymunk = {row['ratio']:.2f}"
        )
    return rows


# --- the gravity part ---------------------------------------------------------------------------

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


def _space(world: WorldSpec, bodies: Bodies, e: float, mu: float):
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
        space = _space(world, bodies, E, MU)
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
    space = _space(world, bodies, DROP_E, 0.0)
    (ball,) = space.bodies
    states = [(0.0, FLOOR_PX - DROP_PX, 0.0)]
    began = time.perf_counter()
    for k in range(1, int(CLOSED_S * fps)):
        space.step(dt)
        states.append((k * dt, ball.position.y - BOX_PX / 2, ball.velocity.y))
    bounce_s = time.perf_counter() - began
    world, block = _block(fps)
    space = _space(world, block, 1.0, SLIDE_MU)
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
        echo(
            f"gravity  stepped  fps={LADDER_FPS}x{k:<3d} bounce {bounce:.2e} s, slide {slide:.2e}"
        )
    return rows


def gravity(quick: bool, echo) -> list[dict]:
    """The part's rows of the stepped model and pymunk: the piles (1,000; and 10,000 unless
    quick), then the closed forms."""
    rows: list[dict] = []
    for n in (1000,) if quick else (1000, 10_000):
        rows += timings(n, echo)
    return rows + closed_forms(echo)
