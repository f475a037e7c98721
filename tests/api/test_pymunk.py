"""`model: pymunk` (the bench extra): a scenario run in pymunk through the model protocol."""

from __future__ import annotations

import pytest

import collide2d
from collide2d.testing import SCENES, problems

pytest.importorskip("pymunk")


def two_masses(model: str = "pymunk") -> dict:
    return {
        "version": 1,
        "world": {"width": 400, "height": 100, "fps": 60},
        "model": model,
        "ticks": 120,
        "objects": [
            {"shape": "box", "size": 10, "position": [100, 40], "velocity": [60, 0], "mass": 1},
            {"shape": "box", "size": 10, "position": [200, 40], "velocity": [0, 0], "mass": 3},
        ],
    }


def test_pymunk_meets_the_protocol():
    assert problems("pymunk", scenes=SCENES["box"][:2] + SCENES["circle"]) == []


def test_a_head_on_collision_of_masses_1_and_3_in_pymunk():
    result = collide2d.run(two_masses())
    # 1-d elastic: v1' = (m1 - m2) / (m1 + m2) v1 = -30, v2' = 2 m1 / (m1 + m2) v1 = 30
    assert result.final["vx"].tolist() == pytest.approx([-30.0, 30.0], abs=1e-9)
    # the gap of 90 px closes at 60 px/s: contact at 1.5 s, the end of tick 90
    assert [(e["tick"], e["type"], e["axis"]) for e in result.event_log()] == [(90, "pair", "x")]
    assert result.summary["model"] == "pymunk"


def test_pymunk_is_named_like_any_model_and_its_walls_bounce():
    scene = two_masses("exact")
    scene["objects"] = [{"shape": "box", "size": 10, "position": [380, 40], "velocity": [120, 0]}]
    result = collide2d.run(scene, model="pymunk")
    walls = [e for e in result.event_log() if e["type"] == "wall"]
    assert walls[0]["id"] == 0 and walls[0]["side"] == "right"
    assert result.final["vx"].tolist() == pytest.approx([-120.0])
