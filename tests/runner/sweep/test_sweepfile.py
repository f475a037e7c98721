"""Sweep files: the matrix read from YAML with located errors, and the command line's refusals
(bad input exits 2 with nothing written; no Dask says how to install it)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from collide2d.runner.command.main import main
from collide2d.runner.scenario.load import ScenarioError
from collide2d.runner.sweep import sweepfile
from collide2d.runner.sweep.cli import LOCAL_WORKERS_PER_CORE

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"
FIFTY = SCENARIOS / "paper_fifty_boxes.yaml"


def _file(tmp_path, text: str) -> str:
    path = tmp_path / "matrix.yaml"
    path.write_text(text)
    return str(path)


def test_a_sweep_file_gives_scenarios_axes_and_seeds(tmp_path):
    (tmp_path / "scn").mkdir()
    (tmp_path / "scn" / "a.yaml").write_text(FIFTY.read_text())
    path = _file(
        tmp_path,
        "sweep: 1\nscenarios: [scn/a.yaml]\nset:\n  model: [paper, exact]\n  fps: 30\n"
        "  generate.0.size: [[10, 10], 12]\nseeds: [1-3, 9]\n",
    )
    assert sweepfile.is_sweep_file(path) and not sweepfile.is_sweep_file(str(FIFTY))
    scenarios, axes, seeds = sweepfile.read(path)
    assert scenarios == [str(tmp_path / "scn" / "a.yaml")]
    assert [(a.key, a.texts) for a in axes] == [
        ("model", ("paper", "exact")),
        ("fps", ("30",)),
        ("generate.0.size", ("[10, 10]", "12")),
    ]
    assert seeds == (1, 2, 3, 9)


@pytest.mark.parametrize(
    "text, where, said",
    [
        ("sweep: 2\nscenarios: [x.yaml]\n", "1:8", "sweep must be 1"),
        ("sweep: 1\n", "1:1", "needs 'scenarios:'"),
        ("sweep: 1\nscenarios: [nope.yaml]\n", "2:13", "no scenario file 'nope.yaml'"),
        (
            "sweep: 1\nscenario: []\n",
            "2:1",
            "unknown key 'scenario' in the sweep file; did you mean 'scenarios'?",
        ),
        (f"sweep: 1\nscenarios: [{FIFTY}]\nset: {{world..x: [1]}}\n", "3:7", "not a key to sweep"),
        (f"sweep: 1\nscenarios: [{FIFTY}]\nset: {{fps: []}}\n", "3:12", "set fps has no values"),
        (f"sweep: 1\nscenarios: [{FIFTY}]\nseeds: 9-2\n", "3:8", "seeds 9-2"),
    ],
)
def test_sweep_file_errors_are_located(tmp_path, text, where, said):
    path = _file(tmp_path, text)
    with pytest.raises(ScenarioError) as err:
        sweepfile.read(path)
    assert str(err.value).startswith(f"{path}:{where}: error: ")
    assert said in str(err.value)


def test_bad_input_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["sweep", str(FIFTY), "--set", "world.width=0", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{FIFTY}:6:") and "in the sweep run world.width=0: " in err
    assert main(["sweep", str(FIFTY), "--set", "fps", "--out", str(out)]) == 2
    assert "collide2d: error: --set fps: expected KEY=V1,V2" in capsys.readouterr().err
    assert main(["sweep", str(tmp_path / "none.yaml"), "--out", str(out)]) == 2
    assert "none.yaml: no such scenario file" in capsys.readouterr().err
    sweep = _file(tmp_path, f"sweep: 1\nscenarios: [{FIFTY}]\n")
    assert main(["sweep", sweep, str(FIFTY), "--out", str(out)]) == 2
    assert "give one sweep file on its own" in capsys.readouterr().err
    assert not out.exists()
    out.mkdir()
    (out / "sweep").symlink_to(tmp_path)
    assert main(["sweep", str(FIFTY), "--out", str(out)]) == 2
    assert "sweep is a symbolic link" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["matrix.yaml", "out"]


@pytest.mark.parametrize("command", ["sweep", "check"])
def test_more_local_workers_than_the_machine_can_hold_are_refused_at_once(tmp_path, capsys,
                                                                         command):
    # a huge --workers would have the embedded cluster start that many processes
    out = tmp_path / "out"
    cap = LOCAL_WORKERS_PER_CORE * (os.cpu_count() or 1)
    for workers in (str(cap + 1), "99999999999999999999"):
        with pytest.raises(SystemExit) as done:
            main([command, str(FIFTY), "--workers", workers, "--out", str(out)])
        assert done.value.code == 2
        err = capsys.readouterr().err
        assert f"argument --workers: {int(workers):,} worker processes" in err
        assert f"(at most {cap}); for more, start a cluster" in err
    assert not out.exists()


def test_without_dask_sweep_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed fails
    out = tmp_path / "out"
    assert main(["sweep", str(FIFTY), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (
        "collide2d: error: collide2d sweep runs on Dask, which is not installed; install it "
        'with: pip install "collide2d[dask]"\n'
    )
    assert main(["check", "fig2_case1", "--workers", "2", "--root", str(SCENARIOS.parent)]) == 2
    assert 'pip install "collide2d[dask]"' in capsys.readouterr().err
    assert not out.exists()


def test_the_example_sweep_file_expands_to_its_runs():
    from .planned import expand

    example = SCENARIOS.parent / "sweeps" / "paper_fps.yaml"
    scenarios, axes, seeds = sweepfile.read(str(example))
    runs = expand(scenarios, axes, seeds)
    assert len(runs) == 90
    assert {(r.params["model"], r.params["fps"]) for r in runs} == {
        (m, f) for m in ("paper", "stepped", "exact") for f in ("10", "30", "60")
    }
    assert {r.scenario.world.fps for r in runs if r.params["fps"] == "30"} == {30}
