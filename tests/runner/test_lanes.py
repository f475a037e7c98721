"""Which lane a run takes (runner.lanes): interpreted for a small run, compiled for a big one or a
huge mass ratio, what `--jit`, `[tool.collide2d] jit` and COLLIDE2D_JIT say, and the switch of a
run that outgrows its interpreted budget, with the same bytes in every case."""

from __future__ import annotations

import json

import numpy as np
import pytest

from collide2d.runner import lanes
from collide2d.runner.command.main import main
from collide2d.runner.run import simulate
from collide2d.runner.scenario.load import loads

SMALL = """version: 1
name: small
world: {width: 80, height: 60, fps: 10}
ticks: 30
objects:
  - {shape: box, size: 6, position: [5, 5], velocity: [30, 10]}
  - {shape: box, size: 6, position: [60, 5], velocity: [-30, 10]}
"""

GAS = """version: 1
name: gas
world: {width: 400, height: 300, fps: 10}
ticks: 100
generate:
  - {count: 300, shape: box, size: 6, speed: 20, seed: 2}
"""

CHAIN = """version: 1
name: chain
world: {width: 400, height: 40, fps: 1}
model: exact
ticks: 5
objects:
  - {shape: box, size: 10, position: [50, 15], velocity: [0, 0], mass: 1}
  - {shape: box, size: 10, position: [100, 15], velocity: [-10, 0], mass: 1e10}
"""


@pytest.fixture(autouse=True)
def auto_mode(monkeypatch):
    monkeypatch.delenv("COLLIDE2D_JIT", raising=False)
    monkeypatch.delenv("NUMBA_DISABLE_JIT", raising=False)
    lanes.set_mode(None)
    yield
    lanes.set_mode(None)


def test_a_small_run_is_interpreted_and_a_big_one_compiled():
    small, gas = loads(SMALL), loads(GAS)
    assert lanes.work(small, 31) < lanes.INTERPRETED_MAX_WORK < lanes.work(gas, 0)
    assert simulate(small).summary["kernels"] == "interpreted"
    assert simulate(gas).summary["kernels"] == "compiled"


def test_the_exact_model_compiles_for_a_mass_ratio_that_makes_many_bounces():
    chain = loads(CHAIN)  # 1e10: about 314,000 bounces
    assert lanes.compiled_for_run(chain, 0)
    assert simulate(chain).summary["kernels"] == "compiled"
    for ratio in ("2", "1e4"):  # about 4 and 314 bounces
        assert not lanes.compiled_for_run(loads(CHAIN.replace("mass: 1e10", f"mass: {ratio}")), 0)


def test_the_mode_comes_from_the_flag_then_the_environment(monkeypatch):
    small, gas = loads(SMALL), loads(GAS)
    monkeypatch.setenv("COLLIDE2D_JIT", "on")
    assert lanes.mode() == "on" and lanes.compiled_for_run(small, 0)
    monkeypatch.setenv("COLLIDE2D_JIT", "0")
    assert lanes.mode() == "off" and not lanes.compiled_for_run(gas, 0)
    lanes.set_mode("on")  # the command line wins
    assert lanes.compiled_for_run(small, 0)
    with pytest.raises(ValueError, match="expected one of auto, on, off"):
        lanes.set_mode("sometimes")


def test_a_run_over_its_interpreted_budget_goes_on_compiled_with_the_same_bytes(monkeypatch):
    scenario = loads(SMALL.replace("ticks: 30", "ticks: 60"))
    lanes.set_mode("on")
    compiled = simulate(scenario, keep_frames=range(0, 61, 5))
    lanes.set_mode(None)
    monkeypatch.setattr(lanes, "INTERPRETED_BUDGET_S", 0.0)  # switch after the first call
    monkeypatch.setattr(lanes, "INTERPRETED_LEFT_S", 0.0)
    switched = simulate(scenario, keep_frames=range(0, 61, 5))
    assert switched.summary["kernels"] == "interpreted, then compiled"
    assert compiled.summary["kernels"] == "compiled"
    assert switched.events.tobytes() == compiled.events.tobytes()
    assert np.array_equal(switched.final_pos, compiled.final_pos)
    assert switched.frames.keys() == compiled.frames.keys()
    for k, frame in compiled.frames.items():
        assert np.array_equal(switched.frames[k], frame), k
    monkeypatch.setattr(lanes, "INTERPRETED_LEFT_S", 1e9)  # never worth it: stays interpreted
    assert simulate(scenario).summary["kernels"] == "interpreted"


def test_run_writes_the_same_files_under_each_mode_and_says_which_lane(tmp_path):
    path = tmp_path / "small.yaml"
    path.write_text(SMALL + "output: {frames: [0, 30], gif: true, events: true}\n")
    files = {}
    for mode in ("auto", "on", "off"):
        out = tmp_path / mode
        assert main(["run", str(path), "--out", str(out), "--quiet", "--jit", mode]) == 0
        folder = out / "small"
        summary = json.loads((folder / "summary.json").read_text())
        assert summary["kernels"] == ("compiled" if mode == "on" else "interpreted")
        files[mode] = {
            p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*"))
            if p.is_file() and p.name != "summary.json"
        }
    assert files["auto"] == files["on"] == files["off"]
    assert "animation.gif" in files["on"] and "events.jsonl" in files["on"]


def test_the_projects_table_sets_the_mode(tmp_path, monkeypatch):
    (tmp_path / "pyproject.toml").write_text('[tool.collide2d]\njit = "on"\n')
    (tmp_path / "small.yaml").write_text(SMALL)
    monkeypatch.chdir(tmp_path)
    assert main(["run", "small.yaml", "--quiet"]) == 0
    assert json.loads((tmp_path / "out/small/summary.json").read_text())["kernels"] == "compiled"
    assert main(["run", "small.yaml", "--quiet", "--jit", "auto"]) == 0  # the command line wins
    assert json.loads((tmp_path / "out/small/summary.json").read_text())["kernels"] == (
        "interpreted"
    )
    (tmp_path / "pyproject.toml").write_text('[tool.collide2d]\njit = "fast"\n')
    assert main(["run", "small.yaml", "--quiet"]) == 2
