"""Which lane a run takes (runner.lanes): under `auto` interpreted until the ticks left would take
longer than compiling the kernels the run called (runner.compilecost), compiled from the start for
a huge mass ratio, what `--jit`, `[tool.collide2d] jit` and COLLIDE2D_JIT say, and the switch in
mid-run, with the same bytes in every case."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from collide2d.engine import jit
from collide2d.engine.models.exact import model as exact_model
from collide2d.engine.models.paper import model as paper_model
from collide2d.runner import compilecost, lanes
from collide2d.runner.command.main import main
from collide2d.runner.run import make_model, simulate
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
    # the runs here weigh interpreting against compiling as in a checkout without the kernels the
    # wheel ships, whose runs of these scenes would start compiled (the test of that sets them)
    monkeypatch.setattr(lanes.kernelstore, "holds_model", lambda model: False)
    lanes.set_mode(None)
    yield
    lanes.set_mode(None)


def _ready_in(monkeypatch, seconds: float, probe_s: float = 0.0) -> None:
    """Every run's kernels take `seconds` to get ready; decisions from `probe_s` on."""
    monkeypatch.setattr(lanes.RunLane, "ready_seconds", lambda self, share=1.0: seconds)
    monkeypatch.setattr(lanes, "PROBE_S", probe_s)
    monkeypatch.setattr(lanes, "MIN_SAVED_S", 0.0)


def test_a_run_goes_on_compiled_once_the_ticks_left_would_take_longer_than_compiling(monkeypatch):
    gas = loads(GAS)
    _ready_in(monkeypatch, 0.0)  # compiling costs nothing: the first look switches
    switched = simulate(gas)
    assert switched.summary["kernels"] == "interpreted, then compiled"
    _ready_in(monkeypatch, 1e9)  # compiling never pays: the whole run is interpreted
    assert simulate(gas).summary["kernels"] == "interpreted"
    lanes.set_mode("on")
    assert simulate(gas).summary["kernels"] == "compiled"


def test_a_run_whose_entry_kernels_this_process_has_needs_nothing_compiled(monkeypatch):
    # the kernels a run calls from Python have the ones they call compiled into them: once this
    # process has them (a sweep's worker after its first run), another run of the scene costs
    # nothing to go on compiled, though the kernels called under them never compiled on their own
    gas = loads(GAS)
    lanes.set_mode("on")
    simulate(gas)  # compiles (or loads) the paper model's kernels and the energy's
    lanes.set_mode(None)
    lane = lanes.RunLane(gas, 0)
    with lane.opened():
        make_model(gas).advance(1, False)
    entries = lane.called.entries
    assert paper_model._run in entries and paper_model._move in entries[paper_model._run]
    assert paper_model._move not in entries  # called by _run only
    assert jit.readiness(paper_model._run) == "compiled"
    assert lane.ready_seconds() == 0.0
    monkeypatch.setattr(lanes, "PROBE_S", 1e9)  # only a switch that costs nothing is taken early
    assert simulate(gas).summary["kernels"] == "interpreted, then compiled"


def _looked_at(monkeypatch, spent: float, cost: float, loaded: bool = True) -> bool:
    """Whether a run 10 ticks into its 100, `spent` s in, switches when its kernels take `cost` s
    to get ready."""
    lane = lanes.RunLane(loads(GAS), 0)
    assert lane.may_switch and not lane.compiled
    monkeypatch.setattr(lanes.RunLane, "ready_seconds", lambda self, share=1.0: cost)
    monkeypatch.setattr(compilecost.jit, "loaded", lambda: loaded)
    monkeypatch.setattr(lanes, "_clock", lambda: 100.0 + spent)
    monkeypatch.setattr(lanes, "_cpu", lambda: 100.0 + spent)  # a whole core
    lane.began, lane.began_cpu, lane.done = 100.0, 100.0, 10
    lane._decide()
    return lane.compiled


