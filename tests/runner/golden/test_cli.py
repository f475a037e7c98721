"""Tests of runner/golden/cli.py: `check` and `bless` on a project tree of synthetic scenarios."""

from __future__ import annotations

import errno
import json
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from collide2d.runner.golden import cli
from collide2d.runner.output import files

from . import synthetic


def _run(*argv):
    return cli.main(list(argv), load=synthetic.load, simulate=synthetic.simulate)


def _write(tree, name, **changes):
    path = tree / "scenarios" / f"{name}.yaml"
    return synthetic.write(path, synthetic.spec(name=name, **changes))


def _changed_pixel():
    return synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]]


def test_check_passes_on_an_identical_run(tree, capsys):
    assert _run("bless") == 0
    capsys.readouterr()
    assert _run("check") == 0
    out = capsys.readouterr().out
    assert out.splitlines() == ["ok      demo", "1 passed, 0 failed"]


def test_check_fails_with_a_readable_message_and_report(tree, capsys):
    assert _run("bless") == 0
    _write(tree, "demo", pixels=_changed_pixel())
    capsys.readouterr()
    assert _run("check", "--report", "rep") == 1
    out = capsys.readouterr().out
    assert "FAILED  demo (scenarios/demo.yaml)" in out
    assert "frame 4: 1 pixel(s) differ (colour threshold 0, budget 0) within x 6..6, y 1..1" in out
    for kind in ("expected", "actual", "diff"):
        assert f"rep/demo/frame_000004_{kind}.png" in out
        assert (tree / "rep" / "demo" / f"frame_000004_{kind}.png").is_file()
    assert "to accept this run as the golden: collide2d bless scenarios/demo.yaml" in out
    assert "report: rep/index.html" in out
    assert out.rstrip().endswith("0 passed, 1 failed")
    summary = json.loads((tree / "rep" / "summary.json").read_text())
    assert summary["failed"] == 1 and summary["scenarios"][0]["name"] == "demo"


def test_check_of_a_missing_golden_fails_and_writes_nothing(tree, capsys):
    assert _run("check") == 1
    out = capsys.readouterr().out
    assert "MISSING demo" in out
    assert "to create it: collide2d bless scenarios/demo.yaml" in out
    assert not (tree / "goldens").exists()


def test_check_and_bless_by_name_or_path(tree, capsys):
    _write(tree, "other")
    assert _run("bless", "other") == 0
    assert capsys.readouterr().out.splitlines() == [
        "created   other: 2 events, 2 frames, 2 objects"
    ]
    assert sorted(p.name for p in (tree / "goldens").iterdir()) == ["other"]
    assert _run("check", "scenarios/other.yaml") == 0
    assert _run("check", "demo") == 1


def test_bless_reports_each_status(tree, capsys):
    _write(tree, "other")
    assert _run("bless") == 0
    capsys.readouterr()
    _write(tree, "other", pixels=_changed_pixel())
    assert _run("bless") == 0
    assert capsys.readouterr().out.splitlines() == [
        "unchanged demo: no change",
        "updated   other: frames 4 (1 px)",
    ]
    assert _run("check") == 0


def test_unused_goldens_are_reported_and_pruned_only_when_asked(tree, capsys):
    _write(tree, "gone")
    assert _run("bless") == 0
    (tree / "scenarios" / "gone.yaml").unlink()
    capsys.readouterr()
    assert _run("check") == 0
    assert "unused goldens (no scenario uses them): gone" in capsys.readouterr().out
    assert _run("bless", "demo") == 0
    assert _run("bless") == 0
    assert "unused goldens kept: gone (remove them with --prune)" in capsys.readouterr().out
    assert (tree / "goldens" / "gone").is_dir()
    assert _run("bless", "--prune") == 0
    assert "removed   gone: no scenario uses it" in capsys.readouterr().out
    assert not (tree / "goldens" / "gone").exists()
    assert (tree / "goldens" / "demo").is_dir()


