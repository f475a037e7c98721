"""Fuzzing the front door: generated scenario documents, valid and broken, through the loader and
the CLI. Every document is either run or refused with exit 2 and a located `FILE:LINE:COL: error:`
message; never a traceback, never exit 1, and nothing written for a refused one."""

from __future__ import annotations

import copy
import math
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from collide2d.runner.command.main import main
from collide2d.runner.scenario.load import (
    BLOCK_KEYS,
    OBJECT_KEYS,
    OUTPUT_KEYS,
    TOP_KEYS,
    WORLD_KEYS,
    Scenario,
    ScenarioError,
    loads,
)
from collide2d.runner.scenario.parse import OptionError

ROOT = Path(__file__).resolve().parents[2]
KNOWN_KEYS = sorted(set(TOP_KEYS + WORLD_KEYS + OBJECT_KEYS + BLOCK_KEYS + OUTPUT_KEYS))

BASE = {
    "version": 1,
    "name": "fuzz",
    "world": {"width": 100, "height": 80, "fps": 10, "background": "black"},
    "model": "paper",
    "ticks": 5,
    "objects": [
        {"shape": "box", "size": [10, 6], "position": [10, 10], "velocity": [10, 0], "mass": 2},
        {"shape": "circle", "diameter": 6, "position": [50, 50], "velocity": [0, 5]},
        {"shape": "polygon", "points": [[0, 0], [5, 0], [0, 5]], "position": [70, 10]},
    ],
    "generate": [{"count": 3, "shape": "box", "size": 4, "speed": 10, "seed": 1}],
    "output": {"frames": [0, 5], "gif": True, "events": True},
    "golden": {"frames": [0, 5], "time_tolerance": 0.0},
}

# Values that probe types, ranges and text: huge and negative numbers, non-finite floats, the
# model names and colours, path-like and unicode text.
NUMBERS = (0, 1, -1, 3, 2**31, 2**63, -(2**70), 10**400, 1e308, -1e-320, 0.5, 1e9, 16385)
NON_NUMBERS = (math.inf, -math.inf, math.nan, True, False, None)
WORDS = ("", "x", "paper", "stepped", "exact", "box", "circle", "polygon", "all", "none", "last")
TEXTS = ("red", "#00ff00", "#0f0", "1e3", "..", "../../etc", "/abs", ".hidden", "é漢字\u202e", "~")
SPECIAL = NUMBERS + NON_NUMBERS + WORDS + TEXTS + ("a" * 300, "yes")
scalars = (
    st.sampled_from(SPECIAL)
    | st.integers(-(10**6), 10**6)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=12)
)


def near_miss(key: str):
    """A key one edit away from a known one (a typo)."""
    return st.sampled_from(
        [key[:-1], key + "s", key[1:] + key[0], key.upper(), key.replace("_", "-"), " " + key]
    )


keys = (
    st.sampled_from(KNOWN_KEYS)
    | st.sampled_from(KNOWN_KEYS).flatmap(near_miss)
    | st.text(max_size=8)
)
values = st.recursive(
    scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(keys, inner, max_size=4),
    max_leaves=12,
)


@st.composite
def mutated_documents(draw):
    """BASE with one to four random edits: replace, delete or add a key or item anywhere."""
    doc = copy.deepcopy(BASE)
    for _ in range(draw(st.integers(1, 4))):
        node = doc
        while True:
            if isinstance(node, dict) and node:
                key = draw(st.sampled_from(sorted(node, key=str)))
            elif isinstance(node, list) and node:
                key = draw(st.integers(0, len(node) - 1))
            else:
                break
            child = node[key]
            descend = isinstance(child, (dict, list)) and child and draw(st.booleans())
            if descend:
                node = child
                continue
            action = draw(st.sampled_from(["replace", "delete", "add"]))
            if action == "replace":
                node[key] = draw(values)
            elif action == "delete":
                del node[key]
            elif isinstance(node, dict):
                node[draw(keys)] = draw(values)
            else:
                node.append(draw(values))
            break
    return yaml.safe_dump(doc, allow_unicode=True, sort_keys=False)


