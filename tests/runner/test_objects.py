"""Objects and generate blocks: paper model rules, convex polygons, generated objects."""

from __future__ import annotations

import numpy as np
import pytest
from scenario_text import BASE, any_overlap, check_refused, objects

from collide2d.engine import motion
from collide2d.engine.world import KIND_CIRCLE
from collide2d.runner.scenario.load import loads
from collide2d.runner.scenario.objects import polygon_problem

# ----------------------------------------------------------------------------- paper model


def test_paper_positions_must_be_whole():
    text = objects("{shape: box, size: 3, position: [1.5, 0]}")
    check_refused(
        text,
        "1.5",
        "objects[0].position x must be a whole number of pixels under the paper model, not 1.5",
    )
    sc = loads(text.replace("version: 1\n", "version: 1\nmodel: stepped\n"))
    assert sc.bodies.pos.tolist() == [[1.5, 0]]


def test_paper_velocity_refused_with_the_engine_message():
    # 1e-7 px/s at 10 fps needs 1 px per 10^8 ticks, past motion.MAX_PERIOD_TICKS
    text = objects("{shape: box, size: 3, position: [0, 0], velocity: [0, 0.0000001]}")
    with pytest.raises(ValueError) as expected:
        motion.paper_rate(0.0000001, 10)
    err = check_refused(text, "0.0000001", str(expected.value))
    assert err.message == str(expected.value)


def test_paper_velocities_that_are_fine():
    sc = loads(objects("{shape: box, size: 3, position: [0, 0], velocity: [7.5, -0.25]}"))
    assert sc.bodies.vel.tolist() == [[7.5, -0.25]]


def test_non_paper_models_take_any_finite_velocity():
    text = objects("{shape: box, size: 3, position: [0, 0], velocity: [0, 0.0000001]}")
    for model in ("stepped", "exact"):
        assert loads(text.replace("version: 1\n", f"version: 1\nmodel: {model}\n")).bodies.n == 1


# ----------------------------------------------------------------------------- polygons


@pytest.mark.parametrize(
    ("points", "problem"),
    [
        ([[0, 0], [10, 0], [10, 10], [0, 10]], None),
        ([[0, 0], [5, 0], [10, 0], [10, 10], [0, 10]], None),  # a collinear point on an edge
        ([[0, 0], [10, 0], [10, 0], [0, 10]], None),  # a repeated point
        ([[0, 10], [10, 10], [10, 0], [0, 0]], None),  # the other winding
        ([[0, 0], [5, 5], [10, 10]], "zero area"),
        ([[3, 3], [3, 3], [3, 3]], "zero area"),
        ([[0, 0], [10, 0], [5, 3], [10, 10], [0, 10]], "turns both ways"),  # a notch
        ([[0, 0], [10, 10], [10, 0], [0, 10]], "crosses itself"),  # a bow tie
        ([[0, 0], [10, 0], [5, 0], [5, 5]], "turns back"),
        # a five-pointed star drawn point to point: turns one way but winds twice
        ([[50, 0], [79, 90], [2, 35], [98, 35], [21, 90]], "winds around more than once"),
    ],
)
def test_polygon_problem(points, problem):
    found = polygon_problem(np.array(points))
    if problem is None:
        assert found is None
    else:
        assert found is not None and problem in found


def test_exact_geometry_refuses_non_convex_polygons_at_their_points():
    obj = "{shape: polygon, points: [[0, 0], [10, 0], [5, 3], [10, 10], [0, 10]], position: [0, 0]}"
    text = objects(obj, head=BASE + "model: exact\n")
    err = check_refused(
        text, "[[0, 0]", "objects[0].points: under geometry 'exact' a polygon must be convex"
    )
    assert "turns both ways" in err.message


