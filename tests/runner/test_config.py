"""Tests of runner/command/settings.py and `collide2d config`: the [tool.collide2d] table, its
checks, and the precedence command line > scenario > table > defaults."""

from __future__ import annotations

from pathlib import Path

import pytest

from collide2d.runner.command import settings
from collide2d.runner.command.main import main
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import ScenarioError, loads

SCENARIO = "version: 1\nticks: 3\nobjects:\n  - {shape: box, size: 4, position: [1, 1]}\n"


def project(tmp_path: Path, table: str) -> Path:
    (tmp_path / "pyproject.toml").write_text(f'[project]\nname = "demo"\n\n{table}')
    return tmp_path


def test_the_table_sets_folders_limits_and_model_defaults_with_their_source(tmp_path):
    root = project(
        tmp_path,
        '[tool.collide2d]\nscenarios = "cases"\ngoldens = "expected"\n'
        "[tool.collide2d.limits]\nmax_objects = 7\n"
        '[tool.collide2d.model]\nkind = "stepped"\nsubsteps = 4\n',
    )
    deep = root / "a" / "b"
    deep.mkdir(parents=True)
    found = settings.find(deep)
    assert found.root == root.resolve() and found.file == root.resolve() / "pyproject.toml"
    assert found.scenarios == root.resolve() / "cases"
    assert found.goldens == root.resolve() / "expected"
    assert found.folder("report") == root.resolve() / "report"
    assert found.settings["scenarios"].source.endswith("pyproject.toml [tool.collide2d]")
    assert found.settings["report"].source == settings.DEFAULT
    assert found.limits() == Limits(max_objects=7)
    assert found.limits({"max_objects": 9}).max_objects == 9  # the command line wins
    assert found.model_defaults() == {"kind": "stepped", "substeps": 4}


def test_a_project_without_the_table_keeps_the_defaults(tmp_path):
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "x"\n')
    (tmp_path / "scenarios").mkdir()
    found = settings.find(tmp_path)
    assert found.file is None and found.root == tmp_path.resolve()
    assert found.value("goldens") == "goldens" and found.load_options() == {}
    assert not settings.has_table(tmp_path / "pyproject.toml")


@pytest.mark.parametrize(
    "table, line, says",
    [
        (
            '[tool.collide2d]\nscenario = "s"\n',
            5,
            "has no setting 'scenario'; did you mean 'scenarios'?",
        ),
        (
            "[tool.collide2d]\n[tool.collide2d.limits]\nmax_object = 3\n",
            6,
            "did you mean 'max_objects'?",
        ),
        (
            "[tool.collide2d]\n[tool.collide2d.model]\nsubsteps = 0\n",
            6,
            "model.substeps must be a whole number >= 1",
        ),
        ('[tool.collide2d]\n[tool.collide2d.model]\ngeometry = "round"\n', 6, "one of box | exact"),
        ('[tool.collide2d]\ngoldens = "../elsewhere"\n', 5, "leads outside the project folder"),
        ("[tool.collide2d\n", 4, "not valid TOML"),
    ],
)
def test_a_bad_table_is_refused_at_its_line(tmp_path, table, line, says):
    project(tmp_path, table)
    with pytest.raises(settings.ConfigError) as info:
        settings.find(tmp_path)
    text = str(info.value)
    assert text.startswith(f"{tmp_path / 'pyproject.toml'}:{line}:") and says in text


def test_precedence_command_line_then_scenario_then_table_then_defaults():
    table = {"kind": "stepped", "substeps": 4, "geometry": "exact"}
    assert loads(SCENARIO).model == "paper"  # defaults
    got = loads(SCENARIO, defaults=table)  # the table
    assert (got.model, got.substeps, got.geometry) == ("stepped", 4, "exact")
    own = SCENARIO + "model: {kind: stepped, substeps: 2}\n"  # the scenario over the table
    got = loads(own, defaults=table)
    assert (got.model, got.substeps, got.geometry) == ("stepped", 2, "exact")
    got = loads(own, defaults=table, overrides={"model": "paper"})  # the command line over all
    assert (got.model, got.geometry) == ("paper", "box")
    cap = {"max_events_per_tick": 77}
    assert loads(SCENARIO + "model: exact\n", defaults=cap).max_events_per_tick == 77
    assert (
        loads(SCENARIO + "model: exact\n", defaults=cap, overrides=cap | {"max_events_per_tick": 5})
    ).max_events_per_tick == 5
    assert loads(SCENARIO, defaults=cap).model == "paper"  # a setting the model does not take


def test_config_command_prints_each_value_and_its_source(tmp_path, monkeypatch, capsys):
    project(tmp_path, '[tool.collide2d]\nout = "runs"\n[tool.collide2d.limits]\nmax_ticks = 500\n')
    monkeypatch.chdir(tmp_path)
    assert main(["config", "--max-objects", "12"]) == 0
    rows = {line.split()[0]: line for line in capsys.readouterr().out.splitlines()}
    assert rows["out"].split()[1] == "runs" and rows["out"].endswith("[tool.collide2d]")
    assert rows["limits.max_ticks"].split()[1] == "500"
    assert rows["limits.max_objects"].split()[1] == "12"
    assert rows["limits.max_objects"].endswith("command line")
    assert rows["goldens"].endswith("default")


def test_run_and_validate_take_the_tables_limits_and_out_folder(tmp_path, monkeypatch, capsys):
    project(tmp_path, '[tool.collide2d]\nout = "runs"\n[tool.collide2d.limits]\nmax_ticks = 2\n')
    (tmp_path / "s.yaml").write_text(SCENARIO)
    monkeypatch.chdir(tmp_path)
    assert main(["validate", "s.yaml"]) == 2
    assert "past the limit of 2 ticks" in capsys.readouterr().err
    assert main(["run", "s.yaml", "--max-ticks", "3", "--quiet"]) == 0  # the command line wins
    assert (tmp_path / "runs" / "s" / "final.csv").is_file()


