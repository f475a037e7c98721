"""Tests of `collide2d init` (runner/init.py) and of a project made by it: plain `pytest` collects
one golden test per scenario through the plugin, with no test file or conftest, and `check` and
`bless` read the same [tool.collide2d] table."""

from __future__ import annotations

from pathlib import Path

import pytest

from collide2d.runner import config
from collide2d.runner.cli import main
from collide2d.runner.golden.store import GoldenStore
from collide2d.runner.scenario import load

pytest_plugins = ["pytester"]

# the nested in-process runs leave out the cache and pytest-playwright, whose per-test hook keeps
# global state that a run inside a run trips on
NESTED = ("-p", "no:cacheprovider", "-p", "no:playwright")


def test_init_makes_a_project_and_prints_the_next_three_commands(tmp_path, capsys):
    assert main(["init", str(tmp_path / "p")]) == 0
    out = capsys.readouterr().out
    root = tmp_path / "p"
    example = root / "scenarios" / "example.yaml"
    scenario = load(example)
    assert scenario.name == "example" and scenario.model == "paper"
    text = example.read_text()
    for section in ("version", "name", "description", "world", "model", "ticks", "objects",
                    "generate", "output", "golden"):  # fmt: skip
        assert f"\n{section}:" in "\n" + text, section
    assert text.count("#") >= 10  # commented
    assert config.find(root).file == (root / "pyproject.toml").resolve()
    assert (root / ".gitignore").read_text() == "out/\n"
    commands = [line.split("#")[0].strip() for line in out.splitlines()[-3:]]
    assert commands == ["collide2d run scenarios/example.yaml", "pytest --update-goldens", "pytest"]


def test_init_extends_what_is_there_and_overwrites_nothing(tmp_path, capsys):
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "mine"\n')
    (tmp_path / ".gitignore").write_text("*.pyc")
    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "example.yaml").write_text("version: 1\n")
    assert main(["init", str(tmp_path)]) == 0
    assert (tmp_path / "scenarios" / "example.yaml").read_text() == "version: 1\n"
    assert (tmp_path / "pyproject.toml").read_text().startswith('[project]\nname = "mine"\n\n')
    assert config.has_table(tmp_path / "pyproject.toml")
    assert (tmp_path / ".gitignore").read_text() == "*.pyc\nout/\n"
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert main(["init", str(tmp_path)]) == 0  # again: everything kept
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before
    out = capsys.readouterr().out
    assert out.count("kept") >= 3


def test_init_refuses_a_pyproject_that_is_not_toml_before_writing_anything(tmp_path, capsys):
    (tmp_path / "pyproject.toml").write_text("[project\n")
    assert main(["init", str(tmp_path)]) == 2
    assert "pyproject.toml:1:" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pyproject.toml"]


@pytest.fixture
def inited(pytester, monkeypatch):
    """A pytester project made by `collide2d init`, with a second scenario (run as on a
    developer's machine: --update-goldens is refused where CI is set)."""
    monkeypatch.delenv("CI", raising=False)
    assert main(["init", str(pytester.path)]) == 0
    text = (pytester.path / "scenarios" / "example.yaml").read_text()
    (pytester.path / "scenarios" / "second.yaml").write_text(
        text.replace("name: example", "name: second")
    )
    return pytester


def test_plain_pytest_collects_one_golden_test_per_scenario_and_update_goldens_blesses(inited):
    assert not list(inited.path.rglob("*.py"))
    result = inited.runpytest("-v", *NESTED)
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(["*scenarios/example.yaml::golden FAILED*"])
    result.stdout.fnmatch_lines(["*to create it: collide2d bless scenarios/example.yaml*"])
    inited.runpytest("--update-goldens", *NESTED).assert_outcomes(passed=2)
    assert GoldenStore(inited.path).names() == ["example", "second"]
    result = inited.runpytest("-v", *NESTED)
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["*scenarios/second.yaml::golden PASSED*"])


def test_a_project_without_the_table_is_untouched(pytester):
    (pytester.path / "scenarios").mkdir()
    (pytester.path / "scenarios" / "a.yaml").write_text("version: 1\nticks: 1\n")
    result = pytester.runpytest(*NESTED)
    assert result.ret == pytest.ExitCode.NO_TESTS_COLLECTED


def test_check_and_bless_use_the_tables_folders(tmp_path, monkeypatch, capsys):
    assert main(["init", str(tmp_path)]) == 0
    pyproject = tmp_path / "pyproject.toml"
    text = (
        pyproject.read_text().replace('"scenarios"', '"cases"').replace('"goldens"', '"expected"')
    )
    pyproject.write_text(text)
    (tmp_path / "scenarios").rename(tmp_path / "cases")
    sub = tmp_path / "deep"
    sub.mkdir()
    monkeypatch.chdir(sub)  # found upward
    monkeypatch.delenv("CI", raising=False)
    assert main(["check"]) == 1  # no golden yet
    assert main(["bless"]) == 0
    assert GoldenStore(tmp_path, "expected").names() == ["example"]
    assert not (tmp_path / "goldens").exists()
    capsys.readouterr()
    assert main(["check", "example", "--report"]) == 0
    out = capsys.readouterr().out
    assert "1 passed, 0 failed" in out
    assert (tmp_path / "report" / "index.html").is_file()  # the table's report folder


def test_the_plugin_reads_a_custom_scenarios_folder(pytester, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    assert main(["init", str(pytester.path)]) == 0
    pyproject = pytester.path / "pyproject.toml"
    pyproject.write_text(
        pyproject.read_text().replace('scenarios = "scenarios"', 'scenarios = "cases"')
    )
    (pytester.path / "scenarios").rename(pytester.path / "cases")
    result = pytester.runpytest("--update-goldens", "-v", *NESTED)
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["*cases/example.yaml::golden PASSED*"])
    assert Path(pytester.path / "goldens" / "example" / "manifest.json").is_file()
