"""The figures `collide2d bench` holds the engine to, in one place: its headline marks each met or
not (runner.bench.report).

- PEER_RATIO: the stepped model's steps/s over pymunk's on the same standard scene, through
  `collide2d run` with every core, by N;
- STEPPED_NS_PER_BODY_STEP: the stepped model's cost per body-step at that N, every core, at most;
- PAPER_STEPS_PER_S: the paper model's steps/s at that N, at least;
- EXACT_EVENTS_PER_S: the exact model's events/s by scene of the exact part, at least;
- EXACT_GRAVITY_RATIO: the exact model's events/s on a gas under gravity over the same gas
  without it (the gravity part), at least;
- LOAD: seconds (and peak MB) to load that many objects, by how (runner.bench.load), at most;
- COMPILE_BUDGET_S: seconds a model's kernels take to compile for its standard scene from an
  empty kernel cache, at most, when nothing is precompiled (the jit part; none at all where the
  wheel ships them).
"""

from __future__ import annotations

PEER_RATIO = {1_000: 10.0, 10_000: 15.0, 100_000: 30.0}
STEPPED_NS_PER_BODY_STEP = (100_000, 10.0)
PAPER_STEPS_PER_S = (100_000, 300.0)
EXACT_EVENTS_PER_S = {"two-body chain": 4_000_000, "standard-10000": 500_000}
EXACT_GRAVITY_RATIO = 0.5
LOAD = {
    "YAML list, fast lane": (1.0, 300),
    "YAML block list, fast lane": (3.0, 300),
    "CSV table": (0.3, None),
}
COMPILE_BUDGET_S = {"paper": 3.0, "stepped": 8.0, "exact": 8.0}
