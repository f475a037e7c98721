"""The skips part of `collide2d bench`: for each thing a run skips when a scene does not need it,
the same work with and without the skip, and the saving (time without / time with): medians of
interleaved measures (timing.measure), with the range and the noisy flag.

The scenes: the section IV demo (frame skips, erase only what moved), one mover among
SKIP_STATICS static boxes (no pair work between statics), the dense gas (no event records without a
log; the exact model's local re-prediction).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from collide2d.engine import models
from collide2d.engine.world import WorldSpec
from collide2d.runner.bench.scenes import DEMO_SCENARIO, PROJECT_SCENARIOS, STANDARD_SEED
from collide2d.runner.bench.timing import measure

SKIP_TICKS = 600
SKIP_STATICS = 4000


def skips(quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """Each skip's work with and without it (see the module docstring); the scenario files are
    read from `folder`."""
    from collide2d.engine.picture.raster import Renderer
    from collide2d.engine.world import Bodies
    from collide2d.runner.run import drive
    from collide2d.runner.scenario.load import load

    ticks = 60 if quick else SKIP_TICKS
    demo = load(folder / f"{DEMO_SCENARIO}.yaml", overrides={"ticks": ticks})
    every = list(range(0, ticks + 1, 10))
    frames_all = list(range(ticks + 1))

    def run(frames):
        return lambda: drive(demo, frames=frames, on_frame=lambda k, idx: None)

    cases = [
        ("no rasterising when no frame is asked for", run(()), run(frames_all), "section IV demo"),
        ("only the frames asked for (every 10th)", run(every), run(frames_all), "section IV demo"),
    ]
    # one mover among many static boxes: no pairs of two static objects
    rng = np.random.default_rng(STANDARD_SEED)
    k = 400 if quick else SKIP_STATICS
    side = int(math.sqrt(k)) + 1
    cells = rng.permutation(side * side)[:k]
    pos = np.stack([cells % side * 12.0, cells // side * 12.0], axis=1)
    pos = np.vstack([[[-100.0, -100.0]], pos]) + 100.0
    static = np.ones(k + 1, bool)
    static[0] = False
    vel = np.zeros((k + 1, 2))
    vel[0] = [97.0, 61.0]
    world = WorldSpec(side * 12 + 200, side * 12 + 200, 60)
    statics = Bodies.boxes(pos, 10.0, vel, static=static)
    steps = 30 if quick else 300
    for model in ("paper", "stepped"):
        cases.append(
            (
                f"no pair work between static objects ({model})",
                lambda m=model: models.make(m, world, statics).advance(steps, log=False),
                lambda m=model: models.make(m, world, statics, skip=False).advance(steps, False),
                f"1 mover, {k} static boxes, {steps} ticks",
            )
        )
    gas = load(folder / "bench_dense_gas.yaml", overrides={"ticks": 30 if quick else 240})
    for model in ("stepped", "exact"):
        cases.append(
            (
                f"no event records when no log is asked for ({model})",
                lambda m=model: models.make(m, gas.world, gas.bodies).advance(gas.ticks, False),
                lambda m=model: models.make(m, gas.world, gas.bodies).advance(gas.ticks, True),
                f"dense gas, {gas.ticks} ticks",
            )
        )
    # erase only what moved: 5 of the demo's 50 boxes move
    frames = 50 if quick else 2000
    moving = np.array(demo.bodies.pos)
    path = np.empty((frames, len(moving), 2))
    for f in range(frames):
        moving[:5] += 1.0
        moving[:5] %= 200.0
        path[f] = moving
    renderer_dirty = Renderer(demo.world, demo.bodies)
    renderer_full = Renderer(demo.world, demo.bodies)
    cases.append(
        (
            "erase only what moved",
            lambda: [renderer_dirty.draw(p) for p in path],
            lambda: [renderer_full.draw_full(p) for p in path],
            f"section IV demo frame, 5 of 50 boxes moving, {frames} frames",
        )
    )
    if _exact_has_full_repredict():
        cases.append(
            (
                "exact re-predicts only what an event touched",
                lambda: models.make("exact", gas.world, gas.bodies).advance(gas.ticks, False),
                lambda: models.make("exact", gas.world, gas.bodies, repredict="all").advance(
                    gas.ticks, False
                ),
                f"dense gas, {gas.ticks} ticks",
            )
        )
    rows = []
    for name, with_skip, without_skip, scene in cases:
        t_with, t_without = measure([with_skip, without_skip], quick)
        saving = t_without.median / max(t_with.median, 1e-12)
        # the saving's range: the extremes of the two ranges against each other
        low = t_without.low / max(t_with.high, 1e-12)
        high = t_without.high / max(t_with.low, 1e-12)
        noisy = t_with.noisy or t_without.noisy
        rows.append(
            {
                "part": "skips",
                "scene": scene,
                "with_s": t_with.median,
                "without_s": t_without.median,
                "saving": saving,
                "saving_min": low,
                "saving_max": high,
                "repeats": t_with.repeats,
                "spread": max(t_with.spread, t_without.spread),
                "noisy": "yes" if noisy else "no",
                "note": name,
            }
        )
        flag = "  noisy" if noisy else ""
        echo(f"skips    {name:52s} x{saving:.1f} (x{low:.1f}-x{high:.1f}){flag}")
    return rows


def _exact_has_full_repredict() -> bool:
    """Whether the exact model takes the `repredict="all"` option (re-predict every object after
    each event: the work its local re-prediction saves)."""
    import inspect

    from collide2d.engine.models import exact

    return "repredict" in inspect.signature(exact.Model).parameters
