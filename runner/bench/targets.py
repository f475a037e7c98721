"""The targets part of `collide2d bench`: the paper's section IV demo headless (ticks/s through the
model's `advance`), and the wall time of `collide2d run` on a small scenario as a user runs it
(interpreted: runner.lanes) and with its kernels compiled and cached.

Also the jit part (`cold_start`, then `compile_budgets`: each model's compile seconds against its
budget): `collide2d run` under `--jit on`, `off` and `auto`, each in a
fresh process (`python -m collide2d run FILE --jit MODE --quiet`, the scenario's own outputs)
with its own empty NUMBA_CACHE_DIR, as a CI job starts, Python's bytecode cached as an
installation has it (`user_env`), wall time. The scenes: GRID, scenes of 10 to 5,000 bodies over
10 to 100,000 ticks, the bench's standard scene (STANDARD: N boxes under each model) and two-body
chain, and every scenario of the scenarios folder. `auto` runs whole; `off` is stopped past
OFF_PAST_AUTO times `auto`'s time, and `on` once it has taken longer than both (it can no longer
be the faster lane): the row then says "> s", a time shorter than the lane's, so the ratio of
`auto` to the faster is at most the one shown. Each row: the three wall times, the lane `auto`
took (the summary's `kernels`) and `auto` over the faster of `on` and `off`, against AUTO_WITHIN.
`--quick` runs QUICK_SCENES only.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from collide2d.engine import models
from collide2d.runner.bench import scenes
from collide2d.runner.bench.paper import demo_row
from collide2d.runner.bench.scenes import DEMO_SCENARIO, PROJECT_SCENARIOS, SMALL_SCENARIO
from collide2d.runner.bench.timing import measure

DEMO_TICKS = 1_000_000
QUICK_DEMO_TICKS = 20_000


def targets(quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """The section IV demo headless, and `collide2d run` of a small scenario, wall time; the
    scenario files are read from `folder`."""
    from collide2d.runner.scenario.load import load

    ticks = QUICK_DEMO_TICKS if quick else DEMO_TICKS
    demo = load(folder / f"{DEMO_SCENARIO}.yaml")
    models.make("paper", demo.world, demo.bodies).advance(2, log=False)

    def headless():
        models.make("paper", demo.world, demo.bodies).advance(ticks, log=False)

    (timing,) = measure([headless], quick)
    rate = ticks / timing.median
    note = "section IV demo headless, ticks/s"
    row = demo_row("targets", demo, ticks, rate, note)
    row.update(timing.row())
    row.update(target=">= 1,000,000", met=rate >= 1_000_000)
    rows = [row]
    echo(f"targets  section IV demo headless {rate:14,.0f} ticks/s (spread {timing.spread:.0%})")
    if not quick:
        rows += small_runs(folder / f"{SMALL_SCENARIO}.yaml", echo)
    return rows


def user_env(pycache: str) -> dict:
    """This process's environment as an installed collide2d runs in it: Python's bytecode cached
    (pip compiles it on install; an environment saying PYTHONDONTWRITEBYTECODE would have every
    run compile collide2d's sources again, ~0.1 s), in `pycache` (nothing written beside the
    sources)."""
    env = dict(os.environ, PYTHONPYCACHEPREFIX=pycache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def small_runs(path: Path, echo) -> list[dict]:
    """`collide2d run` of a small scenario, wall s, as a user runs it (`--jit auto`: interpreted,
    runner.lanes) and with its kernels compiled and cached (`--jit on`), interleaved; bytecode
    cached as an installation has it (`user_env`)."""
    import subprocess
    import tempfile

    rows = []
    with tempfile.TemporaryDirectory(prefix="collide2d-bench-") as tmp:
        out = os.path.join(tmp, "out")
        cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--quiet", "--out", out]
        runs = [cmd + ["--jit", mode] for mode in ("auto", "on")]
        env = user_env(os.path.join(tmp, "pycache"))
        quiet = subprocess.DEVNULL
        for run in runs:
            subprocess.run(run, check=True, stdout=quiet, env=env)  # kernels, bytecode cached
        calls = [lambda r=run: subprocess.run(r, check=True, stdout=quiet, env=env) for run in runs]
        timings = measure(calls)
    for mode, timing, target in zip(("auto", "on"), timings, (0.35, None), strict=True):
        wall = timing.median
        row = {
            "part": "targets",
            "scene": SMALL_SCENARIO,
            "model": "paper",
            "value": wall,
            "note": f"collide2d run --jit {mode} of a small scenario (all outputs), wall s",
            "target": f"<= {target}" if target else "",
            "met": wall <= target if target else None,
        }
        row.update(timing.row())
        rows.append(row)
        echo(f"targets  collide2d run --jit {mode} {SMALL_SCENARIO} {wall:.3f} s")
    return rows


# `auto`'s wall time at most this many times the faster of `on` and `off`, on every scene.
AUTO_WITHIN = 1.2
# `off` is stopped past this many times `auto`'s time (and 2 s): `auto` compiled, and so can
# `on`, whose time then shows whether it should have.
OFF_PAST_AUTO = 3
MODES = ("on", "auto", "off")
# The standard scene: (N, model, ticks).
STANDARD = ((1_000, "paper", 120), (1_000, "stepped", 120), (1_000, "exact", 120))
CHAIN_TICKS = 20
# (bodies, ticks, model) of the grid: a generated gas (the standard scene's boxes and density).
GRID = (
    (10, 10, "paper"),
    (10, 100_000, "paper"),
    (100, 10_000, "exact"),
    (500, 1_000, "stepped"),
    (1_000, 1_000, "paper"),
    (5_000, 10, "exact"),
    (5_000, 1_000, "paper"),
)
QUICK_SCENES = ("tunnelling_1fps", "grid-10x10-paper")  # --quick: seconds, for tests


def scene_files(folder: Path, tmp: Path, quick: bool) -> list[tuple[str, Path, int, int]]:
    """(name, file, bodies, ticks) of each scene, the built ones written into `tmp`."""
    from collide2d.runner import lanes
    from collide2d.runner.scenario.load import load

    found = []
    built = [(f"grid-{n}x{t}-{m}", n, t, m) for n, t, m in GRID]
    built += [(f"standard-{n}-{m}", n, t, m) for n, m, t in STANDARD]
    for name, n, ticks, model in built:
        text = scenes.standard_scene(n, model, ticks)
        path = tmp / f"{name}.yaml"
        path.write_text(text.replace(f"name: standard-{n}\n", f"name: {name}\n"))
        found.append((name, path, n, ticks))
    path = tmp / "two-body-chain.yaml"
    path.write_text(scenes.chain_scene(CHAIN_TICKS))
    found.append(("two-body-chain", path, 2, CHAIN_TICKS))
    previous = lanes.mode()
    lanes.set_mode("off")  # read here only for their sizes: no kernel compiled for that
    try:
        for path in sorted(folder.glob("*.yaml")):
            scenario = load(path)
            found.append((path.stem, path, scenario.bodies.n, scenario.ticks))
    finally:
        lanes.set_mode(previous)
    if quick:
        found = [f for f in found if f[0] in QUICK_SCENES]
    return found


def run_cold(path: Path, mode: str, tmp: Path, limit: float | None = None) -> tuple[float, str]:
    """(wall s, the summary's `kernels`) of `collide2d run PATH --jit MODE` from an empty kernel
    cache; (limit, "stopped") when it passes `limit` seconds."""
    wall, summary = _cold(path, mode, tmp, limit)
    return (wall, "stopped") if summary is None else (wall, summary.get("kernels", ""))


def _cold(path: Path, mode: str, tmp: Path, limit: float | None = None):
    """(wall s, the run's summary.json) of `collide2d run PATH --jit MODE` from an empty kernel
    cache; (limit, None) when it passes `limit` seconds."""
    with tempfile.TemporaryDirectory(prefix="cache-", dir=tmp) as cache:
        env = user_env(str(tmp / "pycache"))
        env["NUMBA_CACHE_DIR"] = cache
        env.pop("COLLIDE2D_JIT", None)
        env.pop("NUMBA_DISABLE_JIT", None)
        out = tmp / f"out-{mode}"
        cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--quiet", "--out", str(out)]
        cmd += ["--jit", mode]
        began = time.perf_counter()
        try:
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env, timeout=limit)
        except subprocess.TimeoutExpired:
            return float(limit), None
        wall = time.perf_counter() - began
    summaries = sorted(out.glob("*/summary.json"), key=os.path.getmtime)
    return wall, json.loads(summaries[-1].read_text()) if summaries else {}


def compile_budgets(quick: bool, echo, tmp: Path) -> list[dict]:
    """One row per built-in model: the seconds `collide2d run --jit on` of its standard scene
    (STANDARD) spends compiling from an empty kernel cache (the summary's `compile_time_s`),
    against goals.COMPILE_BUDGET_S, or against 0 when the kernels the wheel ships hold the
    model's (engine.kernelstore): loading them is no compiling. `--quick` leaves out a model the
    store lacks (a checkout before `python -m collide2d.runner.prebuild`: a minute a model)."""
    from collide2d.engine import kernelstore
    from collide2d.runner.bench import goals

    rows = []
    for n, model, ticks in STANDARD:
        stored = kernelstore.holds_model(model)
        if quick and not stored:
            continue
        path = tmp / f"compile-{model}.yaml"
        path.write_text(scenes.standard_scene(n, model, ticks))
        _wall, summary = _cold(path, "on", tmp)
        seconds = float((summary or {}).get("compile_time_s", 0.0))
        budget = 0.0 if stored else goals.COMPILE_BUDGET_S[model]
        whence = "the wheel's kernels" if stored else "nothing precompiled"
        rows.append({
            "part": "compile",
            "scene": f"standard-{n}",
            "model": model,
            "n": n,
            "value": seconds,
            "note": f"{model} model compiling, standard scene, empty cache ({whence}), s",
            "target": f"<= {budget:g}",
            "met": seconds <= budget,
        })  # fmt: skip
        echo(f"jit      {model} model compiling from an empty cache ({whence}) {seconds:6.1f} s "
             f"(budget {budget:g} s)")  # fmt: skip
    return rows


def bytecode(tmp: Path, small: Path) -> None:
    """Python's bytecode written into `tmp`/pycache (`user_env`) as an installation has it (pip
    writes it on install): of every module of the engine and the runner, and of the public API and
    the libraries a run imports in either lane (a run of `small` interpreted, then compiled); a
    first run, or a first compiled one, would otherwise pay it (0.4 to 0.7 s)."""
    import collide2d.engine

    # the runner's folder holds this module; the `collide2d` package's own modules are written by
    # the runs below, which import them
    engine = Path(collide2d.engine.__file__).parent
    folders = [str(engine), str(Path(__file__).resolve().parents[1])]
    subprocess.run([sys.executable, "-m", "compileall", "-q", *folders], check=True,
                   stdout=subprocess.DEVNULL, env=user_env(str(tmp / "pycache")))  # fmt: skip
    for mode in ("off", "on"):
        run_cold(small, mode, tmp)


def cold_start(quick: bool, echo, folder: Path = scenes.PROJECT_SCENARIOS) -> list[dict]:
    """One row per scene: wall s of each lane from an empty cache, and auto / the faster."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="collide2d-jit-") as name:
        tmp = Path(name)
        bytecode(tmp, folder / f"{scenes.SMALL_SCENARIO}.yaml")
        for scene, path, n, ticks in scene_files(folder, tmp, quick):
            auto, auto_lane = run_cold(path, "auto", tmp)
            off, off_lane = run_cold(path, "off", tmp, limit=OFF_PAST_AUTO * auto + 2.0)
            on, on_lane = run_cold(path, "on", tmp, limit=max(auto, off) + 1.0)
            stopped = {"on": on_lane == "stopped", "off": off_lane == "stopped"}
            # a stopped lane's time is less than its own: the ratio is at most this
            ratio = auto / min(on, off)
            rows.append({
                "part": "jit",
                "scene": scene,
                "n": n,
                "ticks": ticks,
                "on_s": on,
                "on_stopped": stopped["on"],
                "off_s": off,
                "off_stopped": stopped["off"],
                "auto_s": auto,
                "ratio": ratio,
                "note": auto_lane,
                "target": f"<= {AUTO_WITHIN:g}",
                "met": ratio <= AUTO_WITHIN,
            })  # fmt: skip
            shown = {k: f"> {v:.1f}" if stopped[k] else f"{v:.1f}" for k, v in
                     (("on", on), ("off", off))}  # fmt: skip
            echo(f"jit      {scene:32s} on {shown['on']:>7} s  off {shown['off']:>7} s  auto "
                 f"{auto:6.1f} s ({auto_lane})  auto/faster {ratio:.2f}")  # fmt: skip
        rows += compile_budgets(quick, echo, tmp)
    return rows