def test_the_tables_threads_are_put_in_force_unless_the_command_line_names_some(tmp_path):
    import argparse

    from collide2d.engine import jit, threads
    from collide2d.runner.command.options import apply_threads

    found = settings.find(project(tmp_path, "[tool.collide2d]\nthreads = 1\n"))
    jit.numba_module()  # the count is put in force once numba is loaded: load it first
    try:
        apply_threads(argparse.Namespace(threads=None), found)
        assert threads.threads() == 1
        everything = threads.available()
        apply_threads(argparse.Namespace(threads=everything), found)
        assert threads.threads() == everything
        apply_threads(argparse.Namespace(threads=None), None)
        assert threads.threads() == everything
    finally:
        threads.set_threads(None)


@pytest.mark.parametrize(
    "table, line, says",
    [
        ('goldens = "."\n', 5, "goldens = '.' is the project folder"),
        ('scenarios = "./"\n', 5, "scenarios = './' is the project folder"),
        ('report = "goldens/r"\n', 5, "report = 'goldens/r' is inside the goldens folder goldens/"),
        ('out = "scenarios"\n', 5, "out = 'scenarios' is the scenarios folder scenarios/"),
        ('goldens = "out/g"\nout = "out"\n', 6, "out = 'out' holds the goldens folder out/g/"),
        ('report = "r"\ngoldens = "r/../r"\n', 6, "goldens = 'r/../r' is the report folder r/"),
    ],
)
def test_the_tables_folders_are_apart_from_the_project_and_each_other(tmp_path, table, line, says):
    project(tmp_path, "[tool.collide2d]\n" + table)
    with pytest.raises(settings.ConfigError) as info:
        settings.find(tmp_path)
    text = str(info.value)
    assert text.startswith(f"{tmp_path / 'pyproject.toml'}:{line}:1: error: ") and says in text
    assert "need a folder of their own" in text


def test_a_folder_named_on_the_command_line_is_apart_too(tmp_path, monkeypatch, capsys):
    (tmp_path / "p").mkdir()
    root = project(tmp_path / "p", '[tool.collide2d]\nout = "runs"\n')
    (root / "s.yaml").write_text(SCENARIO)
    found = settings.find(root)
    for given, says in (
        (root, "is the project folder"),
        (tmp_path, "holds the project folder"),
        (root / "scenarios" / "x", "is inside the scenarios folder scenarios/"),
        (root / "goldens", "is the goldens folder goldens/"),
        (root / "report", "is the report folder report/"),
    ):
        with pytest.raises(settings.FolderClash, match=says):
            found.apart("out", given, "--out")
    assert found.apart("out", root / "runs", "--out") == root / "runs"  # its own setting's folder
    assert found.apart("report", tmp_path / "elsewhere", "--report") == tmp_path / "elsewhere"
    monkeypatch.chdir(root)
    assert main(["run", "s.yaml", "--out", ".", "--quiet"]) == 2
    assert "--out . is the project folder" in capsys.readouterr().err
    assert sorted(p.name for p in root.iterdir()) == ["pyproject.toml", "s.yaml"]


def test_a_control_character_in_a_folder_setting_is_refused_at_its_line(tmp_path, monkeypatch):
    project(tmp_path, '[tool.collide2d]\nout = "runs"\ngoldens = "g\\u0000old"\n')
    with pytest.raises(settings.ConfigError) as info:
        settings.find(tmp_path)
    text = str(info.value)
    assert text.startswith(f"{tmp_path / 'pyproject.toml'}:6:1: error: goldens = ")
    assert "holds a control character" in text


@pytest.mark.parametrize(
    "setting, line, says",
    [
        ("substeps = 100000000000000000000", 6, "model.substeps must be at most 10000"),
        ("substeps = 10001", 6, "model.substeps must be at most 10000, not 10001"),
        ("max_events_per_tick = 9007199254740993", 6, "must be at most 9007199254740992"),
        ("substeps = 0", 6, "model.substeps must be a whole number >= 1"),
    ],
)
def test_the_tables_model_settings_have_a_scenarios_bounds(
    tmp_path, monkeypatch, capsys, setting, line, says
):
    project(tmp_path, f'[tool.collide2d]\n[tool.collide2d.model]\n{setting}\nkind = "stepped"\n')
    (tmp_path / "s.yaml").write_text(SCENARIO)
    monkeypatch.chdir(tmp_path)
    for argv in (["config"], ["run", "s.yaml", "--quiet"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"{tmp_path / 'pyproject.toml'}:{line}:1: error: ") and says in err
    # the same value in a scenario file is refused by the same bound
    key, value = setting.split(" = ")
    kind = "stepped" if key == "substeps" else "exact"
    with pytest.raises(
        ScenarioError, match=says.replace("must be a whole number >= 1", "must be at least 1")
    ):
        loads(SCENARIO + f"model: {{kind: {kind}, {key}: {value}}}\n")
    assert not (tmp_path / "out").exists()


def test_the_tables_model_settings_at_their_bounds_are_taken(tmp_path):
    project(
        tmp_path,
        "[tool.collide2d]\n[tool.collide2d.model]\n"
        "substeps = 10000\nmax_events_per_tick = 9007199254740992\n",
    )
    assert settings.find(tmp_path).model_defaults() == {
        "substeps": 10000,
        "max_events_per_tick": 2**53,
    }
