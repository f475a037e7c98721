"""The fast lane for long object lists (runner.scenario.fastlane): the same Scenario as the general
path, to the byte, for every file it takes; every file it declines or finds fault with is read, or
refused in the same words at the same place, by the general path."""

from __future__ import annotations

import re

import numpy as np
import pytest

from collide2d.runner.scenario import fastlane, load
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import ScenarioError, loads

HEAD = """version: 1
name: fast
world: {width: 400, height: 300, fps: 10}
model: MODEL
ticks: 2
"""
TAIL = "generate:\n  - {count: 3, shape: box, size: 2, speed: 10, seed: 1}\noutput: {gif: false}\n"


def lines(seed: int, n: int = 40, paper: bool = False) -> list[str]:
    rng = np.random.default_rng(seed)
    cells = rng.choice(20 * 15, n, replace=False)
    out = []
    for k, c in enumerate(cells):
        x, y = int(c % 20 * 20), int(c // 20 * 20)
        if paper:
            vel = f"[{rng.integers(-30, 30)}, {rng.integers(-30, 30)}]"
        else:
            vel = f"[{rng.uniform(-50, 50):.3f}, {-rng.uniform(0, 50):.2f}]"
        kind = k % 5
        if kind == 0:
            out.append(f"  - {{shape: box, size: [10, 6], position: [{x}, {y}], velocity: {vel}}}")
        elif kind == 1:
            out.append(
                f"  - {{shape: circle, diameter: 9, position: [{x}.5, {y}], velocity: "
                f"{vel}, mass: 2.5, color: Red, fill: true}}"
                if not paper
                else f"  - {{shape: circle, diameter: 9, position: [{x}, {y}], mass: 2}}"
            )
        elif kind == 2:
            out.append(
                f"  - {{position: [{x}, {y}], static: true, shape: box, size: 12, "
                f"color: teal, name: wall_{k}}}"
            )
        elif kind == 3:
            out.append(
                f"  - {{shape: box, size: [3, 14], position: [{x}, {y}], velocity: {vel}, "
                f"static: false, color: white, name: b-{k}}}"
            )
        else:
            out.append(f"  - {{shape: box, size: 5, position: [{x}, {y}], mass: 7}}")
    return out


def text(items: list[str], model: str = "stepped") -> str:
    return HEAD.replace("MODEL", model) + "objects:\n" + "\n".join(items) + "\n" + TAIL


@pytest.fixture
def small_lane(monkeypatch):
    """The lane for lists of 3 objects or more, counting the lists it takes."""
    monkeypatch.setattr(fastlane, "FAST_MIN_OBJECTS", 3)
    taken = []
    real = fastlane.table

    def table(*args, **kw):
        result = real(*args, **kw)
        taken.append(result.n)
        return result

    monkeypatch.setattr(fastlane, "table", table)
    return taken


def general(source: str, **kw):
    """The same text through the general path alone."""
    real = fastlane.split
    fastlane.split = lambda text: None
    try:
        return loads(source, **kw)
    finally:
        fastlane.split = real


def same(a, b):
    fields = ("kind", "pos", "size", "vel", "mass", "static", "vert_start", "verts")
    for field in (*fields, "restitution", "friction"):
        x, y = getattr(a.bodies, field), getattr(b.bodies, field)
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), field
    assert a.bodies.looks.color.tobytes() == b.bodies.looks.color.tobytes()
    assert a.bodies.looks.fill.tobytes() == b.bodies.looks.fill.tobytes()
    assert a.palette.tobytes() == b.palette.tobytes()
    assert (a.names, a.lines, a.ticks, a.output, a.golden) == (
        b.names,
        b.lines,
        b.ticks,
        b.output,
        b.golden,
    )


@pytest.mark.parametrize("model", ["paper", "stepped", "exact"])
@pytest.mark.parametrize("seed", [0, 1])
def test_the_lane_gives_the_scenario_of_the_general_path(small_lane, model, seed):
    source = text(lines(seed, paper=model == "paper"), model)
    same(loads(source), general(source))
    assert small_lane == [40]  # the lane took the list