def test_prune_removes_only_folders_that_hold_a_goldens_manifest(tree, capsys):
    _write(tree, "gone")
    assert _run("bless") == 0
    (tree / "scenarios" / "gone.yaml").unlink()
    goldens = tree / "goldens"
    (goldens / "notes").mkdir()
    (goldens / "notes" / "todo.txt").write_text("keep me\n")
    (goldens / "web").mkdir()  # a manifest.json of something else
    (goldens / "web" / "manifest.json").write_text('{"name": "app", "icons": []}\n')
    (goldens / "junk").mkdir()
    (goldens / "junk" / "manifest.json").write_text("not json\n")
    capsys.readouterr()
    assert _run("check") == 0
    assert "unused goldens (no scenario uses them): gone;" in capsys.readouterr().out
    assert _run("bless", "--prune") == 0
    out = capsys.readouterr().out
    assert "removed   gone: no scenario uses it" in out and out.count("removed") == 1
    assert sorted(p.name for p in goldens.iterdir()) == ["demo", "junk", "notes", "web"]
    assert (goldens / "notes" / "todo.txt").read_text() == "keep me\n"


def test_a_goldens_folder_that_is_the_project_is_refused_before_anything(tree, capsys):
    (tree / "pyproject.toml").write_text('[tool.collide2d]\ngoldens = "."\n')
    before = sorted(p.relative_to(tree).as_posix() for p in tree.rglob("*"))
    for argv in (["bless", "--prune"], ["check"]):
        assert _run(*argv) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"{tree / 'pyproject.toml'}:2:1: error: goldens = '.' is the project")
    assert sorted(p.relative_to(tree).as_posix() for p in tree.rglob("*")) == before


def test_ci_refuses_bless_and_check_writes_nothing_to_goldens(tree, monkeypatch, capsys):
    monkeypatch.setenv("CI", "true")
    assert _run("bless") == 2
    assert "CI is set" in capsys.readouterr().err
    assert _run("bless", "--prune") == 2
    assert _run("check", "--report", "rep") == 1
    assert not (tree / "goldens").exists()
    assert (tree / "rep" / "index.html").is_file()


@pytest.mark.parametrize(
    "argv, error",
    [
        (["check", "nosuch"], "no scenario 'nosuch'"),
        (["bless", "nosuch"], "no scenario 'nosuch'"),
        (["check", "--report", "goldens/rep"], "is inside the goldens folder goldens/"),
        (["check", "--report", "."], "--report . is the project folder"),
        (["check", "--report", ".."], "--report .. holds the project folder"),
        (["check", "--report", "scenarios"], "--report scenarios is the scenarios folder"),
        (["check", "--root", "scenarios"], "has no scenarios/ folder"),
    ],
)
def test_bad_input_exits_2(tree, capsys, argv, error):
    assert _run(*argv) == 2
    assert error in capsys.readouterr().err
    assert not (tree / "goldens").exists()


def test_a_refused_scenario_stops_bless_before_anything_runs(tree, capsys):
    _write(tree, "bad", error="unknown key 'tiks' (did you mean 'ticks'?)")
    assert _run("bless") == 2
    captured = capsys.readouterr()
    assert captured.err.strip() == (
        "scenarios/bad.yaml:1:1: error: unknown key 'tiks' (did you mean 'ticks'?)"
    )
    assert captured.out == ""
    assert not (tree / "goldens").exists()


def _real_or_synthetic(path, **kwargs):
    """The real scenario loader for a file that is not a synthetic (JSON) scenario."""
    if Path(path).read_bytes().startswith(b"{"):
        return synthetic.load(path, **kwargs)
    return cli.default_load(path, **kwargs)


