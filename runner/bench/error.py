"""The error part of `collide2d bench`: run time against error, against the exact model.

Each benchmark scenario under each model at the ladder of `ladder()` (paper, exact and a model
plugin at every fps of FPS_LADDER; stepped at every fps with 1 substep, and at the scenario's fps
with every count of SUBSTEPS), against the exact model at the scenario's fps. A model's rows run the
scenario as `collide2d run --model M` would load it: `generate` draws whole px/s under `paper` and
real ones under `stepped` and `exact`, so each row's reference is the exact model on that row's own
bodies.

The measures of a row:
- position error at each of HORIZONS_S (quick: QUICK_HORIZONS_S): the mean distance to the
  reference's positions then, px;
- first divergence: the time of the first pair event of either run with no partner in the
  other, the same pair within two of the row's ticks (`first_divergence`), s (blank: none within
  the long horizon);
- missed collisions (per pair, collisions of the reference the run does not have), collision-count
  error (pair events of the run minus the reference's), kinetic energy drift (relative) and the
  largest penetration (the deepest box overlap at a tick's end, px,
  `engine.invariants.max_penetration`), over the long horizon;
- run time: seconds to run the long horizon with the event log off, timed by `timing.measure`
  (calibrated, medians of interleaved repeats over all rows of the scenario, min-max, noisy).

`sensitivity` adds, per scenario, the exact model against itself with every velocity nudged by
NUDGE_PX_S: how far the scene itself carries an error that small (a floor no model can beat).
A row is on the Pareto front when no other row of its scenario is both faster and closer at the
long horizon. `glancing` scans the glancing contact of two 10x10 boxes at one substep.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from pathlib import Path

import numpy as np

from collide2d.engine import models
from collide2d.engine.events import EV_PAIR
from collide2d.engine.invariants import kinetic_energy, max_penetration
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner.bench.scenes import PROJECT_SCENARIOS
from collide2d.runner.bench.timing import measure

HORIZONS_S = (1.0, 10.0)
# quick: the chain's first contact comes at 1.9 s, so the long horizon is 2 s
QUICK_HORIZONS_S = (1.0, 2.0)
FPS_LADDER = (1, 2, 5, 10, 30, 60, 120, 240)
SUBSTEPS = (1, 2, 4, 8, 16, 32, 64)
QUICK_LADDER = {
    "paper": [(30, 1), (60, 1)],
    "stepped": [(60, 1), (60, 4), (60, 16), (60, 64)],
    "exact": [(60, 1)],
}
# A model plugin's rows in a quick run (engine.models.protocol: it takes no substeps).
PLUGIN_QUICK_LADDER = [(30, 1), (60, 1)]
# The sensitivity rows nudge every velocity by up to this much, px/s (seeded).
NUDGE_PX_S = 1e-9
NUDGE_SEED = 1
# Errors below this are float rounding (the contact tests' TIE_PX), shown as this in plots.
ERROR_FLOOR_PX = 1e-9
# The glancing scan: two 10x10 boxes at GLANCE_FPS, one substep; B comes at A along x with its y
# interval overlapping A's by GLANCE_OVERLAPS px, at relative speeds of GLANCE_STEPS box sizes per
# step.
GLANCE_SIZE = 10.0
GLANCE_FPS = 60
GLANCE_OVERLAPS = (0.05, 0.5, 1.0, 2.5, 5.0, 7.5, 9.5, 10.0)
GLANCE_STEPS = tuple(round(0.05 * k, 2) for k in range(1, 61))  # 0.05 ... 3.0
# where, in steps, the pair starts apart: every phase of the step at which they meet
GLANCE_PHASES = (2.1, 2.3, 2.5, 2.7, 2.9)


def position_error(pos: np.ndarray, ref: np.ndarray) -> float:
    """The mean distance (px) between each object's position and its reference position; (n, 2)
    arrays of the same objects (also the position error of `collide2d sweep`)."""
    return float(np.linalg.norm(pos - ref, axis=1).mean()) if len(pos) else 0.0


def ladder(model: str, fps: int, quick: bool) -> list[tuple[int, int]]:
    """The (fps, substeps) a model runs at on a scenario of `fps` (a plugin's: every fps of
    FPS_LADDER, quick: PLUGIN_QUICK_LADDER)."""
    if quick:
        return QUICK_LADDER.get(model, PLUGIN_QUICK_LADDER)
    rows = [(f, 1) for f in FPS_LADDER]
    if model == "stepped":
        rows += [(fps, s) for s in SUBSTEPS if s > 1]
    return rows


def _pair_events(events) -> np.ndarray:
    return events[events["type"] == EV_PAIR]


def _pair_counts(events) -> Counter:
    pairs = _pair_events(events)
    return Counter(zip(pairs["a"].tolist(), pairs["b"].tolist(), strict=True))


def first_divergence(ref_events, events, window: float) -> float | None:
    """When the two sequences of pair events first part, s; None when they never do.

    Each pair event of either run must have a partner in the other: an event of the same pair
    within `window` seconds (a fixed-step run logs a contact at the end of the tick it saw it in,
    the reference at its instant; events at one instant may come in any order), each taken once,
    in order. The first event without one, on either side, is where they part."""
    ref, run = _pair_events(ref_events), _pair_events(events)
    waiting: dict[tuple[int, int], list[float]] = {}
    for a, b, t in zip(run["a"].tolist(), run["b"].tolist(), run["t"].tolist(), strict=True):
        waiting.setdefault((a, b), []).append(t)
    used: dict[tuple[int, int], int] = {}
    unmatched = []
    for a, b, t in zip(ref["a"].tolist(), ref["b"].tolist(), ref["t"].tolist(), strict=True):
        times = waiting.get((a, b), [])
        k = used.get((a, b), 0)
        while k < len(times) and times[k] < t - window:  # run events left without a partner
            unmatched.append(times[k])
            k += 1
        if k < len(times) and abs(times[k] - t) <= window:
            k += 1
        else:
            unmatched.append(t)
        used[(a, b)] = k
    for pair, times in waiting.items():  # run events after the reference's last of their pair
        unmatched.extend(times[used.get(pair, 0) :])
    return min(unmatched) if unmatched else None


def positions_at(model, fps: int, horizons) -> list[np.ndarray]:
    """The model's positions at each horizon (s, ascending), advancing it there; the events on
    the way."""
    out, done, chunks = [], 0, []
    for h in horizons:
        ticks = round(h * fps)
        chunks.append(model.advance(ticks - done, log=True))
        done = ticks
        out.append(model.positions())
    return out, np.concatenate(chunks)


def _reference(scenario, horizons) -> dict:
    """The exact model at the scenario's fps on its bodies: positions at each horizon, events."""
    world, bodies = scenario.world, scenario.bodies
    at, events = positions_at(models.make("exact", world, bodies), world.fps, horizons)
    return {"at": at, "events": events, "pairs": _pair_counts(events)}


