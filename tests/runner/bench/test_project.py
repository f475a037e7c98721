"""`collide2d bench` as a user runs it in a project of their own: where the project's scenarios
folder lacks the benchmark scenarios it reads the copies the package ships (equal to this
repository's), exits 1 when a target of the headline is missed, and on a terminal shows a bar of
its parts from the start."""

from __future__ import annotations

import io
import sys

from collide2d.runner.bench import goals, scenes
from collide2d.runner.command.main import main

PAPER_40 = ["--n", "40", "--model", "paper"]


def project(tmp_path):
    """A user's project: a [tool.collide2d] table naming its scenarios folder, one scenario."""
    (tmp_path / "pyproject.toml").write_text('[tool.collide2d]\nscenarios = "cases"\n')
    (tmp_path / "cases").mkdir()
    (tmp_path / "cases" / "mine.yaml").write_text("version: 1\n")
    return tmp_path


def test_quick_bench_in_a_users_project_reads_the_benchmark_scenarios_the_package_ships(
    tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(project(tmp_path))
    code = main(["bench", "--quick", "--part", "error", *PAPER_40, "--out", "out", "--quiet"])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "lacks" not in err
    rows = (tmp_path / "out" / "bench" / "bench.csv").read_text()
    assert "bench_tunnelling" in rows and "bench_mass_ratio_chain" in rows


def test_the_benchmark_scenarios_the_package_ships_are_the_projects():
    for name in scenes.NEEDED_SCENARIOS:
        shipped = (scenes.PACKAGED_SCENARIOS / f"{name}.yaml").read_bytes()
        assert shipped == (scenes.PROJECT_SCENARIOS / f"{name}.yaml").read_bytes(), name


def test_a_missed_target_is_exit_status_1_and_named(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(goals, "STEPPED_NS_PER_BODY_STEP", (40, 1e-9))  # out of anyone's reach
    args = ["bench", "--quick", "--part", "scaling", "--n", "40", "--model", "stepped"]
    code = main([*args, "--out", str(tmp_path), "--quiet"])
    err = capsys.readouterr().err
    assert code == 1
    assert "target missed: stepped ns per body-step, N = 40" in err and "(target <= 1e-09)" in err
    monkeypatch.setattr(goals, "STEPPED_NS_PER_BODY_STEP", (40, 1e9))  # met
    assert main([*args, "--out", str(tmp_path), "--quiet"]) == 0


def test_on_a_terminal_the_parts_bar_is_drawn_before_the_first_part_ends(tmp_path, monkeypatch):
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    shown = Terminal()
    monkeypatch.setattr(sys, "stderr", shown)
    code = main(["bench", "--quick", "--part", "scaling", *PAPER_40, "--out", str(tmp_path)])
    assert code == 0
    text = shown.getvalue()
    first_row = text.index("scaling  paper")
    assert "bench: scaling:   0%" in text[:first_row] and "0/1" in text[:first_row]
