"""The stages part of `collide2d bench` (`--part stages`): where a body-step goes, on one thread
and on all, and the stepped model against pymunk in the same run.

For the stepped and paper models on the standard scene at each N: steps/s of the model's `advance`
(event log off, the median of STAGE_REPEATS timings after a warm-up) with one thread and with every
thread numba may use (engine.threads), the ratio of the two, and the time per body-step of each
stage (`Model.profile`, the model's one stage list run a stage at a time). With pymunk installed
(the `bench` extra), pymunk steps the same scene in the same run and the stepped model's ratio to
it is given for one thread and for all. Rows are one figure each (`value`, described by `note`).
Times are in process: the model's own stepping, without a run's start-up or outputs.
"""

from __future__ import annotations

import time

from collide2d.engine import models, threads
from collide2d.runner.bench.scenes import standard_scene
from collide2d.runner.bench.timing import median

STAGE_N = (1_000, 10_000, 100_000)
QUICK_STAGE_N = (300, 2_000)
STAGE_MODELS = ("stepped", "paper")
STAGE_REPEATS = 5
STAGE_TARGET_S = 0.5  # seconds of stepping per timing
QUICK_STAGE_TARGET_S = 0.02


def _rate(model, target: float, repeats: int) -> float:
    """Median steps/s of `model.advance` (log off) over `repeats` timings of about `target` s."""
    model.advance(1, log=False)
    ticks = 1
    while True:  # a tick count that takes about `target`
        began = time.perf_counter()
        model.advance(ticks, log=False)
        spent = time.perf_counter() - began
        if spent >= target / 4 or ticks >= 1 << 20:
            break
        ticks *= 2
    ticks = max(1, int(ticks * target / max(spent, 1e-9)))
    rates = []
    for _ in range(repeats):
        began = time.perf_counter()
        model.advance(ticks, log=False)
        rates.append(ticks / max(time.perf_counter() - began, 1e-12))
    return median(rates)


def stages(quick: bool, echo, ns=None) -> list[dict]:
    from collide2d.runner.bench import peers
    from collide2d.runner.scenario.load import loads

    ns = list(ns or (QUICK_STAGE_N if quick else STAGE_N))
    target = QUICK_STAGE_TARGET_S if quick else STAGE_TARGET_S
    repeats = 1 if quick else STAGE_REPEATS
    every = threads.available()
    before = threads.threads()
    rows = []
    try:
        for n in ns:
            for name in STAGE_MODELS:
                scenario = loads(standard_scene(n, name))
                rates = {}
                for t in dict.fromkeys((1, every)):
                    threads.set_threads(t)
                    model = models.make(name, scenario.world, scenario.bodies)
                    rates[t] = _rate(model, target, repeats)
                    ticks = max(1, int(rates[t] * target / 4))
                    model.profile(1)  # load the kernels the stage-by-stage calls use
                    spent = model.profile(ticks)
                    per = {k: v / ticks / n * 1e9 for k, v in spent.items()}
                    listing = ", ".join(f"{k} {v:.1f}" for k, v in per.items())
                    ns_step = 1e9 / (rates[t] * n)
                    rows.append(
                        {
                            "part": "stages",
                            "scene": f"standard-{n}",
                            "model": name,
                            "n": n,
                            "steps_per_s": rates[t],
                            "ns_per_body_step": ns_step,
                            "value": rates[t],
                            "note": f"steps/s on {t} thread(s); {ns_step:.1f} ns/body-step; "
                            f"stages (ns/body-step, profiled): {listing}",
                        }
                    )
                    echo(
                        f"stages   {name:8s} n={n:<7d} threads={t} {rates[t]:12,.1f} steps/s "
                        f"{ns_step:8.1f} ns/body-step ({listing})"
                    )
                if every > 1:
                    ratio = rates[every] / rates[1]
                    rows.append(
                        {
                            "part": "stages",
                            "scene": f"standard-{n}",
                            "model": name,
                            "n": n,
                            "ratio": ratio,
                            "value": ratio,
                            "note": f"steps/s on {every} threads / on 1 thread",
                        }
                    )
            if peers.pymunk_available():
                peer, _ = peers.pymunk_steps_per_second(n, target, repeats)
                for t in dict.fromkeys((1, every)):
                    ours = next(
                        r["steps_per_s"]
                        for r in rows
                        if r["model"] == "stepped"
                        and r["n"] == n
                        and "steps_per_s" in r
                        and f"on {t} thread(s)" in r["note"]
                    )
                    rows.append(
                        {
                            "part": "stages",
                            "scene": f"standard-{n}",
                            "model": "stepped",
                            "n": n,
                            "peer_steps_per_s": peer,
                            "ratio": ours / peer,
                            "value": ours / peer,
                            "note": f"stepped on {t} thread(s) / pymunk ({peer:,.1f} steps/s), "
                            "same run, in process",
                        }
                    )
                    echo(f"stages   stepped/pymunk n={n} threads={t}: {ours / peer:.1f}x")
    finally:
        threads.set_threads(before)
    return rows
