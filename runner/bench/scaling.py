"""The scaling part of `collide2d bench`: the standard scene under each model at each N.

One row per model and N: steps/s through `collide2d run` in a subprocess (or `runner.run.drive`
in process), start-up excluded by subtracting a 1-tick run (the two interleaved, medians of
REPEATS, the run's min-max, spread and noisy flag kept; with a `peer`, the stepped model's rounds
also time the peer once each, between the two, so that a ratio of the two medians holds no drift
of the machine's speed); body-steps/s; events/s (events per
tick of a logged run times steps/s); the time per step of each stage (`Model.profile`, where the
model has stages); and the time to render one frame.
"""

from __future__ import annotations

import time
from pathlib import Path

from collide2d.engine import models
from collide2d.runner.bench.scenes import STANDARD_FPS, standard_scene
from collide2d.runner.bench.timing import (
    NOISY_SPREAD,
    PROBE_S,
    QUICK_PROBE_S,
    QUICK_TARGET_S,
    REPEATS,
    TARGET_S,
    cli_seconds,
    drive_seconds,
    median,
    probe_rate,
)

SCALING_N = (50, 1_000, 10_000, 100_000)
QUICK_N = (50, 400)
# Frames timed for the render column (the first draw of a renderer repaints everything).
RENDER_FRAMES = 4


def scaling(
    models_: list[str], ns: list[int], quick: bool, in_process: bool, echo, peer=None
) -> list[dict]:
    """The standard scene under each model at each N: one row each (see the module docstring).
    peer: n -> a timer whose `sample()` gives a peer's steps/s on the same scene (peers.timer);
    the stepped model's rows then hold its median as `peer_steps_per_s` and its broad phase as
    `peer_how`."""
    import tempfile

    rows = []
    target = QUICK_TARGET_S if quick else TARGET_S
    probe = QUICK_PROBE_S if quick else PROBE_S
    repeats = 3 if quick else REPEATS
    with tempfile.TemporaryDirectory(prefix="collide2d-bench-") as tmp:
        tmp = Path(tmp)
        for model in models_:
            for n in ns:
                clock = peer(n) if peer is not None and model == "stepped" else None
                rows.append(
                    _scaling_row(model, n, target, probe, repeats, in_process, tmp, echo, clock)
                )
    return rows


def _scaling_row(model, n, target, probe_s, repeats, in_process, tmp: Path, echo, peer) -> dict:
    from collide2d.engine.picture.raster import Renderer
    from collide2d.runner.scenario.load import loads

    text = standard_scene(n, model)
    scenario = loads(text)
    world, bodies = scenario.world, scenario.bodies
    # estimate the rate in process (kernels loaded), then size the timed runs from it
    probe = models.make(model, world, bodies)
    rate = probe_rate(probe, probe_s)
    ticks = max(2, int(target * rate))
    if in_process:
        short, full = (lambda: drive_seconds(text, 1)), (lambda: drive_seconds(text, ticks))
        how = "in process (drive)"
    else:
        path = tmp / f"standard_{model}_{n}.yaml"
        path.write_text(text)
        out = tmp / "out"
        cli_seconds(path, 1, out)  # warm the file cache and the kernels
        short, full = (lambda: cli_seconds(path, 1, out)), (lambda: cli_seconds(path, ticks, out))
        how = "collide2d run"
    # interleaved: 1 tick, the run, the run, 1 tick, ... so that a drift shows in both alike (and
    # the peer's run between the two, each round)
    t1s, tts, peer_rates = [], [], []
    for r in range(repeats):
        round_ = [(t1s, short), (tts, full)]
        if peer is not None:
            round_.insert(1, (peer_rates, peer.sample))
        for which in round_ if r % 2 == 0 else round_[::-1]:
            which[0].append(which[1]())
    t1, tt = median(t1s), median(tts)
    if not tt > 1.5 * t1:  # too short to stand out of the start-up's noise: say so
        how += ", noisy (the run was not much longer than the 1-tick run)"
    per_step = max(tt - t1, 1e-12) / (ticks - 1)
    steps = 1.0 / per_step
    # events per tick from a logged run of the same length as the probe
    logged = models.make(model, world, bodies)
    log_ticks = max(1, min(ticks, int(probe_s * rate) + 1))
    events = len(logged.advance(log_ticks, log=True)) / log_ticks
    row = {
        "part": "scaling",
        "scene": "standard",
        "model": model,
        "n": n,
        "fps": STANDARD_FPS,
        "substeps": 1,
        "ticks": ticks,
        "steps_per_s": steps,
        "body_steps_per_s": steps * n,
        "ns_per_body_step": 1e9 * per_step / n,
        "events_per_s": events * steps,
        "note": how,
        # the run's seconds, its repeats' range and spread
        "run_time_s": tt,
        "run_time_min_s": min(tts),
        "run_time_max_s": max(tts),
        "repeats": repeats,
        "spread": (max(tts) - min(tts)) / max(tt, 1e-12),
        "noisy": "yes" if max(tts) - min(tts) > NOISY_SPREAD * tt else "no",
    }
    if peer is not None:
        row["peer_steps_per_s"] = median(peer_rates)
        row["peer_how"] = peer.how
    # time per stage, where the model has stages (state as after the logged run)
    if hasattr(logged, "profile"):
        prof_ticks = max(1, min(ticks, int(probe_s * rate) + 1))
        logged.profile(1)  # load the stage kernels
        spent = logged.profile(prof_ticks)
        for stage, seconds in spent.items():
            row[f"{stage}_ms"] = 1e3 * seconds / prof_ticks
    renderer = Renderer(world, bodies)
    renderer.draw(logged.positions())  # the first frame is a full one; then load the redraw
    logged.advance(1, log=False)
    renderer.draw(logged.positions())
    began = time.perf_counter()
    for _ in range(RENDER_FRAMES):
        logged.advance(1, log=False)
        renderer.draw(logged.positions())
    row["render_ms"] = 1e3 * (time.perf_counter() - began) / RENDER_FRAMES
    echo(
        f"scaling  {model:7s} n={n:<7d} {steps:12,.1f} steps/s  "
        f"{row['ns_per_body_step']:8.1f} ns/body-step  ({how}, {ticks} ticks)"
    )
    return row
