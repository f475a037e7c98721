"""One stress case: a scene under a model, checked after every tick, then run again for the same
bytes; and the suite of every case.

`run_case` builds the model (`engine.models.make`), advances it one tick at a time through a
`checks.Checker`, and stops at the first broken invariant or at the model's own error (a runaway);
then `_rerun` runs the same ticks again, `CHUNK_TICKS` per call, unchecked, and the two runs must
end with the same positions, velocities, event records and stop, byte for byte. The verdict is
pass, fail, or stopped (a runaway the scene expects, stopped by a clear error).
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass, field

from collide2d.engine.models import make as make_model
from collide2d.engine.models import scenario_options
from collide2d.runner.stress.checks import Checker
from collide2d.runner.stress.falling import every_scene
from collide2d.runner.stress.scenes import Scene

# Ticks per model call in the second, unchecked run (which must give the same bytes).
CHUNK_TICKS = 65_536
VERDICT_PASS = "pass"
VERDICT_FAIL = "fail"
VERDICT_STOPPED = "stopped"  # a runaway the scene expects, stopped by a clear error


@dataclass
class CaseResult:
    """What one scene under one model did. Drifts are relative; None where not measured."""

    scene: str
    model: str
    verdict: str
    ticks: int  # asked for
    ticks_run: int = 0
    events: int = 0
    energy_drift: float | None = None
    momentum_drift: float | None = None
    penetration_px: float | None = None
    run_time_s: float = 0.0  # the checked run, tick by tick (not the second run)
    problems: list[str] = field(default_factory=list)
    note: str = ""


def _stop_message(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}"


def _build(scene: Scene, model: str):
    options = scenario_options(model, substeps=1, geometry="box")
    return make_model(model, scene.world, scene.bodies, **options)


def run_case(scene: Scene, model: str) -> CaseResult:
    """Run `scene` under `model` tick by tick with every check, then again for the same bytes."""
    result = CaseResult(scene.name, model, VERDICT_PASS, scene.ticks)
    began = time.perf_counter()
    try:
        sim = _build(scene, model)
    except Exception as exc:  # a model refusing the scene is a finding, never a crash
        result.verdict = VERDICT_FAIL
        result.problems.append(f"the model refused the scene: {_stop_message(exc)}")
        return result
    pos, vel = sim.positions(), sim.velocities()
    checker = Checker(scene, model, pos, vel)
    digest = hashlib.sha256()
    stopped = None
    try:
        while sim.tick < scene.ticks and not checker.problems:
            events = sim.advance(1, True)
            digest.update(events.tobytes())
            result.events += int(events.shape[0])
            pos, vel = sim.positions(), sim.velocities()
            checker.tick(sim.tick, pos, vel, events)
    except Exception as exc:  # a model's error is a finding to report, never a crash
        stopped = _stop_message(exc)
    result.ticks_run = int(sim.tick)
    result.run_time_s = time.perf_counter() - began
    result.energy_drift = checker.energy_drift
    result.momentum_drift = checker.momentum_drift
    result.penetration_px = checker.penetration
    result.problems = list(checker.problems)
    first = (pos.tobytes(), vel.tobytes(), digest.hexdigest(), stopped)
    second = _rerun(scene, model, result.ticks_run, stopped is not None)
    differ = [w for w, a, b in zip(_RUN_PARTS, first, second, strict=True) if a != b]
    if differ:
        result.problems.append(
            f"a second run differs in its {', '.join(differ)} (not the same bytes twice)"
        )
    if stopped is not None:
        result.note = stopped
        if model not in scene.expect_stop:
            result.problems.append(f"tick {result.ticks_run + 1}: stopped: {stopped}")
        elif not result.problems:
            result.verdict = VERDICT_STOPPED
    elif model in scene.expect_stop and not result.problems:
        result.problems.append("ran through a runaway that should stop with a clear error")
    if result.problems:
        result.verdict = VERDICT_FAIL
    return result


_RUN_PARTS = ("positions", "velocities", "events", "stop")


def _rerun(scene: Scene, model: str, ticks: int, then_stop: bool):
    """The same case again, unchecked, `CHUNK_TICKS` per call: positions and velocities after
    `ticks`, the digest of their events, and (with then_stop) the error of the next tick."""
    sim = _build(scene, model)
    digest = hashlib.sha256()
    stopped = None
    try:
        while sim.tick < ticks:
            events = sim.advance(min(CHUNK_TICKS, ticks - sim.tick), True)
            digest.update(events.tobytes())
    except Exception as exc:
        stopped = _stop_message(exc)
    pos, vel = sim.positions(), sim.velocities()
    if then_stop and stopped is None:
        try:
            sim.advance(1, True)
        except Exception as exc:
            stopped = _stop_message(exc)
    return pos.tobytes(), vel.tobytes(), digest.hexdigest(), stopped


def run_suite(quick: bool, only_scenes=(), only_models=(), on_case=None) -> list[CaseResult]:
    """Every scene under every model it applies to (filtered by name when asked); `on_case` is
    called with each result as it comes."""
    results = []
    for scene in every_scene(quick):
        if only_scenes and scene.name not in only_scenes:
            continue
        for model in scene.models:
            if only_models and model not in only_models:
                continue
            result = run_case(scene, model)
            results.append(result)
            if on_case is not None:
                on_case(result)
    return results
