"""Scenario loading: every refusal of docs/scenario-format.md and docs/limits.md at its
FILE:LINE:COL, and what loads."""

from __future__ import annotations

import hashlib
import math
import pickle
import time

import numpy as np
import pytest
from scenario_text import BASE, DATA, at, check_refused, objects, refused

from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import ScenarioError, load, loads

# ----------------------------------------------------------------------------- the error type


def test_error_text_and_fields():
    err = ScenarioError("a/b.yaml", 3, 7, "boom")
    assert str(err) == "a/b.yaml:3:7: error: boom"
    assert (err.path, err.line, err.col, err.message) == ("a/b.yaml", 3, 7, "boom")
    again = pickle.loads(pickle.dumps(err))
    assert str(again) == str(err)


# ----------------------------------------------------------------------------- what loads


def test_spec_example_loads_as_written():
    path = DATA / "spec_example.yaml"
    sc = load(path)
    assert sc.path == str(path)
    assert sc.text_sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert sc.name == "tunnelling-1fps"
    assert sc.description == "Two boxes pass through each other at 1 fps."
    assert (sc.world.width, sc.world.height, sc.world.fps) == (320, 240, 1)
    assert (sc.model, sc.substeps, sc.geometry, sc.ticks) == ("paper", 1, "box", 12)
    b = sc.bodies
    assert b.n == 4 + 50
    assert list(b.kind[:4]) == [KIND_BOX, KIND_BOX, KIND_CIRCLE, KIND_POLYGON]
    assert np.all(b.kind[4:] == KIND_BOX)
    assert b.pos[:4].tolist() == [[100, 115], [200, 115], [40, 40], [60, 60]]
    # polygon [[0, 9], [5, 0], [10, 9]]: pixels 0..10 by 0..9, an 11 x 10 box
    assert b.size[:4].tolist() == [[10, 10], [10, 10], [12, 12], [11, 10]]
    assert b.vel[:4].tolist() == [[10, 0], [-10, 0], [5, -5], [0, 0]]
    assert b.mass[:3].tolist() == [1, 2, 1] and b.mass[3] == math.inf
    assert b.static.tolist()[:4] == [False, False, False, True]
    # palette: background black, then red, #00ff00, white (the circle's default, then generated)
    assert sc.palette.tolist() == [[0, 0, 0], [255, 0, 0], [0, 255, 0], [255, 255, 255]]
    assert sc.palette.dtype == np.uint8
    assert b.looks.color.tolist() == [1, 2, 3, 3] + [3] * 50
    assert b.vert_start.tolist()[:6] == [0, 0, 0, 0, 3, 3]
    assert b.vert_start[-1] == 3
    assert b.verts.tolist() == [[0, 9], [5, 0], [10, 9]]
    assert sc.lines[:4] == (8, 9, 10, 11) and set(sc.lines[4:]) == {13}
    assert sc.names == (None,) * 54
    assert tuple(sc.output.frames) == tuple(range(13)) and sc.output.frames_spec == "all"
    assert sc.output.gif and sc.output.events
    assert sc.golden.frames == (0, 6, 12)
    assert sc.golden.time_tolerance == 0.0 and sc.golden.max_diff_pixels == 0
    # speed 10: every generated component is +-10
    assert np.all(np.abs(b.vel[4:]) == 10)


def test_defaults():
    sc = loads("version: 1\n")
    assert sc.path is None and sc.name == "scenario" and sc.description == ""
    assert (sc.world.width, sc.world.height, sc.world.fps) == (320, 240, 10)
    assert sc.background == (0, 0, 0)
    assert (sc.model, sc.substeps, sc.geometry) == ("paper", 1, "box")
    assert sc.ticks == 100  # 10 s at 10 fps
    assert tuple(sc.output.frames) == () and sc.output.frames_spec == "none"
    assert sc.output.gif is True and sc.output.events is True
    assert sc.golden.frames == (0, 50, 100)
    assert (sc.golden.time_tolerance, sc.golden.max_diff_pixels, sc.golden.color_threshold) == (
        0.0,
        0,
        0,
    )
    assert sc.bodies.n == 0 and sc.bodies.pos.shape == (0, 2)
    assert sc.bodies.vert_start.tolist() == [0] and sc.bodies.verts.shape == (0, 2)
    assert sc.palette.tolist() == [[0, 0, 0]]
    assert sc.text_sha256 == hashlib.sha256(b"version: 1\n").hexdigest()


