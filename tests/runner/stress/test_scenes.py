"""runner.stress.scenes: every scene a valid start, quick ones shorter than full ones."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.engine.models import MODEL_NAMES
from collide2d.runner.scenario.generate import first_overlap
from collide2d.runner.stress.scenes import scenes


def test_scenes_are_valid_starts():
    names = []
    for quick in (True, False):
        for scene in scenes(quick):
            names.append(scene.name)
            b = scene.bodies
            assert b.pos.shape == b.size.shape == b.vel.shape == (b.n, 2)
            assert np.all(b.pos >= 0)
            assert np.all(b.pos + b.size <= [scene.world.width, scene.world.height])
            assert first_overlap(b.pos, b.size) is None, scene.name
            assert set(scene.models) <= set(MODEL_NAMES)
            assert set(scene.expect_stop) <= set(scene.models)
            if "paper" in scene.models:
                assert np.array_equal(b.pos, np.round(b.pos)), scene.name
    assert len(set(names)) == len(names) // 2


def test_quick_scenes_are_shorter_and_the_long_run_is_a_million_ticks():
    quick = {s.name: s for s in scenes(True)}
    full = {s.name: s for s in scenes(False)}
    assert quick.keys() == full.keys()
    assert all(quick[k].ticks <= full[k].ticks for k in quick)
    assert full["long_run"].ticks == 10**6
    assert full["far_from_origin"].world.width == 10**6
    masses = full["mass_ratios"].bodies.mass
    assert masses.min() == pytest.approx(1e-12) and masses.max() == pytest.approx(1e12)
