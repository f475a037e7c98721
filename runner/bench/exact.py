"""The exact part of `collide2d bench`: events per second of the exact model, event log on.

Two scenes (`scenes.chain_scene`, `scenes.standard_scene`): a two-body chain, two boxes bouncing
between each other and the walls at 1e5 px/s (many events per tick, a tiny heap: the cost of one
event; the issue's target is 1,000,000 events/s), and the standard scene at EXACT_GAS_N boxes (the
cost of an event among many neighbours; target 200,000 events/s). Events are the logged wall and
pair events (cell crossings are bookkeeping and not counted). Each is timed through the model's
`advance` after a warm-up call; the median of EXACT_REPEATS runs. Not a default part
(`--part exact`).
"""

from __future__ import annotations

import time

from collide2d.engine import models
from collide2d.runner.bench import goals
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
