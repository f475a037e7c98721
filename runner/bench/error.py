"""The error part of `collide2d bench`: run time against error, against the exact model.

Each benchmark scenario under each model at a ladder of fps and substeps, against the exact model
at the scenario's fps: run time, missed collisions (per pair, collisions of the reference the run
does not have), collision-count error (pair events of the run minus the reference's), kinetic
energy drift (relative), largest penetration (the deepest box overlap at a tick's end, px,
`engine.invariants.max_penetration`) and position error over a short horizon (mean distance to the
reference HORIZON_S seconds after the reference's first collision, px; long horizons are chaotic).
A row is on the Pareto front when no other row of its scenario is both faster and closer.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from pathlib import Path

import numpy as np

from collide2d.engine import models
from collide2d.engine.events import EV_PAIR
from collide2d.engine.invariants import kinetic_energy, max_penetration
from collide2d.engine.world import WorldSpec
from collide2d.runner.bench.scenes import PROJECT_SCENARIOS
from collide2d.runner.bench.timing import REPEATS, median

HORIZON_S = 0.5
# The horizon is rounded up to a multiple of this (s), a whole number of ticks at every fps of
# the ladders.
HORIZON_GRID_S = 0.1
LADDER = {
    "paper": [(fps, 1) for fps in (10, 30, 60, 120, 240)],
    "stepped": [(fps, s) for fps in (10, 30, 60, 120) for s in (1, 4, 16)],
    "exact": [(10, 1), (60, 1)],
}
QUICK_LADDER = {"paper": [(30, 1), (60, 1)], "stepped": [(60, 1), (60, 4)], "exact": [(60, 1)]}
# In quick mode a benchmark scenario runs at most this long (s).
QUICK_DURATION_S = 0.5


def position_error(pos: np.ndarray, ref: np.ndarray) -> float:
    """The mean distance (px) between each object's position and its reference position; (n, 2)
    arrays of the same objects (also the position error of `collide2d sweep`)."""
    return float(np.linalg.norm(pos - ref, axis=1).mean()) if len(pos) else 0.0


def _pair_counts(events) -> Counter:
    pairs = events[events["type"] == EV_PAIR]
    return Counter(zip(pairs["a"].tolist(), pairs["b"].tolist(), strict=True))


def _reference(scenario, duration: float) -> dict:
    """The exact model at the scenario's fps: pair counts over `duration` s, positions at the
    horizon (HORIZON_S after its first collision, on the HORIZON_GRID_S grid, within the run)."""
    world, bodies = scenario.world, scenario.bodies
    events = models.make("exact", world, bodies).advance(round(duration * world.fps), log=True)
    pairs = events[events["type"] == EV_PAIR]
    first = float(pairs["t"][0]) if len(pairs) else 0.0
    steps = math.ceil(round((first + HORIZON_S) / HORIZON_GRID_S, 9))
    horizon = min(steps * HORIZON_GRID_S, duration)
    model = models.make("exact", world, bodies)
    model.advance(round(horizon * world.fps), log=False)
    return {"pairs": _pair_counts(events), "horizon_s": horizon, "horizon": model.positions()}


def error_ladder(names, models_, quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """Each benchmark scenario (NAME.yaml in `folder`) under each model and (fps, substeps) of the
    ladder, against the exact model: one row each (see the module docstring)."""
    from collide2d.runner.scenario import load

    ladder = QUICK_LADDER if quick else LADDER
    repeats = 1 if quick else REPEATS
    rows = []
    for name in names:
        scenario = load(folder / f"{name}.yaml")
        duration = scenario.ticks / scenario.world.fps
        if quick:
            duration = min(duration, QUICK_DURATION_S)
        ref = _reference(scenario, duration)
        ref_pairs = sum(ref["pairs"].values())
        scene_rows = []
        for model in models_:
            for fps, substeps in ladder.get(model, ()):
                row = _error_row(scenario, model, fps, substeps, duration, ref, repeats)
                row["count_error"] = row["pairs"] - ref_pairs
                scene_rows.append(row)
                echo(
                    f"error    {name:24s} {model:7s} fps={fps:<4d} substeps={substeps:<3d} "
                    f"{row['run_time_s'] * 1e3:9.2f} ms  pos err {row['position_error_px']:.3g} px"
                )
        mark_pareto(scene_rows)
        rows.extend(scene_rows)
    return rows


def _error_row(scenario, model, fps, substeps, duration, ref, repeats) -> dict:
    base = scenario.world
    world = WorldSpec(base.width, base.height, fps)
    bodies = scenario.bodies
    options = {"substeps": substeps} if model == "stepped" else {}
    ticks = round(duration * fps)
    h_ticks = round(ref["horizon_s"] * fps)
    # run time: clean runs with the log on, as a run that writes events
    times = []
    for _ in range(repeats):
        m = models.make(model, world, bodies, **options)
        began = time.perf_counter()
        m.advance(ticks, log=True)
        times.append(time.perf_counter() - began)
    # errors: one run looked at after every tick
    m = models.make(model, world, bodies, **options)
    energy0 = kinetic_energy(bodies.mass, bodies.static, m.velocities())
    chunks, deepest, at_horizon = [], 0.0, None
    for k in range(1, ticks + 1):
        chunks.append(m.advance(1, log=True))
        deepest = max(deepest, max_penetration(m.positions(), bodies.size)[0])
        if k == h_ticks:
            at_horizon = m.positions()
    if at_horizon is None:
        at_horizon = m.positions()
    events = np.concatenate(chunks) if chunks else m.advance(0, log=True)
    counts = _pair_counts(events)
    energy1 = kinetic_energy(bodies.mass, bodies.static, m.velocities())
    missed = sum(max(0, c - counts.get(p, 0)) for p, c in ref["pairs"].items())
    return {
        "part": "error",
        "scene": scenario.name,
        "model": model,
        "n": bodies.n,
        "fps": fps,
        "substeps": substeps,
        "ticks": ticks,
        "run_time_s": median(times),
        "pairs": sum(counts.values()),
        "missed": missed,
        "energy_drift": (energy1 - energy0) / energy0 if energy0 else 0.0,
        "max_penetration_px": deepest,
        "position_error_px": position_error(at_horizon, ref["horizon"]),
        "horizon_s": ref["horizon_s"],
    }


def mark_pareto(rows: list[dict]) -> None:
    """pareto = "yes" for the rows no other row beats on both run time and position error."""
    for r in rows:
        beaten = any(
            o is not r
            and o["run_time_s"] <= r["run_time_s"]
            and o["position_error_px"] <= r["position_error_px"]
            and (
                o["run_time_s"] < r["run_time_s"] or o["position_error_px"] < r["position_error_px"]
            )
            for o in rows
        )
        r["pareto"] = "no" if beaten else "yes"
