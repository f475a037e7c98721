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
from collide2d.runner.bench.timing import measure

DEMO_TICKS = 1_000_000
QUICK_DEMO_TICKS = 20_000


def targets(quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """The section IV demo headless, and `collide2d run` of a small scenario, wall time; the
    scenario files are read from `folder`."""
    import subprocess
    import tempfile

    from collide2d.runner.scenario import load

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
        path = folder / f"{SMALL_SCENARIO}.yaml"
        with tempfile.TemporaryDirectory(prefix="collide2d-bench-") as tmp:
            cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--quiet", "--out", tmp]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)  # kernels cached
            (timing,) = measure(
                [lambda: subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)], quick
            )
        wall = timing.median
        row = {
            "part": "targets",
            "scene": SMALL_SCENARIO,
            "model": "paper",
            "value": wall,
            "note": "collide2d run of a small scenario (all outputs), wall s",
            "target": "< 1",
            "met": wall < 1,
        }
        row.update(timing.row())
        rows.append(row)
        echo(f"targets  collide2d run {SMALL_SCENARIO} {wall:.3f} s")
    return rows
