"""runner.bench.peers: pymunk steps the same standard scene."""

from __future__ import annotations

import math

import pytest

from collide2d.runner.bench import peers, scenes
from collide2d.runner.scenario.load import loads


def test_pymunk_steps_the_same_standard_scene():
    pymunk = pytest.importorskip("pymunk")
    scenario = loads(scenes.standard_scene(30, "stepped"))
    model = peers._pymunk_model(scenario, hashed=False)
    assert type(model).__module__ == "collide2d.engine.models.pymunk.model"  # model: pymunk's
    space = model.space
    assert len(space.bodies) == 30 and len(space.shapes) == 30 + 4
    body = list(space.bodies)[0]
    assert body.moment == math.inf and body.mass == 1.0
    assert tuple(body.velocity) == tuple(scenario.bodies.vel[0])
    rate, how = peers.pymunk_steps_per_second(30, 0.01, 1)
    assert rate > 0 and how in ("spatial hash", "bounding-box tree")
    assert pymunk.version
