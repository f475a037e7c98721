"""Sweeps in bounded memory and in a folder of their own: every run checked before it is sent but
none kept loaded, a seed's objects drawn again exactly as the loader draws them, OUT/sweep/ locked
and swapped in whole, the project's `out` setting, and --scheduler checked at the option."""

from __future__ import annotations

import gc
import socket
import time
from pathlib import Path

import numpy as np
import pytest

from collide2d.runner.command.main import main
from collide2d.runner.output import folder
from collide2d.runner.scenario.load import Scenario, ScenarioError, loads
from collide2d.runner.sweep import cluster, driver
from collide2d.runner.sweep.matrix import parse_set

from .planned import CRAMPED

pytest.importorskip("distributed")

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"
FIFTY = str(SCENARIOS / "paper_fifty_boxes.yaml")


def _live_scenarios() -> int:
    gc.collect()
    # type(), not isinstance(): a dead weak proxy among the objects raises on isinstance
    return sum(type(o) is Scenario for o in gc.get_objects())


def test_a_sweep_holds_no_runs_scenarios_before_or_while_it_runs(tmp_path, monkeypatch):
    seen = []
    connect, run_all = cluster.connect, cluster.run_all
    before = _live_scenarios()  # what other tests of this process hold

    def counting_connect(*args, **kwargs):
        seen.append(("start", _live_scenarios()))
        return connect(*args, **kwargs)

    def counting_run_all(client, fn, items, on_result, **kwargs):
        def counted(i, value, error):
            seen.append(("running", _live_scenarios()))
            on_result(i, value, error)

        return run_all(client, fn, items, counted, **kwargs)

    monkeypatch.setattr(cluster, "connect", counting_connect)
    monkeypatch.setattr(cluster, "run_all", counting_run_all)
    out = tmp_path / "out"
    args = ["sweep", FIFTY, "--set", "ticks=1", "--seeds", "1-1000", "--workers", "1"]
    assert main([*args, "--out", str(out), "--quiet"]) == 0
    rows = (out / "sweep" / "results.csv").read_text().splitlines()
    assert len(rows) == 1001 and rows[1].startswith("paper_fifty_boxes,1,paper,")
    # 1,000 runs in 32 tasks: before the first starts this process holds no run's scenario, and
    # while they run only those of the tasks in flight or in Dask's short message logs (copies
    # of the one scenario the runs share), never one per run or per task
    assert seen[0] == ("start", before), seen[:3]
    running = [n - before for what, n in seen if what == "running"]
    in_flight = driver.WINDOW_PER_THREAD * 1 + cluster.MESSAGES_KEPT
    assert len(running) == 32 and max(running) <= 1 + in_flight, running


def test_a_seed_is_drawn_again_exactly_as_the_loader_draws_it_and_refused_alike(tmp_path):
    from .planned import expand

    path = tmp_path / "cramped.yaml"
    path.write_text(CRAMPED)
    loaded = expand([FIFTY], [parse_set("model=paper,exact")], (1, 2, 3))
    text = Path(FIFTY).read_text()
    for run in loaded:
        seed = run.params["seed"]
        edited = text.replace("seed: 4", f"seed: {seed}").replace(
            "model: paper", f"model: {run.params['model']}"
        )
        want = loads(edited, FIFTY)
        np.testing.assert_array_equal(run.scenario.bodies.pos, want.bodies.pos)
        np.testing.assert_array_equal(run.scenario.bodies.vel, want.bodies.vel)
    # seed 4 loads; seed 5 is refused by the check of its drawing alone, before its run is sent,
    # with the loader's located message naming the run
    with pytest.raises(ScenarioError) as err:
        expand([str(path)], [], (4, 5))
    said = str(err.value)
    assert said.startswith(f"{path}:6:5: error: in the sweep run seed=5: generate[0]: cannot")
    assert [r.params["seed"] for r in expand([str(path)], [], (4, 29, 34))] == ["4", "29", "34"]


def test_a_second_sweep_into_the_same_folder_is_refused_and_the_first_stays(tmp_path, capsys):
    out = tmp_path / "out"
    args = ["sweep", FIFTY, "--set", "ticks=1", "--seeds", "1-2", "--workers", "1", "--quiet"]
    assert main([*args, "--out", str(out)]) == 0
    first = (out / "sweep" / "results.csv").read_text()
    with folder.RunLock(out, "sweep"):  # a sweep into `out` is running
        assert main([*args, "--seeds", "1-3", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{out / 'sweep'} is being written by process" in err
    assert (out / "sweep" / "results.csv").read_text() == first
    # OUT/sweep is replaced whole: a file no sweep writes is never deleted, the sweep refused
    (out / "sweep" / "notes.txt").write_text("mine")
    assert main([*args, "--out", str(out)]) == 2
    assert "holds files a sweep does not write (notes.txt)" in capsys.readouterr().err
    (out / "sweep" / "notes.txt").unlink()
    assert main([*args, "--seeds", "1-3", "--out", str(out)]) == 0
    assert len((out / "sweep" / "results.csv").read_text().splitlines()) == 4
    assert sorted(p.name for p in out.iterdir()) == ["sweep"]  # no lock or staging left


def test_sweep_writes_to_the_projects_out_folder(tmp_path, monkeypatch):
    (tmp_path / "pyproject.toml").write_text('[tool.collide2d]\nout = "results"\n')
    monkeypatch.chdir(tmp_path)
    args = ["sweep", FIFTY, "--set", "ticks=1", "--workers", "1", "--quiet"]
    assert main(args) == 0
    assert (tmp_path / "results" / "sweep" / "results.csv").is_file()
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "address", ["localhost", "tcp://host", "http://127.0.0.1:8786", "tcp://h:0", "tcp://h:99999"]
)
def test_a_malformed_scheduler_address_is_refused_at_the_option(address, tmp_path, capsys):
    with pytest.raises(SystemExit) as done:
        main(["sweep", str(tmp_path / "none.yaml"), "--scheduler", address])
    assert done.value.code == 2
    assert f"argument --scheduler: {address!r}" in capsys.readouterr().err


def test_a_scheduler_that_does_not_answer_fails_within_seconds_naming_it(tmp_path, capsys):
    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    out = tmp_path / "out"
    began = time.monotonic()
    assert (
        main(["sweep", FIFTY, "--set", "ticks=1", "--scheduler", address, "--out", str(out)]) == 2
    )
    assert time.monotonic() - began < 5
    err = capsys.readouterr().err
    assert f"collide2d: error: no Dask scheduler answered at {address} within" in err
    assert not out.exists()
