"""The `bench` command: how fast each model runs, and how far from the reference it lands.

Input: the command line (`collide2d bench [--quick] [--peers] [--part P] [--n N] [--out DIR]`),
the benchmark scenarios `scenarios/bench_*.yaml` and the standard scene built here. Output, under
`OUT/bench/` (each file written whole through a temporary name): `bench.csv` (one row per
measurement, the columns of `COLUMNS`), `bench.md` (the same as tables, with the headline ratios
first) and, when matplotlib is installed (the optional `plot` extra), `scaling.png` and
`runtime_vs_error.png`. Progress goes to stderr unless `--quiet`; the headline table to stdout.

The parts, each selectable with `--part`:
- scaling: the standard scene (N boxes 10x10 px covering 5 % of a 4:3 world, speeds 10-100 px/s in
  random directions, 60 fps, seed 1) under each model at each N: steps/s measured through
  `collide2d run` as a user runs it, in a subprocess, start-up excluded by subtracting a 1-tick run
  (`--in-process` times `runner.run.drive` instead, the same way); body-steps/s; events/s (events
  per tick of a logged run times steps/s); the time per step of each stage (move, broad phase,
  narrow phase, response, from `Model.profile`, where the model has stages) and the time to
  render one frame.
- error: each benchmark scenario under each model at a ladder of fps and substeps, against the
  exact model at the scenario's fps: run time, missed collisions (per pair, collisions of the
  reference the run does not have), collision-count error (pair events of the run minus the
  reference's), kinetic energy drift (relative), largest penetration (the deepest box overlap at a
  tick's end, px) and position error over a short horizon (mean distance to the reference
  HORIZON_S seconds after the reference's first collision, px; long horizons are chaotic). A row
  is on the Pareto front when no other
  row of its scenario is both faster and closer.
- peers: with `--peers` and pymunk installed (the optional `bench` extra), pymunk steps the same
  standard scene in the same run (`pymunk_steps_per_second`), and the stepped model's ratio to it
  is printed.
- skips: for each thing a run skips when a scene does not need it, the same work with and
  without the skip, and the saving (time without / time with).
- targets: the paper's section IV demo headless (ticks/s through the model's `advance`) and the
  wall time of `collide2d run` on a small scenario once kernels are cached.

Quote ratios from one run: absolute times move with the machine and its load. `--quick` shrinks
every part (small N, short runs, one repeat, in-process timing) to a few seconds, for tests.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

from collide2d.engine import models
from collide2d.engine.events import EV_PAIR
from collide2d.engine.invariants import kinetic_energy
from collide2d.engine.world import WorldSpec

# subprocess, tempfile, csv and io are imported where used: `collide2d` loads this module for its
# parser, and a run should not pay for them.

EXIT_OK = 0
EXIT_BAD_INPUT = 2

PARTS = ("scaling", "error", "peers", "skips", "targets")
DEFAULT_PARTS = ("scaling", "error", "skips", "targets")
REPORT_DIR = "bench"

# The standard scene (the issue's): boxes of STANDARD_SIZE_PX covering STANDARD_COVERAGE of a world
# of aspect STANDARD_ASPECT, speeds STANDARD_SPEEDS px/s in random directions, at STANDARD_FPS.
STANDARD_SIZE_PX = 10
STANDARD_COVERAGE = 0.05
STANDARD_ASPECT = 4 / 3
STANDARD_SPEEDS = (10, 100)
STANDARD_FPS = 60
STANDARD_SEED = 1
SCALING_N = (50, 1_000, 10_000, 100_000)
QUICK_N = (50, 400)
# Each timed run aims at about this many seconds of stepping (the 1-tick run is subtracted).
TARGET_S = 2.0
QUICK_TARGET_S = 0.05
REPEATS = 3
# Frames timed for the render column (the first draw of a renderer repaints everything).
RENDER_FRAMES = 4
# The in-process probe that estimates a rate runs this long (s), and so do the logged run that
# counts events and the staged run that times each stage.
PROBE_S = 0.2
QUICK_PROBE_S = 0.02

# Run time against error: the scenarios, the horizon of the position error, and the ladders.
BENCH_SCENARIOS = (
    "bench_tunnelling",
    "bench_dense_gas",
    "bench_mass_ratio_chain",
    "bench_fast_small",
)
HORIZON_S = 0.5
# The horizon is rounded up to a multiple of this (s), a whole number of ticks at every fps of
# the ladders.
HORIZON_GRID_S = 0.1
LADDER = {
    "paper": [(fps, 1) for fps in (10, 30, 60, 120, 240)],
    "stepped": [(fps, s) for fps in (10, 30, 60, 120) for s in (1, 4, 16)],
    "exact": [(10, 1), (60, 1)],
}
QUICK_LADDER = {"paper": [(30, 1), (60, 1)], "stepped": [(60, 1), (60, 4)], "exact": [(60, 1)]}
# In quick mode a benchmark scenario runs at most this long (s).
QUICK_DURATION_S = 0.5

# The skips' scenes: ticks of the frame skips (paper section IV demo), the statics scene (one mover
# among SKIP_STATICS static boxes), the gas of the log and exact-model skips.
SKIP_TICKS = 600
SKIP_STATICS = 4000
SKIP_GAS = 200

# The section IV demo's headless run, and the small scenario timed through `collide2d run`.
DEMO_TICKS = 1_000_000
QUICK_DEMO_TICKS = 20_000
SMALL_SCENARIO = "tunnelling_1fps"

# The peer: pymunk's space steps at 1/STANDARD_FPS s; its spatial hash gets cells of this many
# box sides and this many cells per object, and the better of it and the default tree is kept.
PYMUNK_HASH_SIDES = 2.0
PYMUNK_HASH_CELLS_PER_OBJECT = 10
PYMUNK_WARMUP_STEPS = 10
# The target (stepped at least 5x pymunk's steps/s) is for N = 1,000 and up.
PEER_TARGET_MIN_N = 1_000

COLUMNS = (
    "part",
    "scene",
    "model",
    "n",
    "fps",
    "substeps",
    "ticks",
    "steps_per_s",
    "body_steps_per_s",
    "ns_per_body_step",
    "events_per_s",
    "move_ms",
    "broad_ms",
    "narrow_ms",
    "response_ms",
    "render_ms",
    "run_time_s",
    "pairs",
    "missed",
    "count_error",
    "energy_drift",
    "max_penetration_px",
    "position_error_px",
    "horizon_s",
    "pareto",
    "peer_steps_per_s",
    "ratio",
    "with_s",
    "without_s",
    "saving",
    "value",
    "note",
)


# ---------------------------------------------------------------------------- the scenes


def standard_world(n: int) -> tuple[int, int]:
    """(width, height) px of the standard scene's 4:3 world where n boxes cover 5 % of it."""
    area = n * STANDARD_SIZE_PX**2 / STANDARD_COVERAGE
    width = round(math.sqrt(area * STANDARD_ASPECT))
    return width, round(width / STANDARD_ASPECT)