def test_the_switch_weighs_the_ticks_left_against_compiling(monkeypatch):
    # 90 ticks left at spent / 10 s a tick: 9 x spent interpreted, 9 x spent / 20 compiled,
    # 8.55 s saved for 1.0 s spent: a switch when that is past SWITCH_MARGIN (1.5) times the cost
    assert _looked_at(monkeypatch, spent=1.0, cost=5.6)
    assert not _looked_at(monkeypatch, spent=1.0, cost=5.8)
    # numba not loaded yet: a switch that cannot save its start is not looked at
    assert not _looked_at(monkeypatch, spent=0.05, cost=0.0, loaded=False)
    # kernels ready in this process: after the first chunk
    assert _looked_at(monkeypatch, spent=0.05, cost=0.0)
    # kernels to compile: measured for PROBE_S before paying more than was measured
    assert not _looked_at(monkeypatch, spent=0.05, cost=0.3)
    assert _looked_at(monkeypatch, spent=1.5 * lanes.PROBE_S, cost=0.3)
    # a tiny run never looks
    assert not _looked_at(monkeypatch, spent=0.004, cost=0.0)


def test_the_cost_counts_the_kernels_the_run_called_not_every_kernel(monkeypatch):
    seen = []

    def ready(self, share=1.0):
        seen.append({compilecost.name(k) for k in self.called})
        return 1e9

    monkeypatch.setattr(lanes.RunLane, "ready_seconds", ready)
    monkeypatch.setattr(lanes, "PROBE_S", 0.0)
    simulate(loads(GAS))  # the paper model
    called = seen[-1]
    assert "collide2d.engine.models.paper.model._run" in called
    assert not any(".models.exact." in k or ".models.stepped." in k for k in called)
    seen.clear()
    simulate(loads(GAS.replace("ticks: 100", "model: exact\nticks: 40")))
    assert "collide2d.engine.models.exact.model._run" in seen[-1]
    assert not any(".models.paper." in k for k in seen[-1])


def test_compiling_is_estimated_from_the_table_and_the_cache(monkeypatch, tmp_path):
    kernels = [paper_model._run, exact_model._run]
    table = compilecost.table()["kernels"]
    cold = sum(table[compilecost.name(k)] for k in kernels)
    monkeypatch.setattr(compilecost, "speed_factor", lambda: 2.0)
    monkeypatch.setattr(compilecost.jit, "loaded", lambda: False)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))  # empty: every kernel compiles
    monkeypatch.setenv("COLLIDE2D_KERNEL_STORE", "off")  # (none from the wheel's store)
    assert jit.cache_empty()
    estimate = compilecost.seconds(kernels)
    assert estimate == pytest.approx(compilecost.NUMBA_START_S + 2.0 * cold)
    assert estimate > compilecost.lower_bound(kernels)
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "k-1.py311.nbi").write_bytes(b"")  # something cached: look closer
    assert not jit.cache_empty()


def test_a_huge_mass_ratio_starts_compiled_a_small_one_interpreted():
    chain = loads(CHAIN)  # 1e10: about 314,000 bounces within a tick or two
    assert lanes.bursts_past_compiling(chain)
    assert simulate(chain).summary["kernels"] == "compiled"
    for ratio in ("2", "1e4"):  # about 4 and 314 bounces
        assert not lanes.bursts_past_compiling(loads(CHAIN.replace("mass: 1e10", f"mass: {ratio}")))


def test_a_run_whose_models_kernels_the_wheel_ships_starts_compiled_when_it_pays(monkeypatch):
    """The interpreted ticks of the run would take longer than starting numba and loading the
    stored kernels: the run starts compiled; a short small run, or a model the store lacks, does
    not."""
    monkeypatch.setattr(lanes, "TICK_INTERPRETED_S", 1e-3)  # GAS: 30 s; SMALL: 0.06 s
    monkeypatch.setattr(lanes.kernelstore, "holds_model", lambda model: model == "paper")
    gas, small = loads(GAS), loads(SMALL)
    assert lanes.RunLane(gas, 0).started_compiled and not lanes.RunLane(gas, 0).may_switch
    assert not lanes.RunLane(small, 0).started_compiled
    long = loads(SMALL.replace("ticks: 30", "ticks: 3000"))  # two objects, 6 s of ticks
    assert lanes.RunLane(long, 0).started_compiled
    assert not lanes.RunLane(loads(GAS + "model: exact\n"), 0).started_compiled
    monkeypatch.setattr(lanes.kernelstore, "holds_model", lambda model: False)
    assert not lanes.RunLane(gas, 0).started_compiled


