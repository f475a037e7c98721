"""Reading the file safely: bytes, encodings, YAML syntax, tags, nesting, aliases, located."""

from __future__ import annotations

import time

import pytest
import yaml
from scenario_text import BASE, DATA, at, check_refused, objects, refused

from collide2d.runner.scenario import parse
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import ScenarioError, load, loads

# ----------------------------------------------------------------------------- reading the file


def test_non_utf8_bytes_are_located(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_bytes(b"version: 1\ndescription: caf\xe9 ok\n")
    with pytest.raises(ScenarioError) as info:
        load(path)
    assert (info.value.line, info.value.col) == (2, 17)
    assert "not UTF-8" in info.value.message


def test_a_byte_order_mark_is_fine(tmp_path):
    path = tmp_path / "bom.yaml"
    path.write_bytes(b"\xef\xbb\xbfversion: 1\nname: bom\n")
    assert load(path).name == "bom"


def test_missing_file_is_a_located_error(tmp_path):
    with pytest.raises(ScenarioError) as info:
        load(tmp_path / "nope.yaml")
    assert (info.value.line, info.value.col) == (1, 1) and "cannot read" in info.value.message


@pytest.mark.parametrize("text", ["", "\n\n", "# just a comment\n"])
def test_empty_file(text):
    err = refused(text)
    assert (err.line, err.col) == (1, 1) and "empty" in err.message


@pytest.mark.parametrize("text", ["- 1\n- 2\n", "just words\n", "12\n"])
def test_top_level_must_be_a_mapping(text):
    err = refused(text)
    assert (err.line, err.col) == (1, 1) and "must be a mapping" in err.message


def test_yaml_syntax_errors_are_located():
    # the tab cannot start a token: it is the first character of line 3, and is explained
    check_refused("version: 1\nobjects:\n\t- x\n", "\t", "a tab character in the indentation")
    # the flow mapping is never closed; the parser notices at the next line's key
    check_refused("version: 1\nworld: {width: 10\nticks: 5\n", ": 5", "invalid YAML")


def test_control_character_is_located():
    check_refused("version: 1\nname: a\x07b\n", "\x07", "invalid character U+0007")


def test_second_document_refused():
    check_refused("version: 1\n---\nversion: 1\n", "---", "one YAML document")


def test_python_tags_are_refused_at_their_place():
    text = BASE + "description: !!python/object/apply:os.system ['echo hi']\n"
    check_refused(text, "!!python", "YAML tag '!!python/object/apply:os.system' is not allowed")
    check_refused(
        BASE + "objects: !!python/object:collections.OrderedDict {}\n", "!!python", "not allowed"
    )
    check_refused(BASE + "ticks: !custom 3\n", "!custom", "YAML tag '!custom' is not allowed")


def test_safe_tags_are_fine():
    assert loads(BASE + "ticks: !!int '7'\n").ticks == 7


PARSERS = [yaml.SafeLoader] + ([yaml.CSafeLoader] if hasattr(yaml, "CSafeLoader") else [])


@pytest.fixture(params=PARSERS, ids=lambda loader: loader.__name__)
def parser(request, monkeypatch):
    """Each YAML parser PyYAML offers here: pure Python always, libyaml's when it is built in."""
    monkeypatch.setattr(parse, "_LOADER", request.param)
    return request.param


@pytest.mark.parametrize("depth", [65, 1_000, 100_000])
def test_deep_flow_nesting_refused_at_our_bound_with_every_parser(parser, depth):
    text = "version: 1\ndescription: " + "[" * depth + "]" * depth + "\n"
    err = refused(text)
    # the top mapping is level 1, so the 64th bracket opens level 65, whatever limits of its own
    # the parser has further on
    assert (err.line, err.col) == (2, len("description: ") + 64)
    assert "nested more than 64 levels" in err.message


def test_deep_block_nesting_refused_at_our_bound_with_every_parser(parser):
    text = "version: 1\ndescription:\n" + "".join(" " * (2 * k) + f"k{k}:\n" for k in range(1, 200))
    err = refused(text)
    assert (err.line, err.col) == at(text, "k64:")
    assert "nested more than 64 levels" in err.message


def test_nesting_at_our_bound_is_read(parser):
    # 63 brackets inside the top mapping: 64 levels, the most allowed
    text = "version: 1\nworld: {width: 100, height: 80}\nname: deep\nx: " + "[" * 63
    err = refused(text + "]" * 63 + "\n")
    assert "unknown key 'x'" in err.message


def test_invalid_yaml_is_reported_in_the_same_words_with_every_parser():
    text = "version: 1\nworld: {width: 100, height: 80\nobjects: []\n"
    seen = set()
    for loader in PARSERS:
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(parse, "_LOADER", loader)
            seen.add(str(refused(text)))
    assert len(seen) == 1, seen
    assert "invalid YAML" in seen.pop()


def test_billion_laughs_refused_fast_at_the_alias():
    text = (DATA / "billion_laughs.yaml").read_text()
    start = time.perf_counter()
    err = refused(text)
    assert time.perf_counter() - start < 1.0
    # Aliases repeat 9 * 1 (lol1) + 9 * 10 (lol2) + 9 * 91 (lol3) + 9 * 820 (lol4) = 8298 nodes;
    # the first *lol4 inside lol5 repeats 7381 more, passing the bound of 10000 there.
    assert (err.line, err.col) == at(text, "*lol4")
    assert "aliases repeat more than 10000 YAML nodes" in err.message


def test_alias_bound_is_a_limit():
    text = objects("&a {shape: box, size: 10, position: [0, 0]}", "{<<: *a, position: [20, 0]}")
    assert loads(text).bodies.n == 2
    # the alias repeats the 7-node mapping {shape, size, position: [x, y]} and its values
    err = refused(text, limits=Limits(max_alias_nodes=5))
    assert (err.line, err.col) == at(text, "*a")


def test_recursive_alias_refused():
    check_refused(BASE + "objects: &a [*a]\n", "*a", "refers to a node that contains it")


def test_merge_keys_and_explicit_keys_win():
    text = objects(
        "&base {shape: box, size: 10, position: [0, 0], color: red}",
        "{<<: *base, position: [20, 0], color: blue}",
    )
    sc = loads(text)
    assert sc.bodies.size.tolist() == [[10, 10], [10, 10]]
    assert sc.bodies.pos.tolist() == [[0, 0], [20, 0]]
    assert sc.palette[sc.bodies.looks.color].tolist() == [[255, 0, 0], [0, 0, 255]]


def test_duplicate_key_refused():
    text = BASE + "ticks: 3\nticks: 4\n"
    err = check_refused(text, "ticks", "duplicate key 'ticks'", nth=1)
    assert f"first on line {at(text, 'ticks')[0]}" in err.message
