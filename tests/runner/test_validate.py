"""The `validate` and `schema` commands through an argparse parser, as the CLI registers them."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from collide2d.runner.command import validate
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.schema import json_schema

DATA = Path(__file__).parent / "data"
GOOD = str(DATA / "spec_example.yaml")  # 4 listed + 50 generated objects, paper, 12 ticks


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="collide2d")
    validate.register(p.add_subparsers(dest="command", required=True))
    return p


def run(argv, capsys):
    args = parser().parse_args(argv)
    status = args.func(args)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_good_file(capsys):
    status, out, err = run(["validate", GOOD], capsys)
    assert status == 0 and err == ""
    assert out == f"{GOOD}: ok (54 objects, model paper, 12 ticks)\n"


def test_good_and_bad_files(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("version: 1\nworld: {widht: 3}\n")
    status, out, err = run(["validate", GOOD, str(bad)], capsys)
    assert status == 2
    assert out == f"{GOOD}: ok (54 objects, model paper, 12 ticks)\n"
    # "widht" starts in column 9 of line 2, after "world: {"
    assert err == f"{bad}:2:9: error: unknown key 'widht' in world; did you mean 'width'?\n"


def test_an_error_in_world_hides_no_error_of_the_objects(tmp_path, capsys):
    """A typo in `world` and two in objects: all three in one run, in line order; a rule that
    needs the world (an object outside it) waits for a good world."""
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "version: 1\n"
        "world: {widht: 100}\n"
        "objects:\n"
        "  - {shape: box, size: 3, positon: [0, 0]}\n"
        "  - {shape: box, size: 3, position: [900, 0]}\n"
        "  - {shape: crcle, diameter: 3, position: [20, 0]}\n"
    )
    status, out, err = run(["validate", str(bad)], capsys)
    assert (status, out) == (2, "")
    assert err.splitlines() == [
        f"{bad}:2:9: error: unknown key 'widht' in world; did you mean 'width'?",
        f"{bad}:4:27: error: unknown key 'positon' in object; did you mean 'position'?",
        f"{bad}:6:13: error: unknown shape 'crcle'; did you mean 'circle'?",
    ]


def test_every_file_is_checked_after_a_bad_one(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("version: 3\n")
    status, out, err = run(["validate", str(bad), GOOD], capsys)
    assert status == 2 and out.startswith(f"{GOOD}: ok")
    assert err.startswith(f"{bad}:1:10: error: version must be 1")


def test_missing_file(tmp_path, capsys):
    missing = tmp_path / "missing.yaml"
    status, out, err = run(["validate", str(missing)], capsys)
    assert status == 2 and out == ""
    assert err.startswith(f"{missing}:1:1: error: cannot read the file")


def test_overrides(tmp_path, capsys):
    status, out, _ = run(["validate", GOOD, "--model", "stepped", "--ticks", "20"], capsys)
    assert status == 0 and out == f"{GOOD}: ok (54 objects, model stepped, 20 ticks)\n"
    slow = tmp_path / "slow.yaml"
    line4 = "  - {shape: box, size: 3, position: [0, 0], velocity: [0.000001, 0]}"
    slow.write_text("version: 1\nworld: {fps: 1}\nobjects:\n" + line4 + "\n")
    col = line4.index("0.000001") + 1
    assert run(["validate", str(slow)], capsys)[0] == 0
    status, _, err = run(["validate", str(slow), "--fps", "3"], capsys)
    assert status == 2 and err.startswith(f"{slow}:4:{col}: error: --fps 3: velocity 1e-06 px/s")


def test_limit_options(capsys):
    status, _, err = run(["validate", GOOD, "--max-objects", "10"], capsys)
    assert status == 2 and "past the limit of 10 objects; raise it with --max-objects" in err
    status, _, err = run(["validate", GOOD, "--max-ticks", "11"], capsys)
    assert status == 2 and "--max-ticks" in err
    status, _, err = run(["validate", GOOD, "--max-side", "300"], capsys)
    assert status == 2 and "--max-side" in err
    status, _, err = run(["validate", GOOD, "--max-frames", "5"], capsys)
    assert status == 2 and "--max-frames" in err


def test_limits_from_args():
    args = parser().parse_args(["validate", GOOD, "--max-side", "100", "--max-objects", "7"])
    assert validate.limits_from_args(args) == Limits(max_side=100, max_objects=7)
    assert validate.limits_from_args(parser().parse_args(["validate", GOOD])) == Limits()


@pytest.mark.parametrize(
    "argv",
    [
        ["validate", GOOD, "--max-objects", "0"],
        ["validate", GOOD, "--max-ticks", "many"],
        ["validate", GOOD, "--model", "fast"],
    ],
)
def test_usage_errors_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as info:
        parser().parse_args(argv)
    assert info.value.code == 2


def test_schema(capsys):
    status, out, err = run(["schema"], capsys)
    assert status == 0 and err == ""
    assert json.loads(out) == json_schema()
    assert out.startswith('{\n  "$schema": "https://json-schema.org/draft/2020-12/schema"')