# Pieces of YAML text: structure, anchors and aliases, tags (safe and not), odd scalars and
# characters. Joined at random they give broken and valid text alike.
ATOMS = (
    ("version: 1\n", "world: ", "{", "}", "[", "]", ", ", ": ", "- ", "\n", "  ", "? ", "'", '"')
    + ("&a ", "*a", "&b ", "*b", "<<: *a\n", "|\n  ", ">\n  ", "#c\n", "%YAML 1.1\n", "---\n")
    + ("!!python/object/apply:os.system ", "!!str ", "!!int ", "!!float ", "!!bool ", "!local ")
    + ("!!binary ", "!!set ", "!!timestamp ", "objects:\n", "generate:\n", "shape: box")
    + ("size: 10", "position: [1, 2]", "velocity: [1e3, .5]", "count: 5", "ticks: 3", "name: x")
    + ("1", "-1", "1e999", ".nan", ".inf", "0x1F", "0o17", "1_000", "2001-01-01", "yes", "~")
    + ("\t", "\x00", "\x85", "\ufeff", "é", "...\n", "\\")
)
raw_texts = st.lists(st.sampled_from(ATOMS), min_size=1, max_size=40).map("".join)


def nested(depth: int, opener: str) -> str:
    closer = {"[": "]", "{a: ": "}"}[opener]
    return "version: 1\ndescription: " + opener * depth + "1" + closer * depth + "\n"


deep_texts = st.builds(nested, st.integers(1, 150), st.sampled_from(["[", "{a: "]))


@st.composite
def alias_texts(draw):
    """Aliases: a bomb of `levels` x `width` aliases, or objects repeated through merge keys."""
    levels = draw(st.integers(1, 12))
    width = draw(st.integers(1, 12))
    if draw(st.booleans()):
        lines = ["version: 1", "description:", '  - &l0 "x"']
        for k in range(1, levels + 1):
            lines.append(f"  - &l{k} [" + ", ".join([f"*l{k - 1}"] * width) + "]")
        return "\n".join(lines) + "\n"
    lines = [
        "version: 1",
        "ticks: 4",
        "world: {width: 200, height: 200}",
        "objects:",
        "  - &o {shape: box, size: 3, position: [0, 0], velocity: [10, 10]}",
    ]
    lines += [f"  - {{<<: *o, position: [{5 * k}, {5 * (k % width)}]}}" for k in range(1, levels)]
    lines += ["output: {frames: &f [0, 2]}", "golden: {frames: *f}"]
    return "\n".join(lines) + "\n"


@st.composite
def tweaked_documents(draw):
    """BASE under each model with other rates and velocities: mostly valid documents."""
    doc = copy.deepcopy(BASE)
    model = draw(st.sampled_from(["paper", "stepped", "exact"]))
    doc["model"] = model
    doc["world"]["fps"] = draw(st.integers(1, 30))
    speed = st.integers(-40, 40) if model == "paper" else st.floats(-40, 40)
    for obj in doc["objects"]:
        obj["velocity"] = [draw(speed), draw(speed)]
    doc["output"]["frames"] = draw(st.sampled_from(["all", "none", "last", {"every": 2}, [0, 3]]))
    return yaml.safe_dump(doc, sort_keys=False)


documents = mutated_documents() | tweaked_documents() | raw_texts | deep_texts | alias_texts()


# Line breaks as YAML counts them.
BREAKS = re.compile("\r\n|[\n\r\x85\u2028\u2029]")


def check_located(err: ScenarioError, text: str, path: str) -> None:
    for one in getattr(err, "errors", [err]):  # every error of the file, or the one
        assert one.path == path
        if isinstance(one, OptionError):  # caused by a command-line option: named by it
            assert str(one) == f"{path}: error: {one.message}" and one.message.startswith("--")
            continue
        assert 1 <= one.line <= len(BREAKS.findall(text)) + 2, str(one)
        assert one.col >= 1 and one.message.strip(), str(one)
        assert str(one).startswith(f"{path}:{one.line}:{one.col}: error: ")


# ----------------------------------------------------------------------------- the loader


@settings(max_examples=250, deadline=None)
@given(documents)
def test_the_loader_returns_a_scenario_or_a_located_error(text):
    try:
        sc = loads(text, "doc.yaml")
    except ScenarioError as err:
        check_located(err, text, "doc.yaml")
    else:
        assert isinstance(sc, Scenario)
        assert sc.bodies.pos.shape == (sc.bodies.n, 2)