def test_an_object_crossing_its_room_a_million_times_a_tick_starts_compiled():
    fast = (
        "version: 1\nworld: {width: 40, height: 40, fps: 1}\nmodel: exact\nticks: 3\n"
        "objects:\n  - {shape: box, size: 10, position: [15, 15], velocity: [%s, 0]}\n"
    )
    assert lanes.bursts_past_compiling(loads(fast % "1000000000"))  # 3e7 bounces in tick 1
    assert not lanes.bursts_past_compiling(loads(fast % "3000"))  # 100 bounces a tick


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


@pytest.mark.parametrize("after", [1, 3])  # the first look; a later one (a longer probe)
def test_a_run_that_switches_mid_run_gives_the_same_bytes(monkeypatch, after):
    scenario = loads(SMALL.replace("ticks: 30", "ticks: 60"))
    lanes.set_mode("on")
    compiled = simulate(scenario, keep_frames=range(0, 61, 5))
    lanes.set_mode("off")
    interpreted = simulate(scenario, keep_frames=range(0, 61, 5))
    lanes.set_mode(None)
    looks = []

    def ready(self, share=1.0):
        looks.append(self.done)
        return 0.0 if len(looks) >= after else 1e9

    monkeypatch.setattr(lanes.RunLane, "ready_seconds", ready)
    monkeypatch.setattr(lanes, "PROBE_S", 0.0)
    monkeypatch.setattr(lanes, "MIN_SAVED_S", 0.0)  # a run of microseconds looks too
    switched = simulate(scenario, keep_frames=range(0, 61, 5))
    assert switched.summary["kernels"] == "interpreted, then compiled"
    assert 0 < looks[-1] < 60  # switched mid-run, between two chunks
    assert compiled.summary["kernels"] == "compiled"
    assert interpreted.summary["kernels"] == "interpreted"
    for other in (compiled, interpreted):
        assert switched.events.tobytes() == other.events.tobytes()
        assert np.array_equal(switched.final_pos, other.final_pos)
        assert np.array_equal(switched.final_vel, other.final_vel)
        assert switched.frames.keys() == other.frames.keys()
        for k, frame in other.frames.items():
            assert np.array_equal(switched.frames[k], frame), k


def test_run_writes_the_same_files_under_each_mode_and_says_which_lane(tmp_path):
    path = tmp_path / "small.yaml"
    path.write_text(SMALL + "output: {frames: [0, 30], gif: true, events: true}\n")
    files = {}
    for mode in ("auto", "on", "off"):
        out = tmp_path / mode
        assert main(["run", str(path), "--out", str(out), "--quiet", "--jit", mode]) == 0
        folder = out / "small"
        kernels = json.loads((folder / "summary.json").read_text())["kernels"]
        # auto starts interpreted, and may go on compiled where this process has the kernels
        # ready and the machine is slow enough for that to pay
        if mode == "on":
            assert kernels == "compiled"
        else:
            switched = (mode, kernels) == ("auto", "interpreted, then compiled")
            assert kernels == "interpreted" or switched
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
    kernels = json.loads((tmp_path / "out/small/summary.json").read_text())["kernels"]
    assert kernels.startswith("interpreted")  # (then compiled, where that pays: test above)
    (tmp_path / "pyproject.toml").write_text('[tool.collide2d]\njit = "fast"\n')
    assert main(["run", "small.yaml", "--quiet"]) == 2


def test_a_cold_check_of_small_scenarios_never_starts_numba(tmp_path):
    # a CI job's first check: an empty kernel cache; the gases (300 boxes over 120 ticks, 40
    # circles under exact) would each take tens of seconds to compile and take about a second
    # interpreted, so nothing compiles and numba is never imported
    root = Path(__file__).resolve().parents[2]
    names = ["bench_dense_gas", "circles_gas", "tunnelling_1fps"]
    code = (
        "import sys\nfrom collide2d.runner.command.main import main\n"
        f"status = main(['check', '--root', {str(root)!r}, '--quiet', *{names!r}])\n"
        "print(status, 'numba' in sys.modules)"
    )
    env = dict(os.environ, COLLIDE2D_KERNEL_STORE="off", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    for name in ("COLLIDE2D_JIT", "NUMBA_DISABLE_JIT", "CI"):
        env.pop(name, None)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[-1].split() == ["0", "False"]
