"""The peers part of `collide2d bench`: pymunk steps the standard scene (the `bench` extra;
pymunk against the stepped model under gravity is the gravity part's, runner/bench/gravity).

pymunk steps at 1/STANDARD_FPS s with boxes of mass 1 and infinite moment, elasticity 1, friction 0
and four static walls: the standard scene run by the pymunk model (`engine.models.pymunk`, the
adapter behind `model: pymunk`, with no collision callback), so the bench times what a scenario
runs; the faster of its bounding-box tree and its spatial hash is
kept (`PymunkTimer`). The scaling part times pymunk in turn with the stepped model (`timer`,
`scaling`'s `peer`): each round one pymunk run between the stepped model's two, so that a
machine whose speed drifts over minutes (a shared virtual machine's does, by a quarter) slows
both sides of the ratio alike (timed apart, minutes after the stepped model, the ratio took that
drift in); `peers` then divides the stepped model's steps/s by pymunk's.
"""

from __future__ import annotations

import time

from collide2d.runner.bench.scenes import STANDARD_FPS, STANDARD_SIZE_PX, standard_scene
from collide2d.runner.bench.timing import PROBE_S, QUICK_TARGET_S, TARGET_S, median

# pymunk's spatial hash gets cells of this many box sides and this many cells per object.
PYMUNK_HASH_SIDES = 2.0
PYMUNK_HASH_CELLS_PER_OBJECT = 10
PYMUNK_WARMUP_STEPS = 10


def pymunk_available() -> bool:
    try:
        import pymunk  # noqa: F401
    except ImportError:
        return False
    return True


def _pymunk_model(scenario, hashed: bool):
    """The standard scene as the pymunk model (`engine.models.pymunk`, the adapter `model:
    pymunk` runs): boxes of mass 1 and infinite moment (no rotation), elasticity 1, friction 0,
    four static walls, no gravity; no collision callback (pymunk's own speed)."""
    from collide2d.engine.models.pymunk import Model

    spatial_hash = None
    if hashed:
        n = scenario.bodies.n
        spatial_hash = (
            PYMUNK_HASH_SIDES * STANDARD_SIZE_PX,
            max(1000, PYMUNK_HASH_CELLS_PER_OBJECT * n),
        )
    return Model(scenario.world, scenario.bodies, spatial_hash=spatial_hash, events=False)


class PymunkTimer:
    """pymunk on the standard scene with n boxes, its broad phase chosen: both its default tree
    and its spatial hash step a probe of about PROBE_S s (or `target`, when shorter) after a
    warm-up, and the faster is kept (`how` names it). Each `sample()` then times one run of
    about `target` s of it and returns steps/s."""

    def __init__(self, n: int, target: float):
        from collide2d.runner.scenario.load import loads

        scenario = loads(standard_scene(n, "stepped"))
        self.dt = 1.0 / STANDARD_FPS
        best = 0.0
        for hashed in (False, True):
            model = _pymunk_model(scenario, hashed)
            model.advance(PYMUNK_WARMUP_STEPS, log=False)
            began = time.perf_counter()
            steps = 0
            while time.perf_counter() - began < min(target, PROBE_S) or steps < 2:
                model.advance(1, log=False)
                steps += 1
            rate = steps / (time.perf_counter() - began)
            if rate > best:
                best = rate
                self.model = model
                self.how = "spatial hash" if hashed else "bounding-box tree"
        self.ticks = max(2, int(target * best))

    def sample(self) -> float:
        """Steps/s of one timed run."""
        began = time.perf_counter()
        self.model.advance(self.ticks, log=False)
        return self.ticks / (time.perf_counter() - began)


def timer(quick: bool):
    """The peer timers the scaling part interleaves with the stepped model's runs: n -> a
    `PymunkTimer` of this run's length (`peers`' own)."""
    target = QUICK_TARGET_S if quick else TARGET_S / 2
    return lambda n: PymunkTimer(n, target)


def pymunk_steps_per_second(n: int, target: float, repeats: int) -> tuple[float, str]:
    """pymunk's steps/s on the standard scene with n boxes, the median of `repeats` timed runs of
    about `target` s, and its broad phase (`PymunkTimer`)."""
    clock = PymunkTimer(n, target)
    return median([clock.sample() for _ in range(repeats)]), clock.how


def peers(ns: list[int], ours: dict[int, float], timed: dict, echo) -> list[dict]:
    """pymunk on the standard scene at each N, and the stepped model's ratio to it: `ours` the
    stepped model's steps/s by N and `timed` pymunk's (steps/s, broad phase) by N, both from this
    run's scaling part, which timed them in turn (`timer`)."""
    import pymunk

    rows = []
    for n in ns:
        rate, how = timed[n]
        how += ", timed in turn with the stepped model's runs"
        row = {
            "part": "peers",
            "scene": "standard",
            "model": f"pymunk {pymunk.version}",
            "n": n,
            "fps": STANDARD_FPS,
            "steps_per_s": rate,
            "body_steps_per_s": rate * n,
            "ns_per_body_step": 1e9 / (rate * n),
            "peer_steps_per_s": rate,
            "note": how,
            "ratio": ours[n] / rate,
        }
        rows.append(row)
        echo(
            f"peers    pymunk  n={n:<7d} {rate:12,.1f} steps/s ({how}), "
            f"stepped/pymunk = {row['ratio']:.2f}"
        )
    return rows