def test_object_defaults():
    sc = loads(objects("{shape: box, size: 10, position: [1, 2]}"))
    b = sc.bodies
    assert b.vel.tolist() == [[0, 0]] and b.mass.tolist() == [1.0]
    assert b.static.tolist() == [False] and b.looks.fill.tolist() == [False]
    assert sc.palette[b.looks.color[0]].tolist() == [255, 255, 255]
    assert sc.names == (None,)


def test_object_fields():
    sc = loads(
        objects(
            "{shape: circle, diameter: 7, position: [1, 2], velocity: [3, -4], "
            "mass: 2.5, fill: true, name: ball, color: [1, 2, 3]}"
        )
    )
    b = sc.bodies
    assert b.kind.tolist() == [KIND_CIRCLE] and b.size.tolist() == [[7, 7]]
    assert (
        b.vel.tolist() == [[3, -4]] and b.mass.tolist() == [2.5] and b.looks.fill.tolist() == [True]
    )
    assert sc.names == ("ball",) and sc.palette[b.looks.color[0]].tolist() == [1, 2, 3]
    for arr, dtype in (
        (b.pos, np.float64),
        (b.vel, np.float64),
        (b.size, np.float64),
        (b.kind, np.int8),
        (b.looks.color, np.uint8),
        (b.verts, np.int64),
    ):
        assert arr.dtype == dtype


@pytest.mark.parametrize(
    ("model", "geometry"),
    [
        ("paper", "box"),
        ("stepped", "box"),
        ("exact", "exact"),
        ("{kind: stepped, geometry: exact}", "exact"),
        ("{kind: exact, geometry: box}", "box"),
    ],
)
def test_geometry_defaults(model, geometry):
    assert loads(BASE + f"model: {model}\n").geometry == geometry


def test_model_mapping():
    sc = loads(BASE + "model: {kind: stepped, substeps: 8}\n")
    assert (sc.model, sc.substeps, sc.geometry) == ("stepped", 8, "box")


@pytest.mark.parametrize(
    ("duration", "fps", "ticks"),
    [("2.5", 10, 25), ("12", 1, 12), ("0", 10, 0), ("0.05", 10, 1), ("0.04", 10, 0)],
)
def test_duration_counts_ticks(duration, fps, ticks):
    # ticks = duration * fps rounded to the nearest whole tick, halves up (0.05 s * 10 = 0.5 -> 1)
    sc = loads(f"version: 1\nworld: {{fps: {fps}}}\nduration: {duration}\n")
    assert sc.ticks == ticks


def test_whole_floats_count_as_integers_and_exponents_as_numbers():
    sc = loads(objects("{shape: box, size: [10.0, 4], position: [2.0, 0], velocity: [1.5e1, 0]}"))
    assert sc.bodies.size.tolist() == [[10, 4]] and sc.bodies.vel.tolist() == [[15, 0]]
    text = objects("{shape: box, size: 10, position: [0, 0], velocity: ['1e3', 0]}")
    check_refused(text, "'1e3'", "must be a number, not the text '1e3'")


def test_polygon_box_of_pixels_and_normalised_vertices():
    sc = loads(objects("{shape: polygon, points: [[-2, 3], [4, -1], [6, 5]], position: [20, 20]}"))
    b = sc.bodies
    # minimum point (-2, -1), maximum (6, 5): box top-left (18, 19), size (9, 7)
    assert b.pos.tolist() == [[18, 19]] and b.size.tolist() == [[9, 7]]
    assert b.verts.tolist() == [[0, 4], [6, 0], [8, 6]]
    assert b.vert_start.tolist() == [0, 3]