def standard_scene(n: int, model: str, ticks: int = 1) -> str:
    """The standard scene with n boxes under `model`, as scenario text."""
    width, height = standard_world(n)
    lo, hi = STANDARD_SPEEDS
    return (
        "version: 1\n"
        f"name: standard-{n}\n"
        f"description: The standard scene of collide2d bench, {n} boxes.\n"
        f"world: {{width: {width}, height: {height}, fps: {STANDARD_FPS}}}\n"
        f"model: {model}\n"
        f"ticks: {ticks}\n"
        "generate:\n"
        f"  - {{count: {n}, shape: box, size: {STANDARD_SIZE_PX}, "
        f"speed: {{min: {lo}, max: {hi}}}, seed: {STANDARD_SEED}}}\n"
        "output: {frames: none, gif: false, events: false}\n"
    )


# The scenario files the parts read (besides the standard scene, built here).
NEEDED_SCENARIOS = (*BENCH_SCENARIOS, "paper_fifty_boxes", SMALL_SCENARIO)
# Where they are: set by `--scenarios`, else the project's scenarios/ folder.
_SCENARIOS: list[Path] = []


def scenarios_dir() -> Path:
    """The folder of the benchmark scenarios: `--scenarios DIR`, or the project's scenarios/
    folder (next to the runner package)."""
    if _SCENARIOS:
        return _SCENARIOS[0]
    return Path(__file__).resolve().parent.parent / "scenarios"


# ---------------------------------------------------------------------------- timing helpers


def _median(values) -> float:
    return float(statistics.median(values))


def _cli_seconds(path: Path, ticks: int, out: Path) -> float:
    """Wall time of `collide2d run PATH --ticks T` with nothing written but final.csv and summary,
    in a subprocess (`python -m collide2d`, what the console script runs)."""
    import subprocess

    cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--no-gif", "--no-png"]
    cmd += ["--no-events", "--quiet", "--ticks", str(ticks), "--out", str(out)]
    began = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - began


def _drive_seconds(text: str, ticks: int) -> float:
    """Seconds `runner.run.drive` takes over `ticks` ticks of the scenario text (loading not
    counted; model set-up counted, as in a run)."""
    from collide2d.runner.run import drive
    from collide2d.runner.scenario import loads

    scenario = loads(text, overrides={"ticks": ticks})
    began = time.perf_counter()
    drive(scenario)
    return time.perf_counter() - began


def _probe_rate(model, seconds: float) -> float:
    """Ticks per second of `model.advance` (log off), from runs doubling until `seconds` long
    (after one untimed tick that loads the kernels)."""
    model.advance(1, log=False)
    ticks = 1
    while True:
        began = time.perf_counter()
        model.advance(ticks, log=False)
        spent = time.perf_counter() - began
        if spent >= seconds or ticks >= 1 << 20:
            return ticks / max(spent, 1e-9)
        ticks *= 2


