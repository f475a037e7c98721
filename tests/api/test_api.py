"""The public Python API as a user's tests would use it: only `import collide2d`.

Each test proves behaviour through `collide2d.load`, `collide2d.run` and `collide2d.check`: the
paper's tunnelling at 1 fps and its absence under the exact model, the elastic exchange of equal
masses, frames as pictures, the output folder, goldens blessed and checked from Python.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

import collide2d

HERE = os.path.dirname(__file__)


def two_boxes(model: str = "paper", fps: int = 1, ticks: int = 12) -> dict:
    """The paper's section III.A as a dict: two 10x10 boxes closing at 10 px/s each."""
    return {
        "version": 1,
        "name": "two-boxes",
        "world": {"width": 320, "height": 240, "fps": fps},
        "model": model,
        "ticks": ticks,
        "objects": [
            {"name": "left", "shape": "box", "size": 10, "position": [100, 115]}
            | {"velocity": [10, 0]},
            {"name": "right", "shape": "box", "size": 10, "position": [210, 115]}
            | {"velocity": [-10, 0]},
        ],
        "output": {"frames": "none", "gif": False, "events": True},
        "golden": {"frames": [0, 6, ticks]},
    }


def test_a_dict_loads_as_its_yaml_would():
    scenario = collide2d.load(two_boxes())
    assert scenario.name == "two-boxes"
    assert scenario.model == "paper"
    assert scenario.ticks == 12
    assert scenario.names == ("left", "right")


def test_a_refused_dict_names_the_line_of_its_yaml():
    bad = two_boxes()
    bad["world"]["fps"] = 0
    with pytest.raises(collide2d.ScenarioError) as info:
        collide2d.load(bad)
    assert ": error: world.fps" in str(info.value)
    assert info.value.line > 1


def test_at_one_fps_the_paper_model_tunnels_and_the_exact_model_does_not():
    paper = collide2d.run(two_boxes())
    assert len(paper.events) == 0  # passed through each other: no collision at all
    assert paper.final["x"].tolist() == [220.0, 90.0]
    exact = collide2d.run(two_boxes(), model="exact")
    pairs = [e for e in exact.event_log() if e["type"] == "pair"]
    assert [(e["a"], e["b"], e["t"]) for e in pairs] == [(0, 1, 5.0)]


def test_equal_masses_exchange_their_velocities():
    result = collide2d.run(two_boxes("exact", fps=10, ticks=60))
    first = result.events[result.events["type"] == 1][0]
    assert (first["a"], first["b"]) == (0, 1)
    # after the one collision and the walls, each box moves at the other's former speed
    assert sorted(np.abs(result.final["vx"]).tolist()) == [10.0, 10.0]
    assert result.velocities.shape == (2, 2)
    assert result.final["name"] == ("left", "right")


def test_run_takes_a_path_and_keeps_the_frames_asked_for():
    path = os.path.join(HERE, "..", "..", "scenarios", "tunnelling_1fps.yaml")
    result = collide2d.run(path, frames=[0, 5])
    assert sorted(result.frames) == [0, 5]
    picture = result.frames[5]
    assert picture.shape == (240, 320, 3) and picture.dtype == np.uint8
    # at tick 5 the boxes touch: the red one's right edge meets the lime one's left edge
    row = picture[120]
    red = np.flatnonzero((row == [255, 0, 0]).all(axis=1))
    lime = np.flatnonzero((row == [0, 255, 0]).all(axis=1))
    assert red.max() + 1 == lime.min()
    last = collide2d.run(path, frames="last")
    assert list(last.frames) == [12]


def test_the_same_scenario_gives_the_same_bytes():
    a = collide2d.run(two_boxes("exact", fps=10, ticks=60))
    b = collide2d.run(two_boxes("exact", fps=10, ticks=60))
    assert a.events.tobytes() == b.events.tobytes()
    assert a.positions.tobytes() == b.positions.tobytes()


def test_run_into_a_folder_writes_what_the_command_writes(tmp_path):
    scenario = collide2d.load(two_boxes("exact"))
    result = collide2d.run(scenario, out=tmp_path)
    assert result.folder == tmp_path / "two-boxes"
    files = sorted(p.name for p in result.folder.iterdir())
    assert files == ["events.jsonl", "final.csv", "summary.json"]
    header, *rows = (result.folder / "final.csv").read_text().splitlines()
    assert header == "id,x,y,vx,vy,name"
    assert rows[0].split(",")[1:3] == [str(int(x)) for x in result.positions[0]]
    in_memory = collide2d.run(scenario)
    assert in_memory.positions.tolist() == result.positions.tolist()
    assert result.summary["events"] == in_memory.summary["events"]


def test_a_scenario_can_be_run_again_under_another_model():
    scenario = collide2d.load(two_boxes())
    assert collide2d.run(scenario, model="stepped").scenario.model == "stepped"
    assert collide2d.run(scenario).scenario.model == "paper"


def test_frames_out_of_the_run_are_refused():
    with pytest.raises(ValueError, match="frame 13"):
        collide2d.run(two_boxes(), frames=[13])


def test_bless_then_check_from_python(tmp_path, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    (tmp_path / "scenarios").mkdir()
    path = tmp_path / "scenarios" / "two-boxes.yaml"
    import yaml

    path.write_text(yaml.safe_dump(two_boxes("exact")))
    first = collide2d.check(root=tmp_path)
    assert not first.ok and first["two-boxes"].status == "missing"
    blessed = collide2d.check(root=tmp_path, bless=True)
    assert blessed.ok and blessed["two-boxes"].status == "created"
    assert collide2d.check(root=tmp_path).ok
    assert collide2d.check("two-boxes", root=tmp_path).ok
    # the scene changes: the check fails and says where
    changed = two_boxes("exact")
    changed["objects"][1]["velocity"] = [-20, 0]
    path.write_text(yaml.safe_dump(changed))
    found = collide2d.check(path, root=tmp_path)
    assert not found.ok
    assert found["two-boxes"].status == "failed"
    assert any("event" in p for p in found["two-boxes"].problems)


def test_bless_is_refused_in_ci(tmp_path, monkeypatch):
    (tmp_path / "scenarios").mkdir()
    monkeypatch.setenv("CI", "true")
    with pytest.raises(Exception, match="CI"):
        collide2d.check(two_boxes(), root=tmp_path, bless=True)
    assert not (tmp_path / "goldens").exists()