@pytest.mark.parametrize(
    ("data", "error"),
    [
        (b"version: 1\nticks: [\n", "scenarios/bad.yaml:3:1: error: invalid YAML"),
        (b"version: 1\ntiks: 3\n", "scenarios/bad.yaml:2:1: error: unknown key 'tiks'"),
        (b"version: 1\nname: caf\xe9\n", "scenarios/bad.yaml:2:10: error: the file is not UTF-8"),
        (b"unreadable", "scenarios/bad.yaml:1:1: error: cannot read the file: Permission denied"),
    ],
    ids=["yaml", "validation", "encoding", "permissions"],
)
def test_check_keeps_checking_past_an_unreadable_scenario_and_files_it_as_one_case(
    tree, capsys, monkeypatch, data, error
):
    """One scenario file that cannot be read is one error case in the JUnit file and the JSON
    summary (and the report's summary.json); the others are still checked; exit 2."""
    _write(tree, "other")
    assert _run("bless") == 0
    _write(tree, "other", final=[[0.0, 0.0, 0.0, 0.0]])  # differs from its golden
    bad = tree / "scenarios" / "bad.yaml"
    bad.write_bytes(data)
    if data == b"unreadable":
        real_open = os.open

        def refusing_open(file, *args, **kwargs):  # root reads any file: refuse as for a user
            if Path(file).name == "bad.yaml":
                raise PermissionError(13, "Permission denied", str(file))
            return real_open(file, *args, **kwargs)

        monkeypatch.setattr(os, "open", refusing_open)
    capsys.readouterr()
    argv = ["check", "--junit", "out.xml", "--format", "json", "--report", "rep"]
    code = cli.main(argv, load=_real_or_synthetic, simulate=synthetic.simulate)
    monkeypatch.undo()
    out, err = capsys.readouterr()
    assert code == 2
    assert err.startswith(error), err
    summary = json.loads(out)
    assert (summary["passed"], summary["failed"]) == (1, 1)  # demo and other were checked
    assert [s["name"] for s in summary["scenarios"]] == ["demo", "other"]
    assert summary["not_checked"] == ["scenarios/bad.yaml"]
    (record,) = summary["errors"]
    assert record["name"] == "scenarios/bad.yaml" and record["message"].startswith(error)
    kept = json.loads((tree / "rep" / "summary.json").read_text())
    assert kept["errors"] == summary["errors"]
    suite = ET.parse(tree / "out.xml").getroot()
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("3", "1", "1")
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert cases["demo"].find("failure") is None and cases["demo"].find("error") is None
    assert cases["other"].find("failure") is not None
    assert cases["scenarios/bad.yaml"].find("error").get("message").startswith(error)


def test_two_scenarios_with_one_name_exit_2(tree, capsys):
    _write(tree, "twin").write_text(json.dumps(synthetic.spec(name="demo")))
    assert _run("bless") == 2
    assert "are both named 'demo'" in capsys.readouterr().err
    assert not (tree / "goldens").exists()


def test_no_project_found_exits_2(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert _run("check") == 2
    assert "no scenarios/ folder" in capsys.readouterr().err


def test_root_option_and_empty_corpus(tmp_path, capsys):
    (tmp_path / "scenarios").mkdir()
    assert _run("check", "--root", str(tmp_path)) == 2
    assert "no scenario files in" in capsys.readouterr().err
    synthetic.write(tmp_path / "scenarios" / "demo.yaml", synthetic.spec())
    assert _run("bless", "--root", str(tmp_path)) == 0
    assert (tmp_path / "goldens" / "demo" / "manifest.json").is_file()


def test_register_adds_both_commands():
    import argparse

    parser = argparse.ArgumentParser(prog="collide2d")
    cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["bless", "a", "b", "--prune", "--quiet"])
    assert (args.scenarios, args.prune, args.quiet) == (["a", "b"], True, True)
    args = parser.parse_args(["check", "--report", "r"])
    assert args.report == "r" and callable(args.func)


def test_a_full_disk_during_check_report_is_an_io_error_naming_the_file(tree, capsys, monkeypatch):
    """ENOSPC while the report is written: exit 2 with the file named, never "a bug" (exit 3);
    no temporary file is left behind."""
    assert _run("bless") == 0
    _write(tree, "demo", pixels=_changed_pixel())
    (tree / "rep").mkdir()

    class FullDisk:
        def __init__(self, f):
            self.f = f

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

        def write(self, data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    real_open = open

    def full_disk_open(file, mode="r", *args, **kwargs):
        f = real_open(file, mode, *args, **kwargs)
        return FullDisk(f) if "w" in mode and "rep" in Path(file).parts else f

    monkeypatch.setattr(files, "open", full_disk_open, raising=False)
    capsys.readouterr()
    assert _run("check", "--report", "rep") == 2
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert lines[0].startswith("collide2d: error: demo: rep/demo/frame_000004_") and lines[
        0
    ].endswith(".png: No space left on device")
    assert lines[-1] == "collide2d: error: rep/summary.json: No space left on device"
    assert "unexpected" not in err and "bug" not in err
    assert out.rstrip().endswith("0 passed, 0 failed, 1 not checked (errors above)")
    assert [p.name for p in (tree / "rep").rglob("*") if p.is_file()] == []
