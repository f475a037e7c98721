"""`config` and `validate` tell every error at once: each refusal of a project's
[tool.collide2d] table at its line, in one run; and `validate` with no file checks every scenario
of the project's scenarios folder, reading each whatever the others hold."""

from __future__ import annotations

from collide2d.runner.command.main import main

TABLE = """[tool.collide2d]
threads = 0
jit = "maybe"
colour = "red"
[tool.collide2d.limits]
max_objects = -1
max_tick = 5
[tool.collide2d.model]
geometry = "round"
"""
GOOD = """version: 1
name: NAME
world: {width: 60, height: 40, fps: 10}
ticks: 4
objects:
  - {shape: box, size: 6, position: [5, 5], velocity: [20, 0]}
"""


def test_config_and_validate_tell_every_error_of_the_table_at_once(tmp_path, monkeypatch, capsys):
    (tmp_path / "pyproject.toml").write_text(TABLE)
    monkeypatch.chdir(tmp_path)
    for command in (["config"], ["validate", "x.yaml"]):
        assert main(command) == 2
        err = capsys.readouterr().err.splitlines()
        assert [line.split(" error: ")[0] for line in err] == [
            f"{tmp_path / 'pyproject.toml'}:{n}:1:" for n in (2, 3, 4, 6, 7, 9)
        ]
        assert "threads must be a whole number >= 1, not 0" in err[0]
        assert "jit must be one of auto | on | off, not 'maybe'" in err[1]
        assert "has no setting 'colour'" in err[2]
        assert "limits.max_objects must be a whole number >= 1, not -1" in err[3]
        assert "has no setting 'max_tick'; did you mean 'max_ticks'?" in err[4]
        assert "model.geometry must be one of box | exact, not 'round'" in err[5]


def test_validate_with_no_file_checks_every_scenario_of_the_project(tmp_path, monkeypatch, capsys):
    (tmp_path / "pyproject.toml").write_text('[tool.collide2d]\nscenarios = "cases"\n')
    cases = tmp_path / "cases"
    cases.mkdir()
    (cases / "a.yaml").write_text(GOOD.replace("NAME", "a"))
    (cases / "b.yaml").write_text("version: 1\nworld: {widht: 3}\n")
    (cases / "c.yml").write_text(GOOD.replace("NAME", "c"))
    (cases / "notes.txt").write_text("not a scenario")
    monkeypatch.chdir(cases)  # the project is found upward, as every command finds it
    assert main(["validate"]) == 2
    out, err = capsys.readouterr()
    assert out.splitlines() == [
        "a.yaml: ok (1 object, model paper, 4 ticks)",
        "c.yml: ok (1 object, model paper, 4 ticks)",
    ]
    assert err.startswith("b.yaml:2:") and "widht" in err
    (cases / "b.yaml").unlink()
    assert main(["validate"]) == 0
    for path in cases.iterdir():
        path.unlink()
    assert main(["validate"]) == 2
    assert "validate: error: no scenario files in ." in capsys.readouterr().err
