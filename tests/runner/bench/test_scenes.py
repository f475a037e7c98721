"""runner.bench.scenes: the standard scene's world and its generated boxes."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.runner.bench import scenes
from collide2d.runner.scenario.load import loads


@pytest.mark.parametrize("n", [50, 1_000, 10_000, 100_000])
def test_standard_world_is_4_to_3_with_boxes_on_5_percent(n):
    width, height = scenes.standard_world(n)
    assert abs(width / height - 4 / 3) < 2 / height
    covered = n * 100 / (width * height)
    assert abs(covered - 0.05) < 0.05 * 2 / min(width, height) * 2


def test_standard_world_at_100k_fits_the_default_side_limit():
    assert scenes.standard_world(100_000) == (16330, 12248)


def test_standard_scene_is_seeded_boxes_at_10_to_100_px_per_s():
    a = loads(scenes.standard_scene(200, "stepped"))
    b = loads(scenes.standard_scene(200, "stepped"))
    assert a.bodies.n == 200 and a.world.fps == 60
    assert np.array_equal(a.bodies.pos, b.bodies.pos) and np.array_equal(a.bodies.vel, b.bodies.vel)
    speed = np.hypot(*a.bodies.vel.T)
    assert speed.min() >= 10 and speed.max() <= 100
    assert (a.bodies.size == 10).all()
    paper = loads(scenes.standard_scene(200, "paper"))
    assert np.array_equal(paper.bodies.vel, np.floor(paper.bodies.vel))  # whole px/s
