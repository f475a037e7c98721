"""Benchmark of the paper model on the paper's section IV scene (issue: reproduce the paper).

Measures, after a warm-up call so compilation is excluded:
  - headless ticks per second (no frames, no event log), through the model's `advance`;
  - the same with the event log on;
  - ticks per second through `runner.run.drive` with no frames asked for (what `collide2d run
    --no-gif --no-events` does after loading).
Prints the median of REPEATS runs of each. Run: `python benchmarks/bench_paper.py`.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

from collide2d.engine import models
from collide2d.runner.run import drive
from collide2d.runner.scenario import load

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "scenarios" / "paper_fifty_boxes.yaml"
TICKS = 1_000_000
REPEATS = 5


def ticks_per_second(make_and_run) -> float:
    times = []
    for _ in range(REPEATS):
        began = time.perf_counter()
        make_and_run()
        times.append(time.perf_counter() - began)
    return TICKS / statistics.median(times)


def main() -> int:
    scn = load(SCENARIO, overrides={"ticks": TICKS})

    def headless(log: bool):
        def go():
            model = models.make("paper", scn.world, scn.bodies)
            model.advance(TICKS, log)

        return go

    headless(False)()  # warm-up: compile or load the cached kernels
    quiet = ticks_per_second(headless(False))
    logged = ticks_per_second(headless(True))
    driven = ticks_per_second(lambda: drive(scn))
    print(
        f"paper model, section IV scene ({scn.bodies.n} boxes, {TICKS:,} ticks, "
        f"median of {REPEATS})"
    )
    print(f"  headless, no log : {quiet:12,.0f} ticks/s  (target >= 1,000,000)")
    print(f"  headless, logged : {logged:12,.0f} ticks/s")
    print(f"  through drive()  : {driven:12,.0f} ticks/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
