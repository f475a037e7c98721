"""Tests of what a reviewer and CI get from a failed check: why it changed (runner/golden/why.py),
JUnit XML (junit.py), `check --format json` (formats.py) and `bless --from-report` (fromreport.py),
on a project tree of synthetic scenarios."""

from __future__ import annotations

import json
import os
import xml.etree.ElementTree as ET

from collide2d import __version__
from collide2d.runner.golden import cli, junit, why

from . import synthetic


def _run(*argv):
    return cli.main(list(argv), load=synthetic.load, simulate=synthetic.simulate)


def _write(tree, name, **changes):
    return synthetic.write(
        tree / "scenarios" / f"{name}.yaml", synthetic.spec(name=name, **changes)
    )


def _edit_manifest(tree, name, **changes):
    path = tree / "goldens" / name / "manifest.json"
    data = json.loads(path.read_text())
    data.update(changes)
    path.write_text(json.dumps(data, indent=2) + "\n")


def test_manifest_records_the_scenario_hash_and_version(tree):
    import hashlib

    assert _run("bless") == 0
    m = json.loads((tree / "goldens" / "demo" / "manifest.json").read_text())
    text = (tree / "scenarios" / "demo.yaml").read_bytes()
    assert m["scenario_sha256"] == hashlib.sha256(text).hexdigest()
    assert m["collide2d_version"] == __version__


def test_why_says_the_scenario_was_edited(tree, capsys):
    assert _run("bless") == 0
    _write(tree, "demo", pixels=synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]])
    capsys.readouterr()
    assert _run("check", "--format", "json") == 1
    doc = json.loads(capsys.readouterr().out)  # stdout is the JSON document alone
    (scn,) = doc["scenarios"]
    assert scn["cause"]["kind"] == why.SCENARIO_EDITED
    assert scn["cause"]["text"].startswith("the scenario was edited since bless")
    assert doc["summary"] == "1 failed, 0 passed" and (doc["failed"], doc["passed"]) == (1, 0)


def test_why_says_same_scenario_different_engine(tree, capsys):
    assert _run("bless") == 0
    _edit_manifest(tree, "demo", collide2d_version="0.0.1")
    capsys.readouterr()
    # the manifest's own hash is not checked; a changed event makes the check fail
    events = tree / "goldens" / "demo" / "events.jsonl"
    rows = [json.loads(line) for line in events.read_text().splitlines()]
    rows[0]["tick"] -= 1
    events.write_text("".join(json.dumps(r) + "\n" for r in rows))
    import hashlib

    _edit_manifest(
        tree,
        "demo",
        events={
            "file": "events.jsonl",
            "count": 2,
            "sha256": hashlib.sha256(events.read_bytes()).hexdigest(),
        },
    )
    assert _run("check") == 1
    out = capsys.readouterr().out
    assert (
        f"  why: same scenario, different engine: blessed by collide2d 0.0.1, checked by "
        f"collide2d {__version__}" in out
    )


def test_why_of_an_old_golden_is_unknown():
    cause = why.cause(type("S", (), {"text_sha256": "a" * 64})(), {"format": 1})
    assert cause.kind == why.UNKNOWN and "bless it again" in cause.text


def test_junit_has_one_case_per_scenario_and_the_first_divergence(tree, capsys):
    _write(tree, "other")
    assert _run("bless") == 0
    _write(tree, "demo", final=[[1.0, 2.5, 10.0, 0.0], [5.5, 3.0, -10.0, 2.5]])
    capsys.readouterr()
    assert _run("check", "--junit", "out.xml") == 1
    suite = ET.parse(tree / "out.xml").getroot()
    assert suite.tag == "testsuite" and suite.get("name") == "collide2d.check"
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("2", "1", "0")
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert sorted(cases) == ["demo", "other"]
    assert cases["other"].find("failure") is None
    failure = cases["demo"].find("failure")
    assert failure.get("message").startswith("final state:")
    assert "why: the scenario was edited since bless" in failure.text
    first = (tree / "out.xml").read_bytes()
    assert _run("check", "--junit", "out.xml") == 1
    assert (tree / "out.xml").read_bytes() == first  # same outcomes, same bytes


def test_junit_is_valid_xml_whatever_a_name_file_name_or_golden_holds(tree, capsys):
    """Found by hardening: a control character in a golden's text (or a name, or a file name)
    went into the JUnit file as such, which XML 1.0 forbids: CI could not read the file."""
    import hashlib

    assert _run("bless") == 0
    events = tree / "goldens" / "demo" / "events.jsonl"
    rows = [json.loads(line) for line in events.read_text().splitlines()]
    rows[0]["type"] = "pa\x1b[2Jir\x00"
    events.write_text("".join(json.dumps(r) + "\n" for r in rows))
    digest = hashlib.sha256(events.read_bytes()).hexdigest()
    _edit_manifest(tree, "demo", events={"file": "events.jsonl", "count": 2, "sha256": digest})
    assert _run("check", "--junit", "out.xml") == 1
    failure = ET.parse(tree / "out.xml").getroot().find("testcase/failure")
    assert "pa\\x1b[2Jir\\x00" in failure.get("message") and "\\x1b" in failure.text

    bad = os.fsdecode(b"scenarios/b\x01d\xff.yaml")  # a byte that is not UTF-8, too
    suite = ET.fromstring(junit.junit_xml([], [(bad, f"{bad}:1:1: error: \x1b[2J\x0c")]))
    error = suite.find("testcase/error")
    assert suite.find("testcase").get("name") == "scenarios/b\\x01d\\xff.yaml"
    assert error.text == "scenarios/b\\x01d\\xff.yaml:1:1: error: \\x1b[2J\\x0c"


