"""Steps per second of each model on the standard scene, in process (issue: fast at every scale).

The standard scene of `collide2d bench` (runner.bench.scenes.standard_scene: N boxes 10x10 px covering
5 % of a 4:3 world, speeds 10-100 px/s in random directions, 60 fps, seed 1), stepped through the
model's `advance` with the event log off, after a warm-up call so that loading the kernels is not
timed; the median of REPEATS runs, each about TARGET_S seconds long. It prints steps/s and the
cost per body-step, and the ratio of that cost at the largest N to the one at N = 1,000 (the issue
asks for at most 2 for the stepped model). Faster to iterate on than `collide2d bench`, which
times the same scene through `collide2d run` in a subprocess and adds pymunk, the error ladder
and the skips.

Run: `python benchmarks/bench_scaling.py [--model M] [--n N ...]`.
"""

from __future__ import annotations

import argparse
import statistics
import time

from collide2d.engine import models
from collide2d.runner.bench.scaling import SCALING_N
from collide2d.runner.bench.scenes import standard_scene
from collide2d.runner.scenario import loads

REPEATS = 3
TARGET_S = 1.0


def steps_per_second(model: str, n: int) -> float:
    scenario = loads(standard_scene(n, model))
    world, bodies = scenario.world, scenario.bodies
    m = models.make(model, world, bodies)
    ticks = 1
    while True:  # warm-up and rate estimate
        began = time.perf_counter()
        m.advance(ticks, log=False)
        spent = time.perf_counter() - began
        if spent > TARGET_S / 10:
            break
        ticks *= 2
    ticks = max(2, int(ticks * TARGET_S / spent))
    rates = []
    for _ in range(REPEATS):
        m = models.make(model, world, bodies)
        began = time.perf_counter()
        m.advance(ticks, log=False)
        rates.append(ticks / (time.perf_counter() - began))
    return statistics.median(rates)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", action="append", choices=models.MODEL_NAMES)
    parser.add_argument("--n", action="append", type=int)
    args = parser.parse_args()
    ns = args.n or list(SCALING_N)
    for model in args.model or ["stepped", "paper", "exact"]:
        cost = {}
        for n in ns:
            rate = steps_per_second(model, n)
            cost[n] = 1e9 / (rate * n)
            print(f"{model:7s} N={n:<7,d} {rate:12,.1f} steps/s  {cost[n]:7.1f} ns/body-step")
        if 1_000 in cost and max(cost) > 1_000:
            big = max(cost)
            print(
                f"{model:7s} cost per body-step N={big:,} / N=1,000: {cost[big] / cost[1_000]:.2f}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