def test_several_polygons_share_the_vertex_array():
    sc = loads(
        objects(
            "{shape: polygon, points: [[0, 0], [4, 0], [0, 4]], position: [0, 0]}",
            "{shape: box, size: 3, position: [10, 10]}",
            "{shape: polygon, points: [[1, 1], [5, 1], [5, 5], [1, 5]], position: [30, 30]}",
        )
    )
    b = sc.bodies
    assert b.vert_start.tolist() == [0, 3, 3, 7]
    assert b.verts[3:].tolist() == [[0, 0], [4, 0], [4, 4], [0, 4]]
    assert b.pos[2].tolist() == [31, 31] and b.size[2].tolist() == [5, 5]


def test_names_and_lines(tmp_path):
    text = objects(
        "{shape: box, size: 5, position: [0, 0], name: a}",
        "{shape: box, size: 5, position: [10, 0]}",
    ) + ("generate:\n  - {count: 3, shape: circle, diameter: 3, name: dot, seed: 1}\n")
    sc = loads(text)
    assert sc.names == ("a", None, "dot-0", "dot-1", "dot-2")
    line_a = at(text, "{shape: box, size: 5, position: [0, 0]")[0]
    block = at(text, "{count: 3")[0]
    assert sc.lines == (line_a, line_a + 1, block, block, block)
    assert sc.bodies.kind.tolist() == [KIND_BOX, KIND_BOX] + [KIND_CIRCLE] * 3


def test_name_defaults_to_the_file_stem(tmp_path):
    path = tmp_path / "my-scene.v2.yaml"
    path.write_text("version: 1\n")
    assert load(path).name == "my-scene.v2"
    bad = tmp_path / "My Scene.yaml"
    bad.write_text("version: 1\n")
    with pytest.raises(ScenarioError) as info:
        load(bad)
    err = info.value
    assert (err.path, err.line, err.col) == (str(bad), 1, 1)
    assert "add a 'name:'" in err.message


def test_loads_takes_its_default_name_from_a_given_path():
    assert loads("version: 1\n", path="dir/wall-test.yaml").name == "wall-test"


# ----------------------------------------------------------------------------- keys


@pytest.mark.parametrize(
    ("text", "bad", "message"),
    [
        (BASE + "nmae: x\n", "nmae", "unknown key 'nmae' in the scenario; did you mean 'name'?"),
        (
            "version: 1\nworld: {widht: 10}\n",
            "widht",
            "unknown key 'widht' in world; did you mean 'width'?",
        ),
        (
            BASE + "model: {kind: stepped, substep: 2}\n",
            "substep",
            "unknown key 'substep' in model; did you mean 'substeps'?",
        ),
        (
            objects("{shape: box, size: 10, position: [0, 0], velocty: [1, 0]}"),
            "velocty",
            "unknown key 'velocty' in object; did you mean 'velocity'?",
        ),
        (
            objects("{shape: box, size: 10, position: [0, 0], colour: red}"),
            "colour",
            "unknown key 'colour' in object; did you mean 'color'?",
        ),
        (
            BASE + "generate:\n  - {cont: 3, shape: box, size: 2}\n",
            "cont",
            "unknown key 'cont' in generate block; did you mean 'count'?",
        ),
        (
            BASE + "generate:\n  - {count: 3, shape: box, size: 2, speed: {mn: 1, max: 2}}\n",
            "mn",
            "unknown key 'mn' in speed; did you mean 'min'?",
        ),
        (
            BASE + "output: {frame: all}\n",
            "frame",
            "unknown key 'frame' in output; did you mean 'frames'?",
        ),
        (
            BASE + "golden: {time_tolerence: 0.1}\n",
            "time_tolerence",
            "unknown key 'time_tolerence' in golden; did you mean 'time_tolerance'?",
        ),
        (
            BASE + "output: {frames: {evry: 2}}\n",
            "evry",
            "unknown key 'evry' in output.frames; did you mean 'every'?",
        ),
    ],
)
def test_unknown_keys_suggest_the_near_spelling(text, bad, message):
    check_refused(text, bad, message)


def test_unknown_key_with_nothing_near_lists_the_keys():
    err = check_refused(BASE + "zzzzzz: 1\n", "zzzzzz", "unknown key 'zzzzzz' in the scenario")
    assert "expected one of version, name" in err.message


def test_keys_must_be_names():
    check_refused(BASE + "3: x\n", "3:", "keys in the scenario must be names")