def test_junit_refuses_a_link(tree, capsys):
    (tree / "target.xml").write_text("keep")
    (tree / "out.xml").symlink_to(tree / "target.xml")
    assert _run("check", "--junit", "out.xml") == 2
    assert "symbolic link" in capsys.readouterr().err
    assert (tree / "target.xml").read_text() == "keep"


def test_bless_from_report_accepts_the_run_shown_without_running(tree, capsys, monkeypatch):
    assert _run("bless") == 0
    _write(tree, "demo", pixels=synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]])
    assert _run("check", "--report", "rep") == 1
    assert (tree / "rep" / "demo" / "run" / "manifest.json").is_file()
    before = {p.name: p.read_bytes() for p in (tree / "rep" / "demo" / "run").rglob("*.*")}
    calls = []

    def no_run(*args, **kwargs):
        calls.append(args)
        raise AssertionError("bless --from-report must not run the scenario")

    capsys.readouterr()
    assert cli.main(["bless", "--from-report", "rep"], load=synthetic.load, simulate=no_run) == 0
    assert capsys.readouterr().out.startswith("updated   demo: from rep/demo/run")
    assert not calls
    golden = tree / "goldens" / "demo"
    for p in (tree / "rep" / "demo" / "run").rglob("*.*"):
        assert (golden / p.relative_to(tree / "rep" / "demo" / "run")).read_bytes() == before[
            p.name
        ]
    assert _run("check") == 0  # the golden is now what the run gives


def test_bless_from_report_refuses_a_scenario_edited_since(tree, capsys):
    assert _run("bless") == 0
    _write(tree, "demo", pixels=synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]])
    assert _run("check", "--report", "rep") == 1
    old = (tree / "goldens" / "demo" / "manifest.json").read_bytes()
    _write(tree, "demo", pixels=synthetic.BASE["pixels"] + [[4, 5, 1, 0, 0, 9]])
    capsys.readouterr()
    assert _run("bless", "--from-report", "rep", "demo") == 2
    assert "edited after the report was written" in capsys.readouterr().err
    assert (tree / "goldens" / "demo" / "manifest.json").read_bytes() == old


def test_bless_from_report_refuses_a_tampered_run(tree, capsys):
    assert _run("bless") == 0
    _write(tree, "demo", pixels=synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]])
    assert _run("check", "--report", "rep") == 1
    old = (tree / "goldens" / "demo" / "manifest.json").read_bytes()
    (tree / "rep" / "demo" / "run" / "final.csv").write_text("id,x,y,vx,vy\n")
    capsys.readouterr()
    assert _run("bless", "--from-report", "rep") == 2
    assert "final.csv" in capsys.readouterr().err
    assert (tree / "goldens" / "demo" / "manifest.json").read_bytes() == old


def test_bless_from_report_skips_runs_an_older_report_left(tree, capsys):
    _write(tree, "other")
    assert _run("bless") == 0
    _write(tree, "other", pixels=synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]])
    assert _run("check", "--report", "rep") == 1  # keeps rep/other/run
    _write(tree, "other")  # back as blessed; now demo differs
    _write(tree, "demo", pixels=synthetic.BASE["pixels"] + [[4, 5, 1, 0, 0, 9]])
    assert _run("check", "--report", "rep") == 1
    assert (tree / "rep" / "other" / "run").is_dir()  # the older report's run is still there
    capsys.readouterr()
    assert _run("bless", "--from-report", "rep") == 0
    out = capsys.readouterr().out
    assert out.startswith("updated   demo:") and "other" not in out


TABLE_SCENE = """version: 1
name: tab
world: {width: 40, height: 30, fps: 10}
model: paper
ticks: 6
objects: {file: tab.csv}
"""


def test_a_table_is_part_of_the_scenario_goldens_and_reports_keep(tmp_path, monkeypatch, capsys):
    """An edited table reads as an edited scenario in `check`, and `bless --from-report` refuses
    a table changed since the report (and takes it back once it is as the report saw it)."""
    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "tab.yaml").write_text(TABLE_SCENE)
    table = tmp_path / "scenarios" / "tab.csv"

    def rows(vx):
        table.write_text(f"id,shape,w,h,x,y,vx\n0,box,4,4,2,2,{vx}\n1,box,4,4,30,20,0\n")

    monkeypatch.chdir(tmp_path)
    rows(10)
    assert cli.main(["bless"]) == 0
    manifest = tmp_path / "goldens" / "tab" / "manifest.json"
    blessed = manifest.read_bytes()
    rows(20)
    capsys.readouterr()
    assert cli.main(["check", "--format", "json"]) == 1
    (scn,) = json.loads(capsys.readouterr().out)["scenarios"]
    assert scn["cause"]["kind"] == why.SCENARIO_EDITED
    assert scn["cause"]["text"].startswith("the scenario was edited since bless")
    assert cli.main(["check", "--report", "rep"]) == 1
    rows(30)  # changed again after the report
    capsys.readouterr()
    assert cli.main(["bless", "--from-report", "rep"]) == 2
    assert "edited after the report was written" in capsys.readouterr().err
    assert manifest.read_bytes() == blessed
    rows(20)  # as the report saw it
    assert cli.main(["bless", "--from-report", "rep"]) == 0
    assert cli.main(["check"]) == 0