class Echo:
    """Progress lines on stderr (nothing when quiet)."""

    def __init__(self, quiet: bool):
        self.quiet = quiet

    def __call__(self, text: str) -> None:
        if not self.quiet:
            print(text, file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------- scaling


def scaling(models_: list[str], ns: list[int], quick: bool, in_process: bool, echo) -> list[dict]:
    """The standard scene under each model at each N: one row each (see the module docstring)."""
    import tempfile

    rows = []
    target = QUICK_TARGET_S if quick else TARGET_S
    probe = QUICK_PROBE_S if quick else PROBE_S
    repeats = 1 if quick else REPEATS
    with tempfile.TemporaryDirectory(prefix="collide2d-bench-") as tmp:
        tmp = Path(tmp)
        for model in models_:
            for n in ns:
                rows.append(_scaling_row(model, n, target, probe, repeats, in_process, tmp, echo))
    return rows


def _scaling_row(model, n, target, probe_s, repeats, in_process, tmp: Path, echo) -> dict:
    from collide2d.engine.raster import Renderer
    from collide2d.runner.scenario import loads

    text = standard_scene(n, model)
    scenario = loads(text)
    world, bodies = scenario.world, scenario.bodies
    # estimate the rate in process (kernels loaded), then size the timed runs from it
    probe = models.make(model, world, bodies)
    rate = _probe_rate(probe, probe_s)
    ticks = max(2, int(target * rate))
    if in_process:
        t1 = _median(_drive_seconds(text, 1) for _ in range(repeats))
        tt = _median(_drive_seconds(text, ticks) for _ in range(repeats))
        how = "in process (drive)"
    else:
        path = tmp / f"standard_{model}_{n}.yaml"
        path.write_text(text)
        out = tmp / "out"
        _cli_seconds(path, 1, out)  # warm the file cache and the kernels
        t1 = _median(_cli_seconds(path, 1, out) for _ in range(repeats))
        tt = _median(_cli_seconds(path, ticks, out) for _ in range(repeats))
        how = "collide2d run"
    if not tt > 1.5 * t1:  # too short to stand out of the start-up's noise: say so
        how += ", noisy (the run was not much longer than the 1-tick run)"
    per_step = max(tt - t1, 1e-12) / (ticks - 1)
    steps = 1.0 / per_step
    # events per tick from a logged run of the same length as the probe
    logged = models.make(model, world, bodies)
    log_ticks = max(1, min(ticks, int(probe_s * rate) + 1))
    events = len(logged.advance(log_ticks, log=True)) / log_ticks
    row = {
        "part": "scaling",
        "scene": "standard",
        "model": model,
        "n": n,
        "fps": STANDARD_FPS,
        "substeps": 1,
        "ticks": ticks,
        "steps_per_s": steps,
        "body_steps_per_s": steps * n,
        "ns_per_body_step": 1e9 * per_step / n,
        "events_per_s": events * steps,
        "note": how,
    }
    # time per stage, where the model has stages (state as after the logged run)
    if hasattr(logged, "profile"):
        prof_ticks = max(1, min(ticks, int(probe_s * rate) + 1))
        logged.profile(1)  # load the stage kernels
        spent = logged.profile(prof_ticks)
        for stage, seconds in spent.items():
            row[f"{stage}_ms"] = 1e3 * seconds / prof_ticks
    renderer = Renderer(world, bodies)
    renderer.draw(logged.positions())  # the first frame is a full one; then load the redraw
    logged.advance(1, log=False)
    renderer.draw(logged.positions())
    began = time.perf_counter()
    for _ in range(RENDER_FRAMES):
        logged.advance(1, log=False)
        renderer.draw(logged.positions())
    row["render_ms"] = 1e3 * (time.perf_counter() - began) / RENDER_FRAMES
    echo(
        f"scaling  {model:7s} n={n:<7d} {steps:12,.1f} steps/s  "
        f"{row['ns_per_body_step']:8.1f} ns/body-step  ({how}, {ticks} ticks)"
    )
    return row


# ---------------------------------------------------------------------------- peers


def pymunk_available() -> bool:
    try:
        import pymunk  # noqa: F401
    except ImportError:
        return False
    return True


def _pymunk_space(scenario, hashed: bool):
    """The standard scene as a pymunk space: boxes of mass 1 and infinite moment (no rotation),
    elasticity 1, friction 0, four static walls, no gravity."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
    n = scenario.bodies.n
    if hashed:
        space.use_spatial_hash(
            PYMUNK_HASH_SIDES * STANDARD_SIZE_PX, max(1000, PYMUNK_HASH_CELLS_PER_OBJECT * n)
        )
    w, h = scenario.world.width, scenario.world.height
    corners = ((0, 0), (w, 0), (w, h), (0, h))
    for k in range(4):
        wall = pymunk.Segment(space.static_body, corners[k], corners[(k + 1) % 4], 0.0)
        wall.elasticity = 1.0
        wall.friction = 0.0
        space.add(wall)
    b = scenario.bodies
    for (x, y), (bw, bh), (vx, vy) in zip(
        b.pos.tolist(), b.size.tolist(), b.vel.tolist(), strict=True
    ):
        body = pymunk.Body(1.0, math.inf)
        body.position = (x + bw / 2, y + bh / 2)
        body.velocity = (vx, vy)
        shape = pymunk.Poly.create_box(body, (bw, bh))
        shape.elasticity = 1.0
        shape.friction = 0.0
        space.add(body, shape)
    return space


def pymunk_steps_per_second(n: int, target: float, repeats: int) -> tuple[float, str]:
    """pymunk's steps/s on the standard scene with n boxes, the median of `repeats` timed runs of
    about `target` s after a warm-up; the better of its default tree and its spatial hash."""
    from collide2d.runner.scenario import loads

    scenario = loads(standard_scene(n, "stepped"))
    dt = 1.0 / STANDARD_FPS
    best, how = 0.0, ""
    for hashed in (False, True):
        space = _pymunk_space(scenario, hashed)
        for _ in range(PYMUNK_WARMUP_STEPS):
            space.step(dt)
        began = time.perf_counter()
        steps = 0
        while time.perf_counter() - began < min(target, PROBE_S) or steps < 2:
            space.step(dt)
            steps += 1
        per = (time.perf_counter() - began) / steps
        ticks = max(2, int(target / per))
        rates = []
        for _ in range(repeats):
            began = time.perf_counter()
            for _ in range(ticks):
                space.step(dt)
            rates.append(ticks / (time.perf_counter() - began))
        rate = _median(rates)
        if rate > best:
            best, how = rate, "spatial hash" if hashed else "bounding-box tree"
    return best, how


def peers(ns: list[int], ours: dict[int, float], quick: bool, echo) -> list[dict]:
    """pymunk on the standard scene at each N, and the stepped model's ratio to it (`ours`: the
    stepped model's steps/s by N, from this run's scaling part)."""
    import pymunk

    rows = []
    target = QUICK_TARGET_S if quick else TARGET_S / 2
    repeats = 1 if quick else REPEATS
    for n in ns:
        rate, how = pymunk_steps_per_second(n, target, repeats)
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
        }
        if n in ours:
            row["ratio"] = ours[n] / rate
        rows.append(row)
        said = f", stepped/pymunk = {row['ratio']:.2f}" if "ratio" in row else ""
        echo(f"peers    pymunk  n={n:<7d} {rate:12,.1f} steps/s ({how}){said}")
    return rows


# ---------------------------------------------------------------------------- run time vs error


def _pair_counts(events) -> Counter:
    pairs = events[events["type"] == EV_PAIR]
    return Counter(zip(pairs["a"].tolist(), pairs["b"].tolist(), strict=True))


def max_penetration(pos: np.ndarray, size: np.ndarray) -> float:
    """The deepest overlap of two boxes, min(overlap width, overlap height), px (0 if none).
    pos, size (n, 2) px."""
    from collide2d.engine.broadphase import METHOD_SWEEP, find_pairs

    pairs = find_pairs(METHOD_SWEEP, pos, pos + size, np.ones(len(pos), bool))
    if not len(pairs):
        return 0.0
    a, b = pairs[:, 0], pairs[:, 1]
    over = np.minimum(pos[a] + size[a], pos[b] + size[b]) - np.maximum(pos[a], pos[b])
    return float(over.min(axis=1).max())


def _reference(scenario, duration: float) -> dict:
    """The exact model at the scenario's fps: pair counts over `duration` s, positions at the
    horizon (HORIZON_S after its first collision, on the HORIZON_GRID_S grid, within the run)."""
    world, bodies = scenario.world, scenario.bodies
    events = models.make("exact", world, bodies).advance(round(duration * world.fps), log=True)
    pairs = events[events["type"] == EV_PAIR]
    first = float(pairs["t"][0]) if len(pairs) else 0.0
    steps = math.ceil(round((first + HORIZON_S) / HORIZON_GRID_S, 9))
    horizon = min(steps * HORIZON_GRID_S, duration)
    model = models.make("exact", world, bodies)
    model.advance(round(horizon * world.fps), log=False)
    return {"pairs": _pair_counts(events), "horizon_s": horizon, "horizon": model.positions()}


def error_ladder(names, models_, quick: bool, echo) -> list[dict]:
    """Each benchmark scenario under each model and (fps, substeps) of the ladder, against the
    exact model: one row each (see the module docstring)."""
    from collide2d.runner.scenario import load

    ladder = QUICK_LADDER if quick else LADDER
    repeats = 1 if quick else REPEATS
    rows = []
    for name in names:
        scenario = load(scenarios_dir() / f"{name}.yaml")
        duration = scenario.ticks / scenario.world.fps
        if quick:
            duration = min(duration, QUICK_DURATION_S)
        ref = _reference(scenario, duration)
        ref_pairs = sum(ref["pairs"].values())
        scene_rows = []
        for model in models_:
            for fps, substeps in ladder.get(model, ()):
                row = _error_row(scenario, model, fps, substeps, duration, ref, repeats)
                row["count_error"] = row["pairs"] - ref_pairs
                scene_rows.append(row)
                echo(
                    f"error    {name:24s} {model:7s} fps={fps:<4d} substeps={substeps:<3d} "
                    f"{row['run_time_s'] * 1e3:9.2f} ms  pos err {row['position_error_px']:.3g} px"
                )
        _mark_pareto(scene_rows)
        rows.extend(scene_rows)
    return rows


def _error_row(scenario, model, fps, substeps, duration, ref, repeats) -> dict:
    base = scenario.world
    world = WorldSpec(base.width, base.height, fps)
    bodies = scenario.bodies
    options = {"substeps": substeps} if model == "stepped" else {}
    ticks = round(duration * fps)
    h_ticks = round(ref["horizon_s"] * fps)
    # run time: clean runs with the log on, as a run that writes events
    times = []
    for _ in range(repeats):
        m = models.make(model, world, bodies, **options)
        began = time.perf_counter()
        m.advance(ticks, log=True)
        times.append(time.perf_counter() - began)
    # errors: one run looked at after every tick
    m = models.make(model, world, bodies, **options)
    energy0 = kinetic_energy(bodies.mass, bodies.static, m.velocities())
    chunks, deepest, at_horizon = [], 0.0, None
    for k in range(1, ticks + 1):
        chunks.append(m.advance(1, log=True))
        deepest = max(deepest, max_penetration(m.positions(), bodies.size))
        if k == h_ticks:
            at_horizon = m.positions()
    if at_horizon is None:
        at_horizon = m.positions()
    events = np.concatenate(chunks) if chunks else m.advance(0, log=True)
    counts = _pair_counts(events)
    energy1 = kinetic_energy(bodies.mass, bodies.static, m.velocities())
    missed = sum(max(0, c - counts.get(p, 0)) for p, c in ref["pairs"].items())
    return {
        "part": "error",
        "scene": scenario.name,
        "model": model,
        "n": bodies.n,
        "fps": fps,
        "substeps": substeps,
        "ticks": ticks,
        "run_time_s": _median(times),
        "pairs": sum(counts.values()),
        "missed": missed,
        "energy_drift": (energy1 - energy0) / energy0 if energy0 else 0.0,
        "max_penetration_px": deepest,
        "position_error_px": float(np.linalg.norm(at_horizon - ref["horizon"], axis=1).mean()),
        "horizon_s": ref["horizon_s"],
    }


def _mark_pareto(rows: list[dict]) -> None:
    """pareto = "yes" for the rows no other row beats on both run time and position error."""
    for r in rows:
        beaten = any(
            o is not r
            and o["run_time_s"] <= r["run_time_s"]
            and o["position_error_px"] <= r["position_error_px"]
            and (
                o["run_time_s"] < r["run_time_s"] or o["position_error_px"] < r["position_error_px"]
            )
            for o in rows
        )
        r["pareto"] = "no" if beaten else "yes"


# ---------------------------------------------------------------------------- skips


def _best_of(fn, repeats: int) -> float:
    """The shortest of `repeats` timings of fn() (s): skips compare like with like."""
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        fn()
        times.append(time.perf_counter() - began)
    return min(times)


def skips(quick: bool, echo) -> list[dict]:
    """Each skip's work with and without it (see the module docstring)."""
    from collide2d.engine.raster import Renderer
    from collide2d.engine.world import Bodies
    from collide2d.runner.run import drive
    from collide2d.runner.scenario import load

    repeats = 1 if quick else REPEATS
    ticks = 60 if quick else SKIP_TICKS
    demo = load(scenarios_dir() / "paper_fifty_boxes.yaml", overrides={"ticks": ticks})
    every = list(range(0, ticks + 1, 10))
    frames_all = list(range(ticks + 1))

    def run(frames):
        return lambda: drive(demo, frames=frames, on_frame=lambda k, idx: None)

    cases = [
        ("no rasterising when no frame is asked for", run(()), run(frames_all), "section IV demo"),
        ("only the frames asked for (every 10th)", run(every), run(frames_all), "section IV demo"),
    ]
    # one mover among many static boxes: no pairs of two static objects
    rng = np.random.default_rng(STANDARD_SEED)
    k = 400 if quick else SKIP_STATICS
    side = int(math.sqrt(k)) + 1
    cells = rng.permutation(side * side)[:k]
    pos = np.stack([cells % side * 12.0, cells // side * 12.0], axis=1)
    pos = np.vstack([[[-100.0, -100.0]], pos]) + 100.0
    static = np.ones(k + 1, bool)
    static[0] = False
    vel = np.zeros((k + 1, 2))
    vel[0] = [97.0, 61.0]
    world = WorldSpec(side * 12 + 200, side * 12 + 200, 60)
    statics = Bodies.boxes(pos, 10.0, vel, static=static)
    steps = 30 if quick else 300
    for model in ("paper", "stepped"):
        cases.append(
            (
                f"no pair work between static objects ({model})",
                lambda m=model: models.make(m, world, statics).advance(steps, log=False),
                lambda m=model: models.make(m, world, statics, skip=False).advance(steps, False),
                f"1 mover, {k} static boxes, {steps} ticks",
            )
        )
    gas = load(scenarios_dir() / "bench_dense_gas.yaml", overrides={"ticks": 30 if quick else 240})
    for model in ("stepped", "exact"):
        cases.append(
            (
                f"no event records when no log is asked for ({model})",
                lambda m=model: models.make(m, gas.world, gas.bodies).advance(gas.ticks, False),
                lambda m=model: models.make(m, gas.world, gas.bodies).advance(gas.ticks, True),
                f"dense gas, {gas.ticks} ticks",
            )
        )
    # erase only what moved: 5 of the demo's 50 boxes move
    frames = 50 if quick else 2000
    moving = np.array(demo.bodies.pos)
    path = np.empty((frames, len(moving), 2))
    for f in range(frames):
        moving[:5] += 1.0
        moving[:5] %= 200.0
        path[f] = moving
    renderer_dirty = Renderer(demo.world, demo.bodies)
    renderer_full = Renderer(demo.world, demo.bodies)
    cases.append(
        (
            "erase only what moved",
            lambda: [renderer_dirty.draw(p) for p in path],
            lambda: [renderer_full.draw_full(p) for p in path],
            f"section IV demo frame, 5 of 50 boxes moving, {frames} frames",
        )
    )
    if _exact_has_full_repredict():
        cases.append(
            (
                "exact re-predicts only what an event touched",
                lambda: models.make("exact", gas.world, gas.bodies).advance(gas.ticks, False),
                lambda: models.make("exact", gas.world, gas.bodies, repredict="all").advance(
                    gas.ticks, False
                ),
                f"dense gas, {gas.ticks} ticks",
            )
        )
    rows = []
    for name, with_skip, without_skip, scene in cases:
        with_skip()  # warm-up: load the kernels
        without_skip()
        t_with = _best_of(with_skip, repeats)
        t_without = _best_of(without_skip, repeats)
        rows.append(
            {
                "part": "skips",
                "scene": scene,
                "with_s": t_with,
                "without_s": t_without,
                "saving": t_without / max(t_with, 1e-12),
                "note": name,
            }
        )
        echo(f"skips    {name:52s} x{rows[-1]['saving']:.1f}")
    return rows


def _exact_has_full_repredict() -> bool:
    """Whether the exact model takes the `repredict="all"` option (re-predict every object after
    each event: the work its local re-prediction saves)."""
    import inspect

    from collide2d.engine.models import exact

    return "repredict" in inspect.signature(exact.Model).parameters


# ---------------------------------------------------------------------------- targets


def targets(quick: bool, echo) -> list[dict]:
    """The section IV demo headless, and `collide2d run` of a small scenario, wall time."""
    import subprocess
    import tempfile

    from collide2d.runner.scenario import load

    repeats = 1 if quick else 5
    ticks = QUICK_DEMO_TICKS if quick else DEMO_TICKS
    demo = load(scenarios_dir() / "paper_fifty_boxes.yaml")
    models.make("paper", demo.world, demo.bodies).advance(2, log=False)

    def headless():
        models.make("paper", demo.world, demo.bodies).advance(ticks, log=False)

    rate = ticks / _median(_timed(headless) for _ in range(repeats))
    rows = [
        {
            "part": "targets",
            "scene": "paper_fifty_boxes",
            "model": "paper",
            "n": demo.bodies.n,
            "ticks": ticks,
            "steps_per_s": rate,
            "value": rate,
            "note": "section IV demo headless, ticks/s (target >= 1,000,000)",
        }
    ]
    echo(f"targets  section IV demo headless {rate:14,.0f} ticks/s")
    if not quick:
        path = scenarios_dir() / f"{SMALL_SCENARIO}.yaml"
        with tempfile.TemporaryDirectory(prefix="collide2d-bench-") as tmp:
            cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--quiet", "--out", tmp]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)  # kernels cached
            wall = _median(
                _timed(lambda: subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL))
                for _ in range(repeats)
            )
        rows.append(
            {
                "part": "targets",
                "scene": SMALL_SCENARIO,
                "model": "paper",
                "run_time_s": wall,
                "value": wall,
                "note": "collide2d run of a small scenario (all outputs), wall s (target < 1)",
            }
        )
        echo(f"targets  collide2d run {SMALL_SCENARIO} {wall:.3f} s")
    return rows


def _timed(fn) -> float:
    began = time.perf_counter()
    fn()
    return time.perf_counter() - began


# ---------------------------------------------------------------------------- reports


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def csv_text(rows: list[dict]) -> str:
    """bench.csv: a header of COLUMNS and one line per row, blanks where a column does not apply."""
    import csv
    import io

    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(COLUMNS)
    for r in rows:
        writer.writerow([_cell(r.get(c)) for c in COLUMNS])
    return buf.getvalue()


def _fmt(value, digits: int = 3) -> str:
    """A table cell: whole thousands with separators, else `digits` significant digits."""
    if value is None or value == "":
        return "—"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return str(value)
    if value != value:  # nan
        return "nan"
    if abs(value) >= 1000:
        return f"{value:,.0f}"
    if isinstance(value, (int, np.integer)):
        return str(value)
    return f"{value:.{digits}g}"


def _table(header: list[str], lines: list[list]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(_fmt(v) for v in line) + " |" for line in lines]
    return out


def headline(rows: list[dict]) -> list[tuple[str, str]]:
    """(what, figure) pairs of the issue's targets, from this run's rows."""
    out = []
    scale = {r["n"]: r for r in rows if r["part"] == "scaling" and r["model"] == "stepped"}
    for r in rows:
        if r["part"] == "peers" and "ratio" in r:
            target = " (target >= 5)" if r["n"] >= PEER_TARGET_MIN_N else ""
            out.append((f"stepped / pymunk steps/s, N = {r['n']:,}{target}", f"{r['ratio']:.2f}"))
    if 1_000 in scale and max(scale) > 1_000:
        big = max(scale)
        ratio = scale[big]["ns_per_body_step"] / scale[1_000]["ns_per_body_step"]
        out.append(
            (f"stepped cost per body-step, N = {big:,} / N = 1,000 (target <= 2)", f"{ratio:.2f}")
        )
    for r in rows:
        if r["part"] == "targets":
            figure = f"{r['value']:,.0f}" if r["value"] > 100 else f"{r['value']:.3f}"
            out.append((r["note"], figure))
    return out


def markdown(rows: list[dict], args_line: str, seconds: float) -> str:
    """bench.md: headline, then one table per part."""
    lines = ["# collide2d bench", ""]
    lines.append(
        f"`{args_line}` on {_machine()}, {seconds:.0f} s in all. Ratios are from this one run."
    )
    lines.append("")
    head = headline(rows)
    if head:
        lines += ["## Headline", ""] + _table(["what", "figure"], [list(h) for h in head]) + [""]
    part = [r for r in rows if r["part"] == "scaling"]
    if part:
        lines += ["## Scaling: the standard scene", ""]
        lines.append(
            f"N boxes {STANDARD_SIZE_PX}x{STANDARD_SIZE_PX} px covering "
            f"{STANDARD_COVERAGE:.0%} of a 4:3 world, {STANDARD_SPEEDS[0]}-{STANDARD_SPEEDS[1]} "
            f"px/s, {STANDARD_FPS} fps, seed {STANDARD_SEED}. Stage times per step are measured "
            "by running the stages one at a time (each includes a call's overhead of a few "
            "microseconds); render is one frame of the whole world."
        )
        lines.append("")
        header = ["model", "N", "steps/s", "body-steps/s", "ns/body-step", "events/s"]
        header += ["move ms", "broad ms", "narrow ms", "response ms", "render ms", "timed by"]
        keys = ["model", "n", "steps_per_s", "body_steps_per_s", "ns_per_body_step"]
        keys += ["events_per_s", "move_ms", "broad_ms", "narrow_ms", "response_ms", "render_ms"]
        keys += ["note"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    part = [r for r in rows if r["part"] == "peers"]
    if part:
        lines += ["## Peers", ""]
        header = ["peer", "N", "steps/s", "ns/body-step", "stepped / peer", "broad phase"]
        keys = ["model", "n", "steps_per_s", "ns_per_body_step", "ratio", "note"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    part = [r for r in rows if r["part"] == "error"]
    if part:
        lines += ["## Run time against error", ""]
        lines.append(
            "Against the exact model at the scenario's fps. missed: collisions of the reference "
            "(per pair) the run does not have; count error: pair events minus the reference's; "
            f"position error: mean distance to the reference {HORIZON_S} s after its first "
            "collision (the horizon, s); Pareto: no "
            "other row of the scenario is both faster and closer."
        )
        lines.append("")
        header = ["scenario", "model", "fps", "substeps", "run ms", "pairs", "missed"]
        header += ["count error", "energy drift", "max penetration px", "position error px"]
        header += ["horizon s", "Pareto"]
        lines += _table(
            header,
            [
                [r["scene"], r["model"], r["fps"], r["substeps"], 1e3 * r["run_time_s"]]
                + [r[k] for k in ("pairs", "missed", "count_error", "energy_drift")]
                + [r["max_penetration_px"], r["position_error_px"], r["horizon_s"], r["pareto"]]
                for r in part
            ],
        ) + [""]
    part = [r for r in rows if r["part"] == "skips"]
    if part:
        lines += ["## Skips: what a scene does not need", ""]
        header = ["skip", "scene", "with s", "without s", "saving"]
        keys = ["note", "scene", "with_s", "without_s", "saving"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    return "\n".join(lines) + "\n"


def _machine() -> str:
    import platform

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def plots(rows: list[dict], folder: Path) -> list[str]:
    """scaling.png and runtime_vs_error.png when matplotlib is installed; the names written."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib import ticker
    except ImportError:
        return []
    from collide2d.runner.outputs import atomic_path

    written = []
    scale = [r for r in rows if r["part"] in ("scaling", "peers")]
    if scale:
        fig, ax = plt.subplots(figsize=(6, 4))
        for name in dict.fromkeys(r["model"] for r in scale):
            pts = sorted((r["n"], r["steps_per_s"]) for r in scale if r["model"] == name)
            ax.plot(*zip(*pts, strict=True), marker="o", label=name)
        ax.set(xscale="log", yscale="log", xlabel="N boxes", ylabel="steps/s")
        ax.set_title("standard scene")
        ax.legend()
        fig.tight_layout()
        with atomic_path(folder / "scaling.png") as tmp:
            fig.savefig(tmp, format="png")
        plt.close(fig)
        written.append("scaling.png")
    err = [r for r in rows if r["part"] == "error"]
    if err:
        scenes = list(dict.fromkeys(r["scene"] for r in err))
        cols = 2
        rows_ = math.ceil(len(scenes) / cols)
        fig, axes = plt.subplots(rows_, cols, figsize=(10, 4 * rows_), squeeze=False)
        for ax, scene in zip(axes.ravel(), scenes, strict=False):
            mine = [r for r in err if r["scene"] == scene]
            for name in dict.fromkeys(r["model"] for r in mine):
                pts = [r for r in mine if r["model"] == name]
                ax.scatter(
                    [1e3 * r["run_time_s"] for r in pts],
                    [r["position_error_px"] + 1e-3 for r in pts],
                    label=name,
                )
            front = sorted(
                (1e3 * r["run_time_s"], r["position_error_px"] + 1e-3)
                for r in mine
                if r["pareto"] == "yes"
            )
            if front:
                ax.step(*zip(*front, strict=True), where="post", color="grey", linewidth=0.8)
            ax.set(xscale="log", yscale="log", xlabel="run time (ms)")
            for axis in (ax.xaxis, ax.yaxis):
                axis.set_major_formatter(ticker.FormatStrFormatter("%g"))
                axis.set_minor_formatter(ticker.NullFormatter())
            ax.set(ylabel="position error at the horizon (px, +0.001)", title=scene)
            ax.legend(fontsize="small")
        for ax in axes.ravel()[len(scenes) :]:
            ax.axis("off")
        fig.tight_layout()
        with atomic_path(folder / "runtime_vs_error.png") as tmp:
            fig.savefig(tmp, format="png")
        plt.close(fig)
        written.append("runtime_vs_error.png")
    return written


# ---------------------------------------------------------------------------- command


def cmd_bench(args: argparse.Namespace) -> int:
    from collide2d.runner import outputs

    parts = tuple(dict.fromkeys(args.part)) if args.part else DEFAULT_PARTS
    if args.peers and "peers" not in parts:
        parts += ("peers",)
    quick = args.quick
    ns = args.n or list(QUICK_N if quick else SCALING_N)
    models_ = args.model or list(models.MODEL_NAMES)
    in_process = args.in_process or quick
    if args.scenarios:
        _SCENARIOS[:] = [Path(args.scenarios)]
    missing = [n for n in NEEDED_SCENARIOS if not (scenarios_dir() / f"{n}.yaml").is_file()]
    if missing and set(parts) - {"scaling", "peers"}:
        print(
            f"collide2d bench: error: {scenarios_dir()} lacks {missing[0]}.yaml; point "
            "--scenarios at the project's scenarios/ folder",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    target = Path(args.out) / REPORT_DIR
    if target.is_symlink():
        print(f"collide2d bench: error: {target} is a symbolic link", file=sys.stderr)
        return EXIT_BAD_INPUT
    echo = Echo(args.quiet)
    began = time.perf_counter()
    rows: list[dict] = []
    if "scaling" in parts:
        rows += scaling(models_, ns, quick, in_process, echo)
    if "peers" in parts:
        if pymunk_available():
            ours = {
                r["n"]: r["steps_per_s"]
                for r in rows
                if r["part"] == "scaling" and r["model"] == "stepped"
            }
            missing = [n for n in ns if n not in ours]
            if missing:
                extra = scaling(["stepped"], missing, quick, in_process, echo)
                ours.update({r["n"]: r["steps_per_s"] for r in extra})
                rows += extra
            rows += peers(ns, ours, quick, echo)
        else:
            print(
                "collide2d bench: pymunk is not installed (pip install 'collide2d[bench]'); "
                "no peers",
                file=sys.stderr,
            )
    if "error" in parts:
        rows += error_ladder(BENCH_SCENARIOS, models_, quick, echo)
    if "skips" in parts:
        rows += skips(quick, echo)
    if "targets" in parts:
        rows += targets(quick, echo)
    seconds = time.perf_counter() - began
    target.mkdir(parents=True, exist_ok=True)
    args_line = "collide2d bench " + " ".join(sys.argv[2:]) if len(sys.argv) > 1 else "bench"
    outputs.atomic_write_text(target / "bench.csv", csv_text(rows))
    outputs.atomic_write_text(target / "bench.md", markdown(rows, args_line, seconds))
    written = ["bench.csv", "bench.md"] + plots(rows, target)
    if not args.quiet:
        for what, figure in headline(rows):
            print(f"{figure:>14}  {what}")
        print(f"bench: {len(rows)} rows in {seconds:.1f}s -> {target} ({', '.join(written)})")
    return EXIT_OK


def register(subparsers) -> None:
    """Add the `bench` subcommand to an argparse subparsers object."""
    p = subparsers.add_parser(
        "bench",
        help="run time against error; scaling; pymunk as a peer; what the skips save",
        description="Benchmark the models: the standard scene at several N (steps/s through "
        "`collide2d run`, events/s, time per stage), the benchmark scenarios at a ladder of fps "
        "and substeps against the exact model (run time against error, Pareto plot), what each "
        "skip saves, and the section IV targets; with --peers, pymunk on the same scene. Writes "
        "OUT/bench/bench.csv, bench.md and, with matplotlib, scaling.png and "
        "runtime_vs_error.png.",
    )
    p.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    p.add_argument("--quick", action="store_true", help="small and short everything (seconds)")
    p.add_argument("--peers", action="store_true", help="also time pymunk (the `bench` extra)")
    p.add_argument(
        "--part",
        action="append",
        choices=PARTS,
        help="run only this part (repeat; default: all but peers)",
    )
    p.add_argument(
        "--n", action="append", type=_positive, metavar="N", help="scaling at this N (repeat)"
    )
    p.add_argument(
        "--model", action="append", choices=models.MODEL_NAMES, help="only this model (repeat)"
    )
    p.add_argument(
        "--in-process",
        action="store_true",
        help="time runs through runner.run.drive in this process instead of `collide2d run`",
    )
    p.add_argument(
        "--scenarios",
        metavar="DIR",
        help="folder of the benchmark scenarios (default: the project's scenarios/)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress, no summary")
    p.set_defaults(func=cmd_bench)


def _positive(text: str) -> int:
    from collide2d.runner.options import positive_int

    return positive_int(text)