# ----------------------------------------------------------------------------- types and values


@pytest.mark.parametrize(
    ("text", "bad", "message"),
    [
        ("version: 2\n", "2", "version must be 1"),
        ("version: '1'\n", "'1'", "version must be 1"),
        ("name: x\n", "name", "missing 'version: 1'"),
        (
            "version: 1\nworld: {width: abc}\n",
            "abc",
            "world.width must be a whole number of pixels, not the text 'abc'",
        ),
        ("version: 1\nworld: {width: 0}\n", "0}", "world.width must be at least 1 px"),
        ("version: 1\nworld: {height: -5}\n", "-5", "world.height must be at least 1 px"),
        (
            "version: 1\nworld: {fps: 2.5}\n",
            "2.5",
            "world.fps must be a whole number of ticks per second",
        ),
        ("version: 1\nworld: {fps: 0}\n", "0}", "world.fps must be at least 1"),
        ("version: 1\nworld: {fps: 10001}\n", "10001", "world.fps must be at most 10000"),
        ("version: 1\nworld: [1, 2]\n", "[1", "world must be a mapping"),
        ("version: 1\nworld: {background: blurple}\n", "blurple", "unknown colour 'blurple'"),
        (BASE + "ticks: true\n", "true", "ticks must be a whole number, not the boolean true"),
        (BASE + "ticks: -1\n", "-1", "ticks must be at least 0"),
        (BASE + "ticks: 1.5\n", "1.5", "ticks must be a whole number"),
        (BASE + "duration: -2\n", "-2", "duration must be at least 0 s"),
        (BASE + "duration: .inf\n", ".inf", "duration must be a finite number"),
        (BASE + "duration: ten\n", "ten", "duration must be a number, not the text 'ten'"),
        (BASE + "description: 12\n", "12", "description must be text"),
        (BASE + "name: 12\n", "12", "name must be text"),
        (BASE + "model: stepd\n", "stepd", "unknown model 'stepd'; did you mean 'stepped'?"),
        (BASE + "model: 3\n", "3", "unknown model 3"),
        (BASE + "model: {substeps: 2}\n", "{", "model is missing 'kind'"),
        (BASE + "model: {kind: stepped, substeps: 0}\n", "0}", "model.substeps must be at least 1"),
        (
            BASE + "model: {kind: exact, substeps: 2}\n",
            "2}",
            "substeps applies to the stepped model",
        ),
        (
            BASE + "model: {kind: stepped, max_events_per_tick: 10}\n",
            "10}",
            "max_events_per_tick applies to the exact model only, not to stepped",
        ),
        (
            BASE + "model: {kind: exact, max_events_per_tick: 0}\n",
            "0}",
            "model.max_events_per_tick must be at least 1",
        ),
        (
            BASE + "model: {kind: paper, geometry: exact}\n",
            "exact}",
            "geometry 'exact' is not available with the paper model",
        ),
        (BASE + "model: {kind: stepped, geometry: round}\n", "round", "unknown geometry 'round'"),
        (BASE + "objects: {shape: box}\n", "{", "or {file: NAME} naming a table, not a mapping"),
        (BASE + "objects:\n  - 3\n", "3", "object must be a mapping"),
        (BASE + "output: {gif: 1}\n", "1}", "output.gif must be true or false"),
        (BASE + "output: {events: 'yes'}\n", "'yes'", "output.events must be true or false"),
        (BASE + "output: {frames: al}\n", "al}", "did you mean 'all'?"),
        (BASE + "output: {frames: 3}\n", "3}", "must be all, none, last, a list of frame numbers"),
        (BASE + "output: {frames: {every: 0}}\n", "0}", "output.frames.every must be at least 1"),
        (BASE + "output: {frames: [0, -1]}\n", "-1", "output.frames item must be at least 0"),
        (
            BASE + "golden: {time_tolerance: -0.5}\n",
            "-0.5",
            "golden.time_tolerance must be at least 0 s",
        ),
        (BASE + "golden: {max_diff_pixels: -1}\n", "-1", "golden.max_diff_pixels must be at least"),
        (
            BASE + "golden: {color_threshold: 256}\n",
            "256",
            "golden.color_threshold must be at most 255",
        ),
        (
            BASE + "golden: {frames: [0, 101]}\n",
            "101",
            "golden.frames: frame 101 is past the last frame, 100",
        ),
    ],
)
def test_bad_values_at_their_place(text, bad, message):
    skip = text.count(bad, 0, len(BASE)) if text.startswith(BASE) else 0
    check_refused(text, bad, message, nth=skip)


