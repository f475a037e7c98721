"""The targets part of `collide2d bench`: the paper's section IV demo headless (ticks/s through the
model's `advance`), and the wall time of `collide2d run` on a small scenario once kernels are
cached.
"""

from __future__ import annotations

import sys
from pathlib import Path

from collide2d.engine import models
from collide2d.runner.bench.paper import demo_row
from collide2d.runner.bench.scenes import DEMO_SCENARIO, PROJECT_SCENARIOS, SMALL_SCENARIO
from collide2d.runner.bench.timing import median, timed

DEMO_TICKS = 1_000_000
QUICK_DEMO_TICKS = 20_000


def targets(quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """The section IV demo headless, and `collide2d run` of a small scenario, wall time; the
    scenario files are read from `folder`."""
    import subprocess
    import tempfile

    from collide2d.runner.scenario import load

    repeats = 1 if quick else 5
    ticks = QUICK_DEMO_TICKS if quick else DEMO_TICKS
    demo = load(folder / f"{DEMO_SCENARIO}.yaml")
    models.make("paper", demo.world, demo.bodies).advance(2, log=False)

    def headless():
        models.make("paper", demo.world, demo.bodies).advance(ticks, log=False)

    rate = ticks / median(timed(headless) for _ in range(repeats))
    note = "section IV demo headless, ticks/s (target >= 1,000,000)"
    rows = [demo_row("targets", demo, ticks, rate, note)]
    echo(f"targets  section IV demo headless {rate:14,.0f} ticks/s")
    if not quick:
        path = folder / f"{SMALL_SCENARIO}.yaml"
        with tempfile.TemporaryDirectory(prefix="collide2d-bench-") as tmp:
            cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--quiet", "--out", tmp]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)  # kernels cached
            wall = median(
                timed(lambda: subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL))
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