@pytest.mark.parametrize("model", ["paper", "stepped", "{kind: exact, geometry: box}"])
def test_every_model_refuses_a_polygon_that_is_not_convex_at_its_points(model):
    # under box geometry a concave outline would be drawn as written but collide as its box: no
    # model takes it silently
    notch = "[[0, 0], [10, 0], [5, 3], [10, 10], [0, 10]]"
    obj = f"{{shape: polygon, points: {notch}, position: [0, 0]}}"
    err = check_refused(
        objects(obj, head=BASE + f"model: {model}\n"),
        "[[0, 0]",
        "objects[0].points: a polygon must be convex, but it is not convex: it turns both ways",
    )
    assert "geometry" not in err.message
    line = "{shape: polygon, points: [[0, 0], [10, 0], [20, 0]], position: [0, 0]}"
    assert loads(objects(line)).bodies.n == 1  # points on a line: drawn as a line, under box


# ----------------------------------------------------------------------------- generate


GEN_HEAD = "version: 1\nworld: {width: 320, height: 240, fps: 10}\n"


def test_generated_objects_fill_the_arrays():
    text = GEN_HEAD + "objects:\n  - {shape: box, size: 40, position: [100, 100], static: true}\n"
    text += (
        "generate:\n  - {count: 30, shape: circle, diameter: 6, speed: 10, seed: 3, "
        "color: yellow, mass: 2, fill: true}\n"
    )
    sc = loads(text)
    b = sc.bodies
    assert b.n == 31
    assert np.all(b.kind[1:] == KIND_CIRCLE) and np.all(b.size[1:] == 6)
    assert np.all(b.mass[1:] == 2) and np.all(b.looks.fill[1:]) and not b.looks.fill[0]
    assert np.all(np.abs(b.vel[1:]) == 10)
    assert np.all(b.pos == np.floor(b.pos))  # whole pixels
    assert np.all(b.pos >= 0) and np.all(b.pos + b.size <= [320, 240])
    # nothing overlaps: compare every pair
    assert not any_overlap(b.pos, b.size)


def test_generate_is_deterministic_and_seeded():
    text = (
        GEN_HEAD + "generate:\n  - {count: 40, shape: box, size: 5, speed: {min: 2, max: 9}, "
        "seed: 11}\n"
    )
    a, b = loads(text).bodies, loads(text).bodies
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.vel, b.vel)
    c = loads(text.replace("seed: 11", "seed: 12")).bodies
    assert not np.array_equal(a.pos, c.pos)


def test_generate_seed_defaults_to_zero():
    text = GEN_HEAD + "generate:\n  - {count: 5, shape: box, size: 5}\n"
    assert np.array_equal(
        loads(text).bodies.pos, loads(text.replace("size: 5}", "size: 5, seed: 0}")).bodies.pos
    )


def test_generate_under_paper_draws_whole_velocities():
    text = GEN_HEAD + "generate:\n  - {count: 50, shape: box, size: 3, speed: {min: 2, max: 9}}\n"
    vel = loads(text).bodies.vel
    assert np.all(vel == np.round(vel))
    speed = np.hypot(vel[:, 0], vel[:, 1])
    # components rounded by at most 1/2 each: the magnitude moves by at most sqrt(2)/2
    assert np.all(speed >= 2 - 0.71) and np.all(speed <= 9 + 0.71)
    stepped = loads(text.replace("version: 1\n", "version: 1\nmodel: stepped\n")).bodies.vel
    assert np.all(np.hypot(stepped[:, 0], stepped[:, 1]) >= 2 - 1e-9)
    assert not np.all(stepped == np.round(stepped))


def test_generate_velocity_ranges():
    text = (
        GEN_HEAD + "generate:\n  - {count: 60, shape: box, size: 3, velocity: {min: [-2, 3], "
        "max: [2, 5]}}\n"
    )
    vel = loads(text).bodies.vel
    assert set(np.unique(vel[:, 0])) <= {-2, -1, 0, 1, 2} and set(np.unique(vel[:, 1])) <= {3, 4, 5}
    assert np.all(vel == np.round(vel))