def error_ladder(names, models_, quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """Each benchmark scenario (NAME.yaml in `folder`) under each model of `models_` and each
    (fps, substeps) of its ladder, against the exact model: one row each (see the module
    docstring), then the sensitivity rows and the glancing scan."""
    from collide2d.runner.scenario.load import load

    horizons = QUICK_HORIZONS_S if quick else HORIZONS_S
    rows = []
    for name in names:
        path = folder / f"{name}.yaml"
        loaded = {m: load(path, overrides={"model": m}) for m in models_}
        refs = {}
        scene_rows, runs = [], []
        for model in models_:
            scenario = loaded[model]
            key = scenario.bodies.vel.tobytes() + scenario.bodies.pos.tobytes()
            if key not in refs:
                refs[key] = _reference(scenario, horizons)
            for fps, substeps in ladder(model, scenario.world.fps, quick):
                row, run = _error_row(scenario, model, fps, substeps, horizons, refs[key])
                scene_rows.append(row)
                runs.append(run)
        # run time: every row of the scenario measured in interleaved rounds
        for row, timing in zip(scene_rows, measure(runs, quick), strict=True):
            row.update(timing.row())
            echo(
                f"error    {name:24s} {row['model']:7s} fps={row['fps']:<4d} "
                f"substeps={row['substeps']:<3d} {row['run_time_s'] * 1e3:9.2f} ms "
                f"({timing.low * 1e3:.2f}-{timing.high * 1e3:.2f}"
                f"{', noisy' if timing.noisy else ''})  "
                f"err {row['error_short_px']:.3g} / {row['error_long_px']:.3g} px"
            )
        mark_pareto(scene_rows)
        rows.extend(scene_rows)
        rows.extend(sensitivity(name, loaded, horizons))
    if "stepped" in models_:
        rows.append(glancing(echo))
    return rows


def _error_row(scenario, model, fps, substeps, horizons, ref) -> tuple[dict, object]:
    """One row's errors, and the function that runs it for the timing."""
    base = scenario.world
    world = WorldSpec(base.width, base.height, fps)
    bodies = scenario.bodies
    options = {"substeps": substeps} if model == "stepped" else {}
    long_ticks = round(horizons[-1] * fps)
    m = models.make(model, world, bodies, **options)
    energy0 = kinetic_energy(bodies.mass, bodies.static, m.velocities())
    marks = {round(h * fps) for h in horizons}
    chunks, deepest, at = [], 0.0, []
    for k in range(1, long_ticks + 1):
        chunks.append(m.advance(1, log=True))
        deepest = max(deepest, max_penetration(m.positions(), bodies.size)[0])
        if k in marks:
            at.append(m.positions())
    events = np.concatenate(chunks)
    counts = _pair_counts(events)
    energy1 = kinetic_energy(bodies.mass, bodies.static, m.velocities())
    missed = sum(max(0, c - counts.get(p, 0)) for p, c in ref["pairs"].items())
    err = [position_error(a, r) for a, r in zip(at, ref["at"], strict=True)]
    diverges = first_divergence(ref["events"], events, 2.0 / fps)
    row = {
        "part": "error",
        "scene": scenario.name,
        "model": model,
        "n": bodies.n,
        "fps": fps,
        "substeps": substeps,
        "ticks": long_ticks,
        "pairs": sum(counts.values()),
        "missed": missed,
        "count_error": sum(counts.values()) - sum(ref["pairs"].values()),
        "energy_drift": (energy1 - energy0) / energy0 if energy0 else 0.0,
        "max_penetration_px": deepest,
        "short_s": horizons[0],
        "long_s": horizons[-1],
        "error_short_px": err[0],
        "error_long_px": err[-1],
        "diverges_s": diverges,
    }

    def run():
        models.make(model, world, bodies, **options).advance(long_ticks, log=False)

    return row, run


def sensitivity(name: str, loaded: dict, horizons) -> list[dict]:
    """The exact model against itself with every velocity nudged by up to NUDGE_PX_S (seeded),
    once per distinct set of bodies the models load: the scene's own floor of error."""
    rows, seen = [], set()
    for model, scenario in loaded.items():
        bodies = scenario.bodies
        key = bodies.vel.tobytes()
        if key in seen:
            continue
        seen.add(key)
        ref = _reference(scenario, horizons)
        rng = np.random.default_rng(NUDGE_SEED)
        vel = bodies.vel + np.where(
            bodies.static[:, None], 0.0, rng.uniform(-NUDGE_PX_S, NUDGE_PX_S, bodies.vel.shape)
        )
        nudged = dataclasses.replace(bodies, vel=vel)
        fps = scenario.world.fps
        at, events = positions_at(models.make("exact", scenario.world, nudged), fps, horizons)
        err = [position_error(a, r) for a, r in zip(at, ref["at"], strict=True)]
        whole = "whole px/s" if model == "paper" else "real px/s"
        rows.append(
            {
                "part": "sensitivity",
                "scene": scenario.name,
                "model": "exact",
                "n": bodies.n,
                "fps": fps,
                "short_s": horizons[0],
                "long_s": horizons[-1],
                "error_short_px": float(err[0]),
                "error_long_px": float(err[-1]),
                "diverges_s": first_divergence(ref["events"], events, 2.0 / fps),
                "note": f"velocities nudged by {NUDGE_PX_S:g} px/s; bodies as loaded under "
                f"{model} ({whole})",
            }
        )
    return rows


def glancing(echo) -> dict:
    """Two 10x10 boxes at GLANCE_FPS, one substep: B comes at A along x, its y interval
    overlapping A's by each of GLANCE_OVERLAPS px, at each relative speed of GLANCE_STEPS box
    sizes per step, meeting at each phase of GLANCE_PHASES, equal masses. A pass is tunnelling
    when B ends up beyond A's far face. Returns a row: the largest relative displacement per step
    (box sizes) that tunnels below one box size (`value`, None: none), and the smallest that
    tunnels at all (`note`)."""
    world = WorldSpec(2000, 100, GLANCE_FPS)
    s = GLANCE_SIZE
    worst_below, first_any = None, None
    for step in GLANCE_STEPS:
        speed = step * s * GLANCE_FPS
        for overlap in GLANCE_OVERLAPS:
            for phase in GLANCE_PHASES:
                gap = phase * step * s  # they meet in the third step
                pos = [[1000.0, 40.0], [1000.0 - s - gap, 40.0 - s + overlap]]
                vel = [[-speed / 2, 0.0], [speed / 2, 0.0]]
                m = models.make("stepped", world, Bodies.boxes(pos, s, vel))
                m.advance(6, log=False)
                p = m.positions()
                if p[1, 0] > p[0, 0]:  # B beyond A: they passed through each other
                    if step < 1.0:
                        worst_below = step if worst_below is None else max(worst_below, step)
                    first_any = step if first_any is None else min(first_any, step)
    said = "none" if worst_below is None else f"{worst_below:g}"
    echo(f"glancing tunnelling at 1 substep below one box size per step: {said}")
    return {
        "part": "glancing",
        "scene": f"two {s:g}x{s:g} boxes, y overlap "
        f"{GLANCE_OVERLAPS[0]:g}-{GLANCE_OVERLAPS[-1]:g} px",
        "model": "stepped",
        "fps": GLANCE_FPS,
        "substeps": 1,
        "value": worst_below,
        "note": "largest relative displacement per step (box sizes) below one box size that "
        "tunnels: "
        + said
        + "; smallest that tunnels at all: "
        + ("none" if first_any is None else f"{first_any:g}"),
    }


def mark_pareto(rows: list[dict]) -> None:
    """pareto = "yes" for the rows no other row beats on both run time and the error at the long
    horizon (errors below ERROR_FLOOR_PX count as equal)."""

    def err(r):
        return max(r["error_long_px"], ERROR_FLOOR_PX)

    for r in rows:
        beaten = any(
            o is not r
            and o["run_time_s"] <= r["run_time_s"]
            and err(o) <= err(r)
            and (o["run_time_s"] < r["run_time_s"] or err(o) < err(r))
            for o in rows
        )
        r["pareto"] = "no" if beaten else "yes"