def test_ticks_and_duration_together():
    check_refused(BASE + "ticks: 10\nduration: 2\n", "duration", "either 'ticks' or 'duration'")


@pytest.mark.parametrize(
    ("obj", "bad", "message"),
    [
        (
            "{shape: box, size: 10, position: [0, 0], mass: .inf}",
            ".inf",
            "objects[0].mass must be a finite number",
        ),
        (
            "{shape: box, size: 10, position: [0, 0], mass: true}",
            "true",
            "objects[0].mass must be a number, not the boolean true",
        ),
        (
            "{shape: box, size: 10, position: [0, 0], mass: 0}",
            "0}",
            "objects[0].mass must be at least 1e-15, not 0",
        ),
        (
            "{shape: box, size: 10, position: [0, 0], mass: -1}",
            "-1",
            "objects[0].mass must be at least 1e-15, not -1",
        ),
        (
            "{shape: box, size: 10, position: [0, 0], velocity: [.nan, 0]}",
            ".nan",
            "objects[0].velocity x must be a finite number",
        ),
        (
            "{shape: box, size: 10, position: [0, 0], velocity: [1, a]}",
            "a]",
            "objects[0].velocity y must be a number, not the text 'a'",
        ),
        (
            "{shape: box, size: 10, position: [0, 0], velocity: [1, 2, 3]}",
            "[1, 2, 3]",
            "objects[0].velocity must be a list of 2 numbers",
        ),
        ("{shape: box, size: 10, position: here}", "here", "objects[0].position must be a list"),
        (
            "{shape: box, size: 10, position: [0, 0], velocity: [2e9, 0]}",
            "2e9",
            "objects[0].velocity x must be at most 1000000000 px/s",
        ),
        ("{shape: box, size: 0, position: [0, 0]}", "0,", "objects[0].size must be at least 1 px"),
        (
            "{shape: box, size: [4, -1], position: [0, 0]}",
            "-1",
            "objects[0].size h must be at least",
        ),
        (
            "{shape: box, size: [1, 2, 3], position: [0, 0]}",
            "[1, 2, 3]",
            "objects[0].size must be one number or [w, h]",
        ),
        (
            "{shape: box, size: 10.5, position: [0, 0]}",
            "10.5",
            "objects[0].size must be a whole number of pixels",
        ),
        (
            "{shape: circle, diameter: 0, position: [0, 0]}",
            "0,",
            "objects[0].diameter must be at least 1 px",
        ),
        (
            "{shape: circle, diameter: 2.5, position: [0, 0]}",
            "2.5",
            "objects[0].diameter must be a whole number of pixels",
        ),
        (
            "{shape: polygon, points: [[0, 0], [1, 1]], position: [0, 0]}",
            "[[0",
            "objects[0].points needs at least 3 items, not 2",
        ),
        (
            "{shape: polygon, points: [[0, 0], [1, 1], [2.5, 0]], position: [0, 0]}",
            "2.5",
            "objects[0].points[2] x must be a whole number of pixels",
        ),
        (
            "{shape: polygon, points: [[0, 0], [1, 1], [2]], position: [0, 0]}",
            "[2]",
            "objects[0].points[2] must be [x, y]",
        ),
        ("{size: 10, position: [0, 0]}", "{", "objects[0] is missing 'shape'"),
        (
            "{shape: crcle, diameter: 3, position: [0, 0]}",
            "crcle",
            "unknown shape 'crcle'; did you mean 'circle'?",
        ),
        (
            "{shape: circle, size: 10, position: [0, 0]}",
            "size",
            "'size' does not apply to a circle; a circle takes 'diameter'",
        ),
        (
            "{shape: box, points: [[0, 0], [1, 0], [0, 1]], position: [0, 0]}",
            "points",
            "'points' does not apply to a box",
        ),
        ("{shape: box, position: [0, 0]}", "{", "objects[0] (box) is missing 'size'"),
        ("{shape: box, size: 3}", "{", "objects[0] is missing 'position'"),
        (
            "{shape: box, size: 3, position: [0, 0], fill: 'no'}",
            "'no'",
            "objects[0].fill must be true or false",
        ),
        (
            "{shape: box, size: 3, position: [0, 0], name: [a]}",
            "[a]",
            "objects[0].name must be a single value",
        ),
        (
            "{shape: box, size: 3, position: [0, 0], static: true, velocity: [1, 0]}",
            "1, 0]",
            "objects[0].velocity x must be 0: the object is static, so it cannot move",
        ),
        (
            "{shape: box, size: 3, position: [0, 0], static: true, mass: 3}",
            "3}",
            "objects[0].mass must not be given: the object is static, so its mass is infinite",
        ),
    ],
)
def test_bad_objects_at_their_place(obj, bad, message):
    text = objects(obj)
    # the needle is searched after the "objects:" line, inside the object
    skip = text.count(bad, 0, text.index("objects:"))
    check_refused(text, bad, message, nth=skip)


