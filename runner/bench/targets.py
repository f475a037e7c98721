"""The targets part of `collide2d bench`: the paper's section IV demo headless (ticks/s through the
model's `advance`), and the wall time of `collide2d run` on a small scenario as a user runs it
(interpreted: runner.lanes) and with its kernels compiled and cached.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from collide2d.engine import models
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