def test_generate_static_block():
    text = GEN_HEAD + "generate:\n  - {count: 4, shape: box, size: 3, static: true}\n"
    b = loads(text).bodies
    assert np.all(b.static) and np.all(b.mass == np.inf) and np.all(b.vel == 0)


@pytest.mark.parametrize(
    ("block", "bad", "message"),
    [
        ("{shape: box, size: 3}", "{shape", "generate[0] is missing 'count'"),
        ("{count: -1, shape: box, size: 3}", "-1", "generate[0].count must be at least 0"),
        ("{count: 2, shape: polygon, size: 3}", "polygon", "unknown shape 'polygon'"),
        ("{count: 2, shape: box}", "{count", "generate[0] (box) is missing 'size'"),
        ("{count: 2, shape: box, size: 3, seed: -1}", "-1", "generate[0].seed must be at least 0"),
        (
            "{count: 2, shape: box, size: 3, speed: -1}",
            "-1",
            "generate[0].speed must be at least 0",
        ),
        (
            "{count: 2, shape: box, size: 3, speed: {min: 5, max: 1}}",
            "{min",
            "generate[0].speed: min 5 is more than max 1",
        ),
        (
            "{count: 2, shape: box, size: 3, speed: {min: 1}}",
            "{min",
            "generate[0].speed is missing 'max'",
        ),
        (
            "{count: 2, shape: box, size: 3, speed: 1, velocity: {min: [0, 0], max: [1, 1]}}",
            "velocity",
            "give either 'speed' or 'velocity', not both",
        ),
        (
            "{count: 2, shape: box, size: 3, velocity: [1, 1]}",
            "[1, 1]",
            "generate[0].velocity must be {min: [vx, vy], max: [vx, vy]}",
        ),
        (
            "{count: 2, shape: box, size: 3, velocity: {min: [0, 0]}}",
            "{min",
            "generate[0].velocity is missing 'max'",
        ),
        (
            "{count: 2, shape: box, size: 3, velocity: {min: [0, 3], max: [1, 1]}}",
            "{min",
            "generate[0].velocity: min y 3 is more than max y 1",
        ),
        (
            "{count: 2, shape: box, size: 3, velocity: {min: [0, 0.5], max: [1, 1]}}",
            "0.5",
            "generate[0].velocity min y must be a whole number under the paper model",
        ),
        (
            "{count: 2, shape: box, size: 3, speed: 0.0000001}",
            "0.0000001",
            "is not a whole number of pixels per whole number of ticks",
        ),
        (
            "{count: 2, shape: box, size: 3, speed: 3, static: true}",
            "3, static",
            "generate[0] is static, so its objects cannot move",
        ),
        (
            "{count: 2, shape: box, size: 3, static: true, mass: 2}",
            "2}",
            "generate[0].mass must not be given: the object is static, so its mass is infinite",
        ),
    ],
)
def test_bad_generate_blocks(block, bad, message):
    text = GEN_HEAD + f"generate:\n  - {block}\n"
    check_refused(text, bad, message, nth=text.count(bad, 0, text.index("generate:")))


def test_generate_cannot_place():
    text = GEN_HEAD + "generate:\n  - {count: 5000, shape: box, size: 10}\n"
    err = check_refused(
        text, "{count", "generate[0]: cannot place 5000 boxes of 10x10 without overlap in 320x240"
    )
    assert err.line == 4
    # 700 boxes of 10x10 cover less than the world's 76800 px^2 but jam long before
    text = GEN_HEAD + "generate:\n  - {count: 700, shape: box, size: 10}\n"
    check_refused(text, "{count", "cannot place 700 boxes of 10x10 without overlap in 320x240")