@pytest.mark.parametrize(
    ("color", "rgb"),
    [
        ("red", (255, 0, 0)),
        ("Navy", (0, 0, 128)),
        ("'#0a0B0c'", (10, 11, 12)),
        ("[1, 2, 3]", (1, 2, 3)),
        ("darkslategray", (47, 79, 79)),
    ],
)
def test_colours(color, rgb):
    sc = loads(objects(f"{{shape: box, size: 3, position: [0, 0], color: {color}}}"))
    assert tuple(sc.palette[sc.bodies.looks.color[0]]) == rgb


@pytest.mark.parametrize(
    ("color", "bad", "message"),
    [
        ("gren", "gren", "unknown colour 'gren'; did you mean 'green'?"),
        ("'#12345'", "'#12345'", "is not of the form #rrggbb"),
        ("[1, 2, 300]", "300", "objects[0].color component must be at most 255"),
        ("[1, 2]", "[1, 2]", "needs 3 values [r, g, b], not 2"),
        ("[1, 2, 3.5]", "3.5", "objects[0].color component must be a whole number"),
        ("12", "12}", "objects[0].color must be a colour name, #rrggbb or [r, g, b]"),
    ],
)
def test_bad_colours(color, bad, message):
    text = objects(f"{{shape: box, size: 3, position: [0, 0], color: {color}}}")
    check_refused(text, bad, message, nth=text.count(bad, 0, text.index("color:")))


@pytest.mark.parametrize(
    ("name", "ok"),
    [
        ("ok.name_1-2", True),
        ("a", True),
        ("_x", True),
        ("-x", True),
        (".", False),
        ("..", False),
        (".hidden", False),
        ("../evil", False),
        ("a/b", False),
        ("Caps", False),
        ("with space", False),
        ("x" * 100, True),
        ("x" * 101, False),
        ("''", False),
    ],
)
def test_scenario_names(name, ok):
    text = BASE + f"name: {name}\n"
    if ok:
        assert loads(text).name == name
    else:
        check_refused(text, name, "is not a valid scenario name")


# ----------------------------------------------------------------------------- limits


def test_world_side_limit():
    text = "version: 1\nworld: {width: 16385}\n"
    check_refused(text, "16385", "past the limit of 16384 px per side; raise it with --max-side")
    assert loads(text, limits=Limits(max_side=20000)).world.width == 16385


def test_tick_limit():
    check_refused(
        BASE + "ticks: 1000000001\n",
        "1000000001",
        "past the limit of 1000000000 ticks; raise it with --max-ticks",
    )
    check_refused(BASE + "ticks: 6\n", "6", "past the limit of 5 ticks", limits=Limits(max_ticks=5))
    check_refused(
        BASE + "duration: 1\n",
        "1\n",
        nth=1,
        fragment="duration 1 s at 10 fps is 10 ticks, past the limit of 5 ticks",
        limits=Limits(max_ticks=5),
    )
    err = refused("version: 1\n", limits=Limits(max_ticks=5))
    assert (err.line, err.col) == (1, 1) and "default duration" in err.message


