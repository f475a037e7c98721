"""Benchmark of the exact model: events per second (issue: accurate models).

Two scenes, built in code and seeded:
  - a two-body chain: two boxes of masses 1 and 3 bouncing between each other and the walls of a
    320 x 240 world at 1e5 px/s (many events per tick, a tiny heap): the cost of one event;
  - a gas of 10,000 boxes (10 x 10 px) covering 5 % of a square world, speeds 10-100 px/s in
    random directions, at 10 fps: the cost of an event among many neighbours.
Each is timed through the model's `advance` with the event log on, after a warm-up call so that
compilation is excluded; the median of REPEATS runs is printed, with the targets of the issue
(>= 1,000,000 and >= 200,000 events per second). Events are the logged wall and pair events (cell
crossings are bookkeeping and not counted). Run: `python benchmarks/bench_exact.py`.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np

from collide2d.engine import models
from collide2d.engine.world import Bodies, WorldSpec

REPEATS = 5
CHAIN_TICKS = 1000  # 100 s at 10 fps: about 160,000 events
GAS_COUNT = 10_000
GAS_SIZE = 10.0  # px
GAS_COVERAGE = 0.05  # share of the world's area covered by boxes
GAS_SPEEDS = (10.0, 100.0)  # px/s
GAS_TICKS = 100  # 10 s at 10 fps: about 55,000 events
SEED = 1


def two_body_chain() -> tuple[WorldSpec, Bodies]:
    world = WorldSpec(320, 240, 10)
    bodies = Bodies.boxes([[50, 115], [200, 115]], 10, [[1e5, 0], [-1.5e5, 0]], mass=[1.0, 3.0])
    return world, bodies


def gas() -> tuple[WorldSpec, Bodies]:
    rng = np.random.default_rng(SEED)
    side = math.ceil(math.sqrt(GAS_COUNT * GAS_SIZE**2 / GAS_COVERAGE))
    k = math.ceil(math.sqrt(GAS_COUNT))
    pitch = side / k
    idx = np.arange(GAS_COUNT)
    cells = np.stack([idx % k, idx // k], axis=1)
    pos = cells * pitch + rng.uniform(0, pitch - GAS_SIZE, (GAS_COUNT, 2))
    speed = rng.uniform(*GAS_SPEEDS, GAS_COUNT)
    angle = rng.uniform(0, 2 * math.pi, GAS_COUNT)
    vel = np.stack([speed * np.cos(angle), speed * np.sin(angle)], axis=1)
    return WorldSpec(side, side, 10), Bodies.boxes(pos, GAS_SIZE, vel)


def events_per_second(world: WorldSpec, bodies: Bodies, ticks: int) -> tuple[float, int]:
    """(median events/s over REPEATS runs, events per run); model setup is not timed."""
    models.make("exact", world, bodies).advance(2)  # warm-up: compile or load the kernels
    rates, count = [], 0
    for _ in range(REPEATS):
        model = models.make("exact", world, bodies)
        began = time.perf_counter()
        count = len(model.advance(ticks, log=True))
        rates.append(count / (time.perf_counter() - began))
    return statistics.median(rates), count


def main() -> int:
    chain, chain_events = events_per_second(*two_body_chain(), CHAIN_TICKS)
    world, bodies = gas()
    gas_rate, gas_events = events_per_second(world, bodies, GAS_TICKS)
    print(f"exact model, events per second (median of {REPEATS}, event log on)")
    print(f"  two-body chain      : {chain:12,.0f} /s  ({chain_events:,} events)  target 1,000,000")
    print(
        f"  gas of {GAS_COUNT:,} boxes : {gas_rate:12,.0f} /s  ({gas_events:,} events, "
        f"{world.width} x {world.height} px)  target 200,000"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