def reads_as_general(source: str) -> None:
    """`source` gives the Scenario of the general path, or is refused in its very words."""
    try:
        expected = general(source)
    except ScenarioError as err:
        with pytest.raises(ScenarioError) as info:
            loads(source)
        assert str(info.value) == str(err)
    else:
        same(loads(source), expected)


def at(k, old, new):
    """A change of line k of the list."""
    return lambda ls: ls[:k] + [ls[k].replace(old, new)] + ls[k + 1 :]


@pytest.mark.parametrize(
    "change",
    [
        lambda ls: ls[:5] + [ls[0]] + ls[5:],  # an overlap
        at(0, "size: [10, 6]", "size: [10, 0]"),
        at(0, "shape: box", "shape: blob"),
        at(2, "teal", "tael"),
        at(4, "mass: 7", "mass: 0"),
        at(4, "mass: 7", "mass: heavy"),
        at(2, "name: wall_2", "name: yes"),
        at(0, "shape: box", "shape: box, shape: box"),
        at(0, "shape: box", "shap: box"),
        at(0, "position: [", "position: [0"),
        lambda ls: ls[:3] + ["  # a comment"] + ls[3:],
        at(0, "size: [10, 6]", "size: [10, 6], velocity: [2e9, 0]"),
        at(0, "size: [10, 6]", "size: [10, 6], velocity: [1000000001, 0]"),
        at(0, "position: [", "position: [399"),
        at(1, "Red", "'Red'"),
        at(3, "static: false", "static: true"),
        at(3, "name: b-3", "name: wall_2"),  # two objects of one name
    ],
)
def test_what_the_lane_declines_the_general_path_reads_or_refuses(small_lane, change):
    source = text(change(lines(3)))
    reads_as_general(source)
    assert small_lane == []  # declined (or found at fault) before the lane gave any objects


def test_paper_rules_send_a_list_to_the_general_path(small_lane):
    items = lines(5, paper=True)
    items[3] = items[3].replace("position: [", "position: [0.5").replace("[0.5", "[1.5")
    source = text(items, "paper")
    with pytest.raises(ScenarioError) as info:
        loads(source)
    with pytest.raises(ScenarioError) as again:
        general(source)
    assert str(info.value) == str(again.value)
    assert "whole number of pixels under the paper model" in str(info.value)


def test_no_room_under_the_exact_model_is_refused_at_the_object(small_lane):
    items = lines(6)
    items.append("  - {shape: box, size: [400, 1], position: [0, 299], velocity: [3, 0]}")
    source = text(items, "exact")
    with pytest.raises(ScenarioError) as info:
        loads(source)
    with pytest.raises(ScenarioError) as again:
        general(source)
    assert str(info.value) == str(again.value) and "no room" in str(info.value)


def test_limits_hold_in_the_lane(small_lane):
    source = text(lines(7))
    with pytest.raises(ScenarioError) as info:
        loads(source, limits=Limits(max_objects=39))
    assert "past the limit of 39 objects" in str(info.value)
    with pytest.raises(ScenarioError) as info:
        loads(source, limits=Limits(max_yaml_nodes=500))
    assert "more than 500 YAML values" in str(info.value)


def test_a_list_inside_a_text_is_not_taken_for_objects(small_lane):
    items = lines(8)
    source = (
        HEAD.replace("MODEL", "stepped")
        + 'description: "a\nobjects:\n'
        + "\n".join(items)
        + '\nb"\n'
        + TAIL
    )
    same(loads(source), general(source))
    assert small_lane == []
    assert load.loads(source).bodies.n == 3


def one_form(kind: int, n: int = 30) -> list[str]:
    """Lines of one form only (the same keys, in one order, with values of the same kinds): the
    lane then takes the list's columns whole instead of line by line."""
    return lines(kind + 11, 150)[kind::5][:n]


@pytest.mark.parametrize("kind", [0, 1, 2, 3, 4])
def test_a_list_of_one_form_gives_the_scenario_of_the_general_path(small_lane, kind):
    items = one_form(kind)
    assert fastlane.split(text(items)).same is not None
    source = text(items)
    same(loads(source), general(source))
    assert small_lane == [len(items)]