def test_object_limit_for_listed_objects():
    text = objects(
        "{shape: box, size: 1, position: [0, 0]}", "{shape: box, size: 1, position: [2, 0]}"
    )
    err = refused(text, limits=Limits(max_objects=1))
    # the list starts at its first dash
    assert (err.line, err.col) == at(text, "- {shape") and "--max-objects" in err.message
    assert "2 objects are past the limit of 1 objects" in err.message


def test_object_limit_counts_generated_objects_before_making_them():
    text = objects("{shape: box, size: 1, position: [0, 0]}") + (
        "generate:\n  - {count: 2, shape: box, size: 1}\n  - {count: 1000000000, shape: box, "
        "size: 1}\n"
    )
    start = time.perf_counter()
    err = check_refused(
        text,
        "1000000000",
        "generate[1].count 1000000000 makes 1000000003 "
        "objects, past the limit of 1000000 objects; raise it with --max-objects",
    )
    assert time.perf_counter() - start < 0.5
    assert err.line == 7
    check_refused(
        text.replace("1000000000", "5"),
        "2, shape",
        "past the limit of 2 objects",
        limits=Limits(max_objects=2),
    )


def test_frame_count_limit():
    text = BASE + "ticks: 20\noutput: {frames: all}\n"
    check_refused(
        text,
        "all",
        "asks for 21 frames, past the limit of 10 frames; raise it with --max-frames",
        limits=Limits(max_frames=10),
    )
    text = BASE + "ticks: 20\noutput: {frames: {every: 2}}\n"
    check_refused(text, "{every", "asks for 11 frames", limits=Limits(max_frames=10))
    assert len(loads(text).output.frames) == 11


# ----------------------------------------------------------------------------- frames


@pytest.mark.parametrize(
    ("frames", "expected", "spec"),
    [
        ("all", tuple(range(13)), "all"),
        ("none", (), "none"),
        ("last", (12,), "last"),
        ("[6, 0, 6, 12]", (0, 6, 12), [6, 0, 6, 12]),
        ("[]", (), []),
        ("{every: 5}", (0, 5, 10), {"every": 5}),
        ("{every: 12}", (0, 12), {"every": 12}),
        ("{every: 50}", (0,), {"every": 50}),
    ],
)
def test_output_frames(frames, expected, spec):
    sc = loads(BASE + f"ticks: 12\noutput: {{frames: {frames}, gif: false, events: false}}\n")
    assert tuple(sc.output.frames) == expected and sc.output.frames_spec == spec
    assert sc.output.gif is False and sc.output.events is False


def test_frame_past_the_end():
    text = BASE + "ticks: 12\noutput: {frames: [0, 13]}\n"
    check_refused(text, "13]", "output.frames: frame 13 is past the last frame, 12 (ticks: 12)")


@pytest.mark.parametrize(("ticks", "frames"), [(0, (0,)), (1, (0, 1)), (7, (0, 3, 7))])
def test_golden_frames_default(ticks, frames):
    assert loads(BASE + f"ticks: {ticks}\n").golden.frames == frames


def test_golden_settings():
    g = loads(
        BASE + "ticks: 9\ngolden: {frames: last, time_tolerance: 0.25, max_diff_pixels: 4, "
        "color_threshold: 3}\n"
    ).golden
    assert (g.frames, g.time_tolerance, g.max_diff_pixels, g.color_threshold) == ((9,), 0.25, 4, 3)


# ----------------------------------------------------------------------------- overrides


SLOW = "{shape: box, size: 3, position: [0, 0], velocity: [0.000001, 0]}"


def test_fps_override_rechecks_paper_velocities():
    # 1e-6 px/s is 1 px per 10^6 ticks at 1 fps (allowed) but per 3 * 10^6 ticks at 3 fps
    text = objects(SLOW, head="version: 1\nworld: {fps: 1}\n")
    assert loads(text).world.fps == 1
    err = check_refused(
        text, "0.000001", "--fps 3: velocity 1e-06 px/s at 3 fps", overrides={"fps": 3}
    )
    assert err.message.startswith("--fps 3: ")