def test_generated_objects_avoid_listed_ones():
    text = (
        "version: 1\nworld: {width: 60, height: 60}\nobjects:\n"
        + "".join(
            f"  - {{shape: box, size: 10, position: [{x}, {y}], static: true}}\n"
            for x in range(0, 60, 20)
            for y in range(0, 60, 20)
        )
        + "generate:\n  - {count: 20, shape: box, size: 4, seed: 5}\n"
    )
    b = loads(text).bodies
    assert not any_overlap(b.pos, b.size)


# ----------------------------------------------------------------------------- names


def _names_in_each_lane(tmp_path, monkeypatch, written: str) -> dict:
    """{lane: the first object's name, or the refusal's message} for an object named `written`
    in a YAML list (general path), a long list (the fast lane, when the name is a plain word), a
    CSV table and a .npy table; a second object is named "other"."""
    from collide2d.runner.scenario import fastlane
    from collide2d.runner.scenario.load import ScenarioError, load

    monkeypatch.setattr(fastlane, "FAST_MIN_OBJECTS", 2)
    quoted = "'" + written.replace("'", "''") + "'"
    head = "version: 1\nworld: {width: 100, height: 80, fps: 10}\nmodel: stepped\n"
    texts = {
        "list": head + f"objects:\n  - {{shape: box, size: 2, position: [0, 0], name: {quoted}}}\n"
        "  - {shape: box, size: 2, position: [10, 0], name: other}\n",
        "csv": head + "objects: {file: t.csv}\n",
        "npy": head + "objects: {file: t.npy}\n",
    }
    if written.isidentifier():
        texts["fast lane"] = texts["list"].replace(quoted, written)
    (tmp_path / "t.csv").write_text(
        'id,shape,w,h,x,y,name\n0,box,2,2,0,0,"' + written.replace('"', '""') + '"\n'
        "1,box,2,2,10,0,other\n"
    )
    rec = np.zeros(
        2,
        dtype=[(c, "f8") for c in ("id", "w", "h", "x", "y")]
        + [("shape", "U3"), ("name", f"U{max(len(written), 5) + 1}")],
    )
    rec["id"], rec["x"], rec["w"], rec["h"], rec["shape"] = [0, 1], [0, 10], 2, 2, "box"
    rec["name"] = [written, "other"]
    np.save(tmp_path / "t.npy", rec)
    taken = []
    real = fastlane.table
    monkeypatch.setattr(fastlane, "table", lambda *a, **k: taken.append(1) or real(*a, **k))
    out = {}
    for lane, text in texts.items():
        (tmp_path / "s.yaml").write_text(text)
        try:
            out[lane] = load(tmp_path / "s.yaml").names[0]
        except ScenarioError as err:
            out[lane] = err.message.split(": ")[-1]  # the reason, wherever it is said
    # the lane read the names it takes (a word of 100 characters at most; longer, the general
    # path reads the file)
    assert bool(taken) == ("fast lane" in texts and len(written) <= 100)
    return out


@pytest.mark.parametrize(
    "written, name",
    [
        ("wall", "wall"),
        ("  wall ", "wall"),  # surrounding whitespace is not part of a name
        ("", None),  # an empty name is no name
        (" ", None),
        ("x" * 100, "x" * 100),
        ("x" * 101, "a name holds at most 100 characters, not 101"),
        (" " + "y" * 100, "y" * 100),
    ],
)
def test_an_object_name_follows_one_rule_in_lists_tables_and_the_fast_lane(
    tmp_path, monkeypatch, written, name
):
    lanes = _names_in_each_lane(tmp_path, monkeypatch, written)
    if written == "x" * 101:  # a CSV cell is bounded as written, before its name is taken
        assert lanes.pop("csv") == "the cell holds more than 100 characters"
        assert lanes.pop("npy") == "the cell holds more than 100 characters"
    if written == " " + "y" * 100:  # likewise: 101 characters as written
        assert lanes.pop("csv") == "the cell holds more than 100 characters"
        assert lanes.pop("npy") == "the cell holds more than 100 characters"
    assert set(lanes.values()) == {name}, lanes
