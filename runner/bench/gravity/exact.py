"""The exact model under gravity, in the gravity part (runner/bench/gravity): its events per second
with gravity against without, and a drop of bouncing balls.

A gas of n boxes (8 px on a jittered grid of a 2,000 px square world, speeds up to 60 px/s, masses
0.2 to 5, seeded; elastic walls and pairs) run for the same ticks at 60 fps without gravity and with
400 px/s² (the gas falls and keeps bouncing), in turns (A B B A), each run after one tick that loads
the kernels and makes the first predictions: the median events per second of each and their ratio
(docs/models.md#exact-under-gravity: at least 0.5). Then 1,000 balls of restitution 0.9 at rest in
the world's upper half fall onto the floor under 980 px/s² and bounce on it and off each other (5
s; they would come to rest after some 30 s): their events per second.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from collide2d.engine.models import make
from collide2d.engine.world import KIND_CIRCLE, Bodies, WorldSpec
from collide2d.runner.bench import goals
from collide2d.runner.bench.gravity.pile import row

SIDE = 2000  # px, the world's side
SIZE = 8.0  # px, each box's or ball's side
GAS_G = 400.0  # px/s², the falling gas's gravity
BALLS_G, BALLS_E = 980.0, 0.9
# (n, ticks) of the gas, and the balls' ticks, in a full run and a quick one
GAS = {False: (10_000, 600), True: (1_000, 300)}
BALLS = {False: (1_000, 300), True: (1_000, 120)}
ROUNDS = {False: 3, True: 1}


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
    """n balls of restitution BALLS_E on a jittered grid of the world's upper half, at rest."""
    rng = np.random.default_rng(seed)
    k = int(np.ceil(np.sqrt(2 * n)))
    pitch = SIDE / k
    idx = np.arange(n)
    pos = np.stack([idx % k, idx // k], axis=1) * pitch + rng.uniform(0, pitch - SIZE, (n, 2))
    boxes = Bodies.boxes(pos, SIZE, [0.0, 0.0])
    kind, restitution = np.full(n, KIND_CIRCLE, np.int8), np.full(n, BALLS_E)
    return Bodies(**{**boxes.__dict__, "kind": kind, "restitution": restitution})


def gravity_rate(bodies: Bodies, gravity: float, ticks: int) -> tuple[float, int, float]:
    """(events per second, events, seconds) of the exact model running `ticks` ticks at 60 fps,
    timed after its first tick."""
    model = make("exact", WorldSpec(SIDE, SIDE, 60, gravity=(0.0, gravity)), bodies)
    model.advance(1, log=False)
    start = time.perf_counter()
    model.advance(ticks, log=False)
    seconds = time.perf_counter() - start
    walls, pairs = model.event_counts()
    return (walls + pairs) / seconds, walls + pairs, seconds


def gas_rates(n: int, ticks: int, rounds: int) -> tuple[float, float]:
    """Median events per second of the gas without gravity and with GAS_G, run in turns."""
    bodies = gas(n)
    rates: dict[float, list[float]] = {0.0: [], GAS_G: []}
    for r in range(rounds):
        for g in (0.0, GAS_G) if r % 2 == 0 else (GAS_G, 0.0):
            rates[g].append(gravity_rate(bodies, g, ticks)[0])
    return statistics.median(rates[0.0]), statistics.median(rates[GAS_G])


def gravity(quick: bool, echo) -> list[dict]:
    """The gravity part's rows for the exact model: the gas with and without gravity, their ratio,
    and the falling balls."""
    gravity_rate(gas(100), GAS_G, 2)  # compiled (or loaded) before any clock starts
    n, ticks = GAS[quick]
    target = goals.EXACT_GRAVITY_RATIO
    flat, falling = gas_rates(n, ticks, ROUNDS[quick])
    scene = f"gas-{n}"
    out = [
        row(scene, "exact", n, flat, f"events/s without gravity, {ticks} ticks"),
        row(scene, "exact", n, falling, f"events/s under gravity {GAS_G:g} px/s², {ticks} ticks"),
        row(scene, "exact", n, falling / flat, f"under gravity / without (target >= {target})"),
    ]
    echo(
        f"gravity  exact    n={n:<6d} gas {flat:,.0f} events/s, falling {falling:,.0f} "
        f"({falling / flat:.2f}x)"
    )
    k, ticks = BALLS[quick]
    rate, events, _ = gravity_rate(balls(k), BALLS_G, ticks)
    note = f"events/s, e {BALLS_E} dropped, {ticks} ticks"
    out.append(row(f"balls-{k}", "exact", k, rate, note))
    echo(f"gravity  exact    n={k:<6d} balls e {BALLS_E}: {events:,} events, {rate:,.0f}/s")
    return out