@pytest.mark.parametrize(
    "change",
    [
        at(4, "shape: box", "shape: circle"),
        at(4, "size: 12", "size: [12, 12]"),
        at(4, "name: wall_", "name: yes_"),
        at(4, "teal", "no"),
        at(4, "static: true", "static: on"),
        lambda ls: ls[:4] + [ls[4].replace("  - ", "   - ")] + ls[5:],
        lambda ls: ls[:4] + [ls[4] + "  "] + ls[5:],
    ],
)
def test_one_form_with_a_line_apart_reads_as_the_general_path(small_lane, change):
    source = text(change(one_form(2)))
    reads_as_general(source)


def block(items: list[str], indent: int = 2, pairs: str = "lines") -> list[str]:
    """The flow lines `items` written in block style, as `yaml.safe_dump` and generators write
    them: the dash at `indent`, each key on its own line, an [x, y] pair as two `- number` lines
    at the key's indent ("lines"), two spaces deeper ("deeper"), or inline ("inline")."""
    out = []
    pad = " " * indent
    for item in items:
        body = item.strip()[3:-1]
        fields = re.findall(r"([a-z]+): (\[[^\]]*\]|[^,]+)", body)
        for k, (key, value) in enumerate(fields):
            lead = pad + ("- " if k == 0 else "  ")
            if value.startswith("[") and pairs != "inline":
                x, y = (v.strip() for v in value[1:-1].split(","))
                under = pad + "  " + ("  " if pairs == "deeper" else "")
                out += [f"{lead}{key}:", f"{under}- {x}", f"{under}- {y}"]
            else:
                out.append(f"{lead}{key}: {value}")
    return out


@pytest.mark.parametrize("pairs", ["lines", "deeper", "inline"])
@pytest.mark.parametrize("indent", [0, 2, 4])
@pytest.mark.parametrize("model", ["paper", "stepped", "exact"])
def test_a_block_style_list_gives_the_scenario_of_the_general_path(
    small_lane, model, indent, pairs
):
    items = lines(9, paper=model == "paper")
    source = text(block(items, indent, pairs), model)
    same(loads(source), general(source))
    assert small_lane == [40]  # the lane took the list
    flow = loads(text(items, model))
    assert flow.bodies.pos.tobytes() == loads(source).bodies.pos.tobytes()


@pytest.mark.parametrize("kind", [0, 2, 3])
def test_a_block_style_list_of_one_form_is_taken_whole(small_lane, kind):
    source = text(block(one_form(kind)))
    assert fastlane.split(source).same is not None
    same(loads(source), general(source))
    assert small_lane == [30]


def block_at(k, old, new):
    """A change of line k of a block-style list."""
    return lambda ls: ls[:k] + [ls[k].replace(old, new)] + ls[k + 1 :]


@pytest.mark.parametrize(
    "change",
    [
        block_at(1, "  size:", "   size:"),  # a key off the item's indent
        block_at(2, "  - 10", "    - 10"),  # a pair's lines at two indents
        block_at(0, "shape: box", "shape: box # a comment"),
        block_at(0, "shape: box", "shape: 'box'"),
        block_at(1, "size:", "size: &a"),
        lambda ls: ls[:3] + [""] + ls[3:],  # a blank line inside the list
        lambda ls: ls[:3] + ["  - 3"] + ls[3:],  # a pair of three
        lambda ls: ls[:1] + ["  size: 4"] + ls[1:],  # a key twice
        block_at(4, "position:", "position: "),
        block_at(0, "shape: box", "shape: box  "),
        block_at(1, "size:", "size:\n    - [10, 6]"),
        lambda ls: ls[:6] + [ls[6] + "\n    - 9"] + ls[7:],  # a list under the pair
    ],
)
def test_what_the_block_lane_declines_the_general_path_reads_or_refuses(small_lane, change):
    items = block(lines(3), 2, "lines")
    source = text(change(items))
    reads_as_general(source)
    assert small_lane == []  # declined (or found at fault) before the lane gave any objects


def test_a_block_style_object_is_refused_at_its_own_line(small_lane):
    items = lines(6)
    items.append("  - {shape: box, size: [400, 1], position: [0, 299], velocity: [3, 0]}")
    source = text(block(items), "exact")
    with pytest.raises(ScenarioError) as info:
        loads(source)
    with pytest.raises(ScenarioError) as again:
        general(source)
    assert str(info.value) == str(again.value) and "no room" in str(info.value)