@settings(max_examples=60, deadline=None)
@given(mutated_documents(), st.sampled_from(["paper", "stepped", "exact"]), st.integers(-3, 40))
def test_overrides_on_fuzzed_documents_are_located_too(text, model, fps):
    try:
        loads(text, "doc.yaml", overrides={"model": model, "fps": fps, "ticks": 3})
    except ScenarioError as err:
        check_located(err, text, "doc.yaml")


@pytest.mark.parametrize(
    ("text", "needle", "fragment"),
    [
        ("!!int generate:\n", "!!int", "'generate' is not a valid !!int value"),
        ("version: 1\nticks: !!int ''\n", "!!int", "'' is not a valid !!int value"),
        ("version: 1\nticks: !!int 0o17[\n", "!!int", "is not a valid !!int value"),
        ("version: 1\nduration: !!float abc\n", "!!float", "'abc' is not a valid !!float"),
        ("version: 1\noutput: {gif: !!bool maybe}\n", "!!bool", "'maybe' is not a valid !!bool"),
    ],
)
def test_explicit_tags_whose_text_does_not_fit_are_located(text, needle, fragment):
    """Found by the fuzzer: `!!int generate` made PyYAML's constructor raise ValueError."""
    with pytest.raises(ScenarioError) as info:
        loads(text)
    index = text.index(needle)
    assert (info.value.line, info.value.col) == (
        text.count("\n", 0, index) + 1,
        index - (text.rfind("\n", 0, index) + 1) + 1,
    )
    assert fragment in info.value.message


def test_explicit_tags_whose_text_fits_still_load():
    sc = loads("version: 1\nticks: !!int '7'\nworld: {fps: !!int 5}\noutput: {gif: !!bool no}\n")
    assert (sc.ticks, sc.world.fps, sc.output.gif) == (7, 5, False)


# ----------------------------------------------------------------------------- the CLI


def tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


LOCATED = re.compile(r"^(?P<path>.+):(?P<line>\d+):(?P<col>\d+): error: \S")


def check_cli(argv, path: str, capsys) -> None:
    status = main(argv)
    out, err = capsys.readouterr()
    assert status in (0, 2), (status, err)
    assert "Traceback" not in err + out
    if status == 2:
        found = LOCATED.match(err.splitlines()[0])
        assert found and found.group("path") == path, err


@settings(
    max_examples=50, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(text=documents)
def test_validate_exits_0_or_2_with_a_located_message(text, capsys):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "doc.yaml"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        check_cli(["validate", str(path)], str(path), capsys)


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(text=mutated_documents() | tweaked_documents() | alias_texts())
def test_run_exits_0_or_2_and_a_refusal_writes_nothing(text, capsys):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "doc.yaml"
        path.write_text(text, encoding="utf-8")
        out = Path(tmp) / "out"
        out.mkdir()
        argv = [
            "run",
            str(path),
            "--out",
            str(out),
            "--quiet",
            "--ticks",
            "3",
            "--max-output-bytes",
            "2000000",
        ]
        status = main(argv)
        stdout, err = capsys.readouterr()
        assert status in (0, 2), err
        assert "Traceback" not in err
        if status == 0:
            assert any(out.rglob("final.csv"))
        elif LOCATED.match(err.splitlines()[0]):
            assert tree(out) == {} and list(out.iterdir()) == []


BROKEN = {
    "python_tag": "version: 1\ndescription: !!python/object/apply:os.system ['echo hi']\n",
    "bad_yaml": "version: 1\nworld: {width: 10\n",
    "typo": "version: 1\nwrold: {width: 10}\n",
    "huge": "version: 1\ngenerate: [{count: 1000000000000, shape: box, size: 1}]\n",
}


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_in_a_separate_process_a_broken_file_is_exit_2_without_traceback(tmp_path, name):
    path = tmp_path / f"{name}.yaml"
    path.write_text(BROKEN[name])
    proc = subprocess.run(
        [sys.executable, "-m", "collide2d", "run", str(path), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert LOCATED.match(proc.stderr.splitlines()[0]).group("path") == str(path)
    assert not (tmp_path / "out").exists()
