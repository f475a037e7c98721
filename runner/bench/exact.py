"""The exact part of `collide2d bench`: events per second of the exact model, event log on.

Two scenes (`scenes.chain_scene`, `scenes.standard_scene`): a two-body chain, two boxes bouncing
between each other and the walls at 1e5 px/s (many events per tick, a tiny heap: the cost of one
event; the issue's target is 1,000,000 events/s), and the standard scene at EXACT_GAS_N boxes (the
cost of an event among many neighbours; target 200,000 events/s). Events are the logged wall and
pair events (cell crossings are bookkeeping and not counted). Each is timed through the model's
`advance` after a warm-up call; the median of EXACT_REPEATS runs. Not a default part
(`--part exact`).

Under gravity (`gravity`, rows of the gravity part, `--part gravity`): a gas of n boxes (8 px on a
jittered grid of a 2,000 px square world, speeds up to 60 px/s, masses 0.2 to 5, seeded; elastic
walls and pairs) run for the same ticks at 60 fps without gravity and with 400 px/s² (the gas
falls and keeps bouncing), in turns (A B B A), each run after one tick that loads the kernels and
makes the first predictions: the median events per second of each and their ratio
(docs/models.md#exact-under-gravity: at least 0.5). Then 1,000 balls of restitution 0.9 at rest
in the world's upper half fall onto the floor under 980 px/s² and bounce on it and off each other
(5 s; they would come to rest after some 30 s): their events per second.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from collide2d.engine import models
from collide2d.engine.models import make
from collide2d.engine.world import KIND_CIRCLE, Bodies, WorldSpec
from collide2d.runner.bench import goals
from collide2d.runner.bench.peers import row
from collide2d.runner.bench.scenes import chain_scene, standard_scene
from collide2d.runner.bench.timing import median

EXACT_REPEATS = 5
CHAIN_TICKS = 1000  # 100 s at 10 fps: about 160,000 events
QUICK_CHAIN_TICKS = 50
EXACT_GAS_N = 10_000
QUICK_EXACT_GAS_N = 400
GAS_TICKS = 600  # 10 s at 60 fps
QUICK_GAS_TICKS = 30


def events_per_second(text: str, ticks: int, repeats: int) -> tuple[float, int, int]:
    """(median events/s, events per run, objects) of the exact model over `ticks` ticks of the
    scenario text; building the model is not timed."""
    from collide2d.runner.scenario.load import loads

    scenario = loads(text)
    world, bodies = scenario.world, scenario.bodies
    models.make("exact", world, bodies).advance(2, log=True)  # load the kernels
    rates, count = [], 0
    for _ in range(repeats):
        model = models.make("exact", world, bodies)
        began = time.perf_counter()
        count = len(model.advance(ticks, log=True))
        rates.append(count / max(time.perf_counter() - began, 1e-12))
    return median(rates), count, bodies.n


def exact(quick: bool, echo) -> list[dict]:
    """One row per scene: events/s of the exact model."""
    repeats = 1 if quick else EXACT_REPEATS
    n = QUICK_EXACT_GAS_N if quick else EXACT_GAS_N
    scenes = [
        ("two-body chain", chain_scene(), QUICK_CHAIN_TICKS if quick else CHAIN_TICKS),
        (f"standard-{n}", standard_scene(n, "exact"), QUICK_GAS_TICKS if quick else GAS_TICKS),
    ]
    rows = []
    for name, text, ticks in scenes:
        target = goals.EXACT_EVENTS_PER_S.get(name)
        rate, count, bodies = events_per_second(text, ticks, repeats)
        rows.append(
            {
                "part": "exact",
                "scene": name,
                "model": "exact",
                "n": bodies,
                "ticks": ticks,
                "events_per_s": rate,
                "value": rate,
                "note": f"events/s, {count:,} events a run"
                + (f" (target >= {target:,})" if target else ""),
            }
        )
        echo(f"exact    {name:24s} {rate:14,.0f} events/s ({count:,} events)")
    return rows


# --- under gravity ---------------------------------------------------------------------------

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