def test_model_override_rechecks_paper_rules():
    text = objects("{shape: box, size: 3, position: [0.5, 0]}", head=BASE + "model: stepped\n")
    assert loads(text).bodies.pos[0, 0] == 0.5
    err = check_refused(
        text,
        "0.5",
        "must be a whole number of pixels under the paper model",
        overrides={"model": "paper"},
    )
    assert err.message.startswith("--model paper: ")


def test_model_override_replaces_the_model_entry():
    text = BASE + "model: {kind: exact, geometry: exact}\n"
    sc = loads(text, overrides={"model": "paper"})
    assert (sc.model, sc.geometry, sc.substeps) == ("paper", "box", 1)
    text = BASE + "model: {kind: stepped, substeps: 4, geometry: exact}\n"
    sc = loads(text, overrides={"model": "stepped"})  # the same kind keeps its settings
    assert (sc.model, sc.geometry, sc.substeps) == ("stepped", "exact", 4)
    sc = loads(text, overrides={"model": "exact"})
    assert (sc.model, sc.geometry, sc.substeps) == ("exact", "exact", 1)


def test_ticks_override_resolves_frames():
    text = BASE + "ticks: 12\noutput: {frames: {every: 4}}\n"
    sc = loads(text, overrides={"ticks": 8})
    assert sc.ticks == 8 and tuple(sc.output.frames) == (0, 4, 8) and sc.golden.frames == (0, 4, 8)
    # a run shortened from the command line drops listed frames past its end
    text = BASE + "ticks: 12\noutput: {frames: [0, 6, 10]}\n"
    assert tuple(loads(text, overrides={"ticks": 8}).output.frames) == (0, 6)
    # the file's own list must fit the file's own ticks
    check_refused(
        text.replace("ticks: 12", "ticks: 9"), "10]", "frame 10 is past the last frame, 9"
    )


def test_fps_override_counts_duration_again():
    sc = loads(BASE + "duration: 2\n", overrides={"fps": 30})
    assert (sc.world.fps, sc.ticks) == (30, 60)
    sc = loads(BASE + "duration: 2\n", overrides={"fps": 30, "ticks": 5})
    assert sc.ticks == 5


def test_ticks_override_replaces_a_file_value_past_the_limit():
    text = BASE + "ticks: 50\n"
    assert loads(text, overrides={"ticks": 4}, limits=Limits(max_ticks=10)).ticks == 4
    err = refused("version: 1\n", overrides={"ticks": 11}, limits=Limits(max_ticks=10))
    assert str(err) == f"<string>: error: {err.message}"  # named by the option, not line 1
    assert err.message.startswith("--ticks 11: ")
    assert "--max-ticks" in err.message


@pytest.mark.parametrize(
    ("overrides", "fragment"),
    [
        ({"fps": 0}, "--fps 0: fps must be a whole number of ticks per second from 1 to 10000"),
        ({"fps": 2.5}, "--fps 2.5: "),
        ({"model": "bogus"}, "--model bogus: unknown model 'bogus'"),
        ({"model": "exat"}, "did you mean 'exact'?"),
        ({"ticks": -1}, "--ticks -1: ticks must be a whole number >= 0"),
    ],
)
def test_bad_override_values(overrides, fragment):
    err = refused(BASE, overrides=overrides)
    assert fragment in err.message
    if "fps" in overrides:  # points at the file's fps
        assert (err.line, err.col) == at(BASE, "10}")
    else:  # named by the option, not FILE:1:1
        assert str(err) == f"<string>: error: {err.message}"
        assert err.message.startswith("--")


def test_override_none_means_not_given_and_unknown_keys_are_a_programming_error():
    assert loads(BASE, overrides={"model": None, "fps": None, "ticks": None}).world.fps == 10
    with pytest.raises(ValueError):
        loads(BASE, overrides={"speed": 3})


def test_file_values_must_be_valid_even_when_overridden():
    text = "version: 1\nworld: {fps: 0}\n"
    check_refused(text, "0}", "world.fps must be at least 1", overrides={"fps": 5})
