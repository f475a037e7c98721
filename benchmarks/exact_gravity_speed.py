"""The exact model's events per second under gravity against the same scene without it.

Builds a gas of N boxes (default 10,000: 8 px boxes on a jittered grid, speeds up to 60 px/s,
masses 0.2 to 5, seeded) in a world of 2,000 x 2,000 px and runs it with the exact model,
compiled, for the same ticks with gravity 0 and with gravity 400 px/s² (elastic walls and pairs:
the gas falls and keeps bouncing), in turns (A B B A ...), each after a warm-up run that compiles
and loads the kernels; then a scene of 1,000 balls of restitution 0.9 dropped onto the floor,
which bounce, come to rest and slide. Prints the median events per second of each, and the ratio
under gravity / without. Usage:

    python benchmarks/exact_gravity_speed.py [--n 10000] [--ticks 600] [--rounds 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from collide2d.engine.models import make
from collide2d.engine.world import KIND_CIRCLE, Bodies, Looks, WorldSpec

SIDE = 2000
SIZE = 8.0


def gas(n: int, seed: int = 1) -> Bodies:
    """n boxes on a jittered grid of the world, random velocities and masses."""
    rng = np.random.default_rng(seed)
    k = int(np.ceil(np.sqrt(n)))
    pitch = SIDE / k
    idx = np.arange(n)
    pos = np.stack([idx % k, idx // k], axis=1) * pitch + rng.uniform(0, pitch - SIZE, (n, 2))
    vel = rng.uniform(-60, 60, (n, 2))
    return Bodies.boxes(pos, SIZE, vel, mass=rng.uniform(0.2, 5.0, n))


def balls(n: int, seed: int = 2) -> Bodies:
    """n balls of restitution 0.9 on a jittered grid of the world's upper half, at rest."""
    rng = np.random.default_rng(seed)
    k = int(np.ceil(np.sqrt(2 * n)))
    pitch = SIDE / k
    idx = np.arange(n)
    pos = np.stack([idx % k, idx // k], axis=1) * pitch + rng.uniform(0, pitch - SIZE, (n, 2))
    return Bodies(
        kind=np.full(n, KIND_CIRCLE, np.int8),
        pos=pos,
        size=np.full((n, 2), SIZE),
        vel=np.zeros((n, 2)),
        mass=np.ones(n),
        static=np.zeros(n, bool),
        vert_start=np.zeros(n + 1, np.int64),
        verts=np.zeros((0, 2), np.int64),
        looks=Looks(color=np.ones(n, np.uint8), fill=np.zeros(n, bool)),
        restitution=np.full(n, 0.9),
    )


def events_per_s(bodies: Bodies, gravity: float, ticks: int) -> tuple[float, int, float]:
    """(events per second, events, seconds) of one run of `ticks` ticks at 60 fps."""
    model = make("exact", WorldSpec(SIDE, SIDE, 60, gravity=(0.0, gravity)), bodies)
    model.advance(1, log=False)  # the first predictions, and the kernels loaded
    start = time.perf_counter()
    model.advance(ticks, log=False)
    seconds = time.perf_counter() - start
    walls, pairs = model.event_counts()
    return (walls + pairs) / seconds, walls + pairs, seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--ticks", type=int, default=600)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    bodies = gas(args.n)
    events_per_s(gas(100), 400.0, 2)  # compile both paths once
    rates: dict[float, list[float]] = {0.0: [], 400.0: []}
    for r in range(args.rounds):
        order = (0.0, 400.0) if r % 2 == 0 else (400.0, 0.0)
        for g in order:
            rate, events, seconds = events_per_s(bodies, g, args.ticks)
            rates[g].append(rate)
            print(f"round {r + 1}, gravity {g:g}: {events:,} events in {seconds:.3f} s")
    flat, falling = statistics.median(rates[0.0]), statistics.median(rates[400.0])
    print(f"{args.n:,} boxes, {args.ticks} ticks, medians of {args.rounds} rounds:")
    print(f"  without gravity  {flat:,.0f} events/s")
    print(f"  gravity 400      {falling:,.0f} events/s   ratio {falling / flat:.3f}")
    rate, events, seconds = events_per_s(balls(1000), 980.0, 300)
    print(f"1,000 balls, e 0.9, dropped: {events:,} events in {seconds:.3f} s ({rate:,.0f}/s)")


if __name__ == "__main__":
    main()
