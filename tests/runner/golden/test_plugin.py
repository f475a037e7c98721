"""Tests of runner/golden/plugin.py: golden tests per scenario, --update-goldens, CI, xdist."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from collide2d.runner.golden import cli
from collide2d.runner.golden.store import GoldenStore

from . import synthetic

pytest_plugins = ["pytester"]

CONFTEST = """
import pytest
import golden_synthetic

# no `pytest_plugins` line: the plugin comes from collide2d's pytest11 entry point


@pytest.fixture(scope="session")
def golden_load():
    return golden_synthetic.load


@pytest.fixture(scope="session")
def golden_simulate():
    return golden_synthetic.simulate
"""

TEST_FILE = """
def test_golden(golden_scenario, golden_check):
    golden_check(golden_scenario)
"""


@pytest.fixture
def project(pytester):
    """A pytester project: synthetic scenarios a and b, the plugin, one golden test module."""
    pytester.makepyfile(
        golden_synthetic=Path(synthetic.__file__).read_text(),
        conftest=CONFTEST,
        test_golden_project=TEST_FILE,  # a name no other test module in the run has
    )
    for name in ("a", "b"):
        synthetic.write(pytester.path / "scenarios" / f"{name}.yaml", synthetic.spec(name=name))
    # pytest-playwright's per-test hook keeps global state that a nested in-process run trips on
    pytester.makeini("[pytest]\naddopts = -p no:playwright\n")
    return pytester


def test_a_missing_golden_fails_naming_the_command(project):
    result = project.runpytest("-v")
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(["*test_golden?a? FAILED*", "*test_golden?b? FAILED*"])
    result.stdout.fnmatch_lines(["*to create it: collide2d bless scenarios/a.yaml*"])
    assert not (project.path / "goldens").exists()


def test_update_goldens_blesses_what_runs_then_checks_pass(project):
    result = project.runpytest("--update-goldens", "-k", "a")
    result.assert_outcomes(passed=1, deselected=1)
    result.stdout.fnmatch_lines(["*goldens written*", "created   a: 2 events, 2 frames, 2 objects"])
    assert GoldenStore(project.path).names() == ["a"]
    project.runpytest("--update-goldens").assert_outcomes(passed=2)
    result = project.runpytest("-v")
    result.assert_outcomes(passed=2)
    assert "goldens written" not in result.stdout.str()


def test_a_difference_fails_with_the_check_message_and_a_report(project):
    project.runpytest("--update-goldens").assert_outcomes(passed=2)
    changed = synthetic.spec(name="b", pixels=synthetic.BASE["pixels"] + [[0, 0, 0, 7, 7, 7]])
    synthetic.write(project.path / "scenarios" / "b.yaml", changed)
    rep = project.path / "rep"
    result = project.runpytest("--golden-report", str(rep))
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(
        [
            "*FAILED  b (scenarios/b.yaml)*",
            "*frame 0: 1 pixel(s) differ*within x 0..0, y 0..0*",
            "*diff:*rep/b/frame_000000_diff.png*",
            "*to accept this run as the golden: collide2d bless scenarios/b.yaml*",
        ]
    )
    summary = json.loads((rep / "b" / "summary.json").read_text())
    assert summary["frames"][0]["n_diff"] == 1


def test_a_golden_text_reaches_the_terminal_spelled_out(project):
    """Found by hardening: a control character in a golden's text went raw into pytest's report
    (an escape sequence there clears the terminal)."""
    project.runpytest("--update-goldens").assert_outcomes(passed=2)
    events = project.path / "goldens" / "b" / "events.jsonl"
    rows = [json.loads(line) for line in events.read_text().splitlines()]
    rows[0]["type"] = "pa\x1b[2Jir"
    events.write_text("".join(json.dumps(r) + "\n" for r in rows))
    manifest = project.path / "goldens" / "b" / "manifest.json"
    data = json.loads(manifest.read_text())
    data["events"]["sha256"] = hashlib.sha256(events.read_bytes()).hexdigest()
    manifest.write_text(json.dumps(data, indent=2) + "\n")
    result = project.runpytest()
    result.assert_outcomes(passed=1, failed=1)
    out = result.stdout.str()
    assert "pa\\x1b[2Jir" in out and "\x1b[2J" not in out


def test_update_goldens_is_refused_in_ci(project, monkeypatch):
    monkeypatch.setenv("CI", "true")
    result = project.runpytest_subprocess("--update-goldens")
    assert result.ret == 2
    assert "CI is set" in result.stderr.str() + result.stdout.str()
    assert not (project.path / "goldens").exists()


def test_unused_goldens_are_listed(project):
    project.runpytest("--update-goldens").assert_outcomes(passed=2)
    (project.path / "scenarios" / "b.yaml").unlink()
    result = project.runpytest()
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["*unused goldens*", "no scenario uses: b; remove them with*"])


def test_a_refused_scenario_fails_its_own_test(project):
    synthetic.write(project.path / "scenarios" / "b.yaml", synthetic.spec(error="bad value"))
    result = project.runpytest("--update-goldens")
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(["*scenarios/b.yaml:1:1: error: bad value*"])
    assert GoldenStore(project.path).names() == ["a"]


def test_no_scenarios_is_a_failure(project):
    for p in (project.path / "scenarios").iterdir():
        p.unlink()
    result = project.runpytest()
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*test_golden?no-scenarios?*", "*no scenario files in*"])


def test_xdist_blesses_each_golden_once_and_checks(project):
    for name in ("c", "d", "e"):
        synthetic.write(project.path / "scenarios" / f"{name}.yaml", synthetic.spec(name=name))
    result = project.runpytest_subprocess("-n", "2", "--update-goldens")
    result.assert_outcomes(passed=5)
    written = [ln for ln in result.stdout.lines if ln.startswith("created ")]
    assert sorted(ln.split()[1] for ln in written) == ["a:", "b:", "c:", "d:", "e:"]
    store = GoldenStore(project.path)
    assert store.names() == ["a", "b", "c", "d", "e"]
    for name in store.names():
        store.read(name)
    project.runpytest().assert_outcomes(passed=5)


def test_links_in_goldens_fail_the_tests_clearly(project, tmp_path_factory):
    argv = ["bless", "--root", str(project.path), "--quiet"]
    assert cli.main(argv, load=synthetic.load, simulate=synthetic.simulate) == 0
    outside = tmp_path_factory.mktemp("outside")
    golden = project.path / "goldens" / "a"
    golden.rename(outside / "a")
    golden.symlink_to(outside / "a", target_is_directory=True)
    before = sorted((p.as_posix(), p.read_bytes()) for p in outside.rglob("*") if p.is_file())
    for argv in ([], ["--update-goldens"]):
        result = project.runpytest(*argv)
        result.assert_outcomes(passed=1, failed=1)
        result.stdout.fnmatch_lines(["*goldens/a is a symbolic link*"])
        result.stdout.no_fnmatch_line("*Traceback*")
    after = sorted((p.as_posix(), p.read_bytes()) for p in outside.rglob("*") if p.is_file())
    assert after == before and golden.is_symlink()


@pytest.mark.parametrize("folder", ["goldens", "."])
def test_golden_report_obeys_the_rule_of_check_report(project, folder):
    project.runpytest("--update-goldens").assert_outcomes(passed=2)
    synthetic.write(
        project.path / "scenarios" / "b.yaml",
        synthetic.spec(name="b", pixels=synthetic.BASE["pixels"] + [[0, 0, 0, 7, 7, 7]]),
    )
    mine = ("goldens", "scenarios", "b", "index.html", "summary.json", "rep")

    def tree():
        return sorted(
            (p.relative_to(project.path).as_posix(), p.read_bytes() if p.is_file() else None)
            for top in mine
            for p in [project.path / top, *(project.path / top).rglob("*")]
            if p.exists()
        )

    before = tree()
    result = project.runpytest_subprocess("--golden-report", folder)
    assert result.ret == 2
    assert f"--golden-report {folder} " in result.stdout.str() + result.stderr.str()
    assert tree() == before  # no report written anywhere in the project


def test_two_scenarios_with_one_name_fail_as_the_cli_refuses_them(project):
    synthetic.write(project.path / "scenarios" / "twin.yaml", synthetic.spec(name="a"))
    argv = ["check", "--root", str(project.path)]
    assert cli.main(argv, load=synthetic.load, simulate=synthetic.simulate) == 2
    for argv in (["--update-goldens", "-v"], ["-v"]):
        result = project.runpytest(*argv)
        result.assert_outcomes(passed=1, failed=2)
        result.stdout.fnmatch_lines(
            ["*scenarios/twin.yaml and scenarios/a.yaml are both named 'a'; a golden belongs*"]
        )
        assert GoldenStore(project.path).names() == ["b"]
