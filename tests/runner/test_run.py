"""The run driver (runner.run): what a run skips when a scene does not need it changes nothing.

No rasterising when no frame is asked for, only the frames asked for, no event records when no
log is asked for: each gives the same events, final state and pictures as doing all of it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from collide2d.engine.picture.raster import Renderer
from collide2d.runner.run import drive, simulate
from collide2d.runner.scenario.load import load

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"
# One scene per model, each with collisions within its ticks.
CASES = [
    ("paper_fifty_boxes.yaml", {"ticks": 60}),
    ("bench_dense_gas.yaml", {"ticks": 30, "model": "stepped"}),
    ("bench_fast_small.yaml", {"ticks": 30, "model": "exact"}),
]


def _scene(name, overrides):
    return load(SCENARIOS / name, overrides=overrides)


@pytest.mark.parametrize("name, overrides", CASES)
def test_frames_asked_for_are_those_of_drawing_every_frame(name, overrides):
    scenario = _scene(name, overrides)
    ticks = scenario.ticks
    every = simulate(scenario, keep_frames=range(ticks + 1))
    few = simulate(scenario, keep_frames=[0, 7, ticks])
    none = simulate(scenario, keep_frames=())
    assert sorted(few.frames) == [0, 7, ticks] and none.frames == {}
    for k in (0, 7, ticks):
        assert np.array_equal(few.frames[k], every.frames[k])
    for other in (few, none):
        assert other.events.tobytes() == every.events.tobytes()
        assert other.final_pos.tobytes() == every.final_pos.tobytes()
        assert other.final_vel.tobytes() == every.final_vel.tobytes()
    assert len(every.events) > 0


@pytest.mark.parametrize("name, overrides", CASES)
def test_a_frame_is_the_picture_of_the_state_at_its_tick(name, overrides):
    # the frames drive hands out are those of rendering the model's state at that tick afresh
    scenario = _scene(name, overrides)
    seen = {}
    drive(scenario, frames=[5, 9], on_frame=lambda k, idx: seen.__setitem__(k, idx.copy()))
    model = simulate(scenario.__class__(**{**scenario.__dict__, "ticks": 9}), log_events=False)
    fresh = Renderer(scenario.world, scenario.bodies).draw_full(model.final_pos)
    assert np.array_equal(seen[9], fresh)
    assert set(seen) == {5, 9}


@pytest.mark.parametrize("name, overrides", CASES)
def test_no_log_gives_the_same_state_and_no_events(name, overrides):
    scenario = _scene(name, overrides)
    logged = simulate(scenario, log_events=True)
    quiet = simulate(scenario, log_events=False)
    assert len(quiet.events) == 0 and len(logged.events) > 0
    assert quiet.final_pos.tobytes() == logged.final_pos.tobytes()
    assert quiet.final_vel.tobytes() == logged.final_vel.tobytes()
    # the counts are the same, logged or not, and they are the log's
    kinds = np.bincount(logged.events["type"], minlength=2)
    assert quiet.summary["events"] == logged.summary["events"]
    assert logged.summary["events"] == {"wall": int(kinds[0]), "pair": int(kinds[1])}
    assert kinds.min() > 0


def test_no_frames_means_no_renderer(monkeypatch):
    # with no frame asked for, nothing is rasterised at all
    import collide2d.runner.run as run_module

    def refuse(*args, **kwargs):
        raise AssertionError("a renderer was made for a run that asked for no frame")

    monkeypatch.setattr(run_module, "Renderer", refuse)
    scenario = _scene(*CASES[0])
    result = simulate(scenario, keep_frames=())
    assert result.frames == {} and len(result.events) > 0
