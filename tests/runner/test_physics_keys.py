"""Gravity, restitution and friction in the scenario format (docs/scenario-format.md#gravity-
restitution-and-friction): what a file gives becomes the WorldSpec, the Bodies and the stepped
model's settings, written in any of the ways objects are written (listed, generate, a CSV or .npy
table, the fast lane); bad values are refused at their place, the paper model refuses every key at
its line, the exact model takes only the defaults (naming `stepped`), and settings of another model
are refused; the exact model's `rest_height` (docs/models.md#exact-under-gravity) reaches it and
ends a ball's bouncing sooner."""

from __future__ import annotations

import numpy as np
import pytest
from scenario_text import check_refused, refused

from collide2d.engine import models
from collide2d.engine.events import EV_REST, EV_WALL
from collide2d.runner.run import make_model
from collide2d.runner.scenario import fastlane
from collide2d.runner.scenario.load import load, loads

HEAD = "version: 1\nworld: {width: 200, height: 100, fps: 10, WORLD}\nmodel: MODEL\n"


def scene(objects: str = "", world: str = "gravity: 980", model: str = "stepped") -> str:
    head = HEAD.replace("WORLD", world).replace(", }", "}").replace("MODEL", model)
    return head + ("objects:\n" + objects if objects else "objects: []\n")


BALL = "  - {shape: circle, diameter: 10, position: [20, 20], restitution: 0.8, friction: 0.4}\n"
BOX = "  - {shape: box, size: [20, 10], position: [60, 80], velocity: [120, 0]}\n"
FLOOR = "  - {shape: box, size: [200, 5], position: [0, 95], static: true, friction: 0.9}\n"


# ----------------------------------------------------------------------------- what a file gives


@pytest.mark.parametrize(
    "written, gravity",
    [("980", (0.0, 980.0)), ("[30, -9.8]", (30.0, -9.8)), ("-0.0", (0.0, 0.0)), ("0", (0.0, 0.0))],
)
def test_gravity_is_one_number_pulling_down_or_a_pair(written, gravity):
    world = loads(scene(world=f"gravity: {written}")).world
    assert world.gravity == gravity and all(str(g) != "-0.0" for g in world.gravity)
    assert world.has_gravity == (gravity != (0.0, 0.0))


def test_the_world_without_the_keys_is_the_elastic_weightless_world():
    world = loads("version: 1\n").world
    assert (world.gravity, world.restitution, world.friction) == ((0.0, 0.0), 1.0, 0.0)
    assert not world.has_gravity


def test_the_walls_take_the_worlds_restitution_and_friction():
    world = loads(scene(world="gravity: 10, restitution: 0.5, friction: 0.25")).world
    assert (world.restitution, world.friction) == (0.5, 0.25)


def test_each_object_has_its_own_restitution_and_friction_static_ones_too():
    b = loads(scene(BALL + BOX + FLOOR)).bodies
    assert b.restitution.tolist() == [0.8, 1.0, 1.0]  # not given: elastic, whatever the walls
    assert b.friction.tolist() == [0.4, 0.0, 0.9]  # the static floor keeps its friction
    assert b.restitution.dtype == b.friction.dtype == np.float64


def test_a_generate_block_gives_its_objects_its_restitution_and_friction():
    gen = (
        "generate:\n  - {count: 4, shape: box, size: 5, speed: 10, seed: 2, restitution: 0.3, "
        "friction: 0.6}\n  - {count: 2, shape: circle, diameter: 4, seed: 1}\n"
    )
    b = loads(scene(BALL) + gen).bodies
    assert b.restitution.tolist() == [0.8] + [0.3] * 4 + [1.0] * 2
    assert b.friction.tolist() == [0.4] + [0.6] * 4 + [0.0] * 2


def test_a_table_gives_the_bodies_of_the_listed_objects(tmp_path):
    rows = [
        "id,shape,w,h,x,y,restitution,friction,static",
        "0,circle,10,10,20,20,0.8,0.4,false",
        "1,box,20,10,60,80,1,0,false",
        "2,box,200,5,0,95,1,0.9,true",
    ]
    (tmp_path / "t.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "t.yaml").write_text(scene().replace("objects: []", "objects: {file: t.csv}"))
    from_csv = load(tmp_path / "t.yaml").bodies
    rec = np.array(
        [(0, "circle", 10, 10, 20, 20, 0.8, 0.4), (1, "box", 20, 10, 60, 80, 1.0, 0.0)],
        dtype=[("id", "i8"), ("shape", "U8"), ("w", "i8"), ("h", "i8"), ("x", "f8"), ("y", "f8"),
               ("restitution", "f8"), ("friction", "f4")],
    )  # fmt: skip
    np.save(tmp_path / "t.npy", rec)
    (tmp_path / "n.yaml").write_text(scene().replace("objects: []", "objects: {file: t.npy}"))
    from_npy = load(tmp_path / "n.yaml").bodies
    listed = loads(scene(BALL + BOX + FLOOR)).bodies
    for b in (from_csv, from_npy):
        k = b.n
        assert b.restitution.tolist() == listed.restitution[:k].tolist()
        assert np.allclose(b.friction, listed.friction[:k], rtol=1e-7)  # float32 0.4 in the .npy


def test_a_table_without_the_columns_gives_the_defaults(tmp_path):
    (tmp_path / "t.csv").write_text("id,shape,w,h,x,y\n0,box,5,5,1,1\n")
    (tmp_path / "t.yaml").write_text(scene().replace("objects: []", "objects: {file: t.csv}"))
    b = load(tmp_path / "t.yaml").bodies
    assert (b.restitution.tolist(), b.friction.tolist()) == ([1.0], [0.0])


def long_list(extra: str, n: int = 30) -> str:
    return "".join(
        f"  - {{shape: box, size: 4, position: [{6 * (i % 30)}, {6 * (i // 30)}], {extra}}}\n"
        for i in range(n)
    )


@pytest.mark.parametrize("model", ["stepped", "exact"])
def test_the_fast_lane_reads_them_as_the_general_path_does(monkeypatch, model):
    monkeypatch.setattr(fastlane, "FAST_MIN_OBJECTS", 3)
    taken = []
    real = fastlane.table
    monkeypatch.setattr(fastlane, "table", lambda *a: taken.append(1) or real(*a))
    e = "0.5" if model == "stepped" else "1"
    text = scene(long_list(f"restitution: {e}, friction: 0") + long_list("velocity: [1, 0]")[:0])
    text = text.replace("gravity: 980", "gravity: 0")
    fast = loads(text.replace("MODEL", model).replace("model: stepped", f"model: {model}"))
    assert taken == [1]  # the lane took the list
    monkeypatch.setattr(fastlane, "split", lambda text: None)
    general = loads(text.replace("model: stepped", f"model: {model}"))
    for field in ("restitution", "friction", "pos", "size"):
        a, b = getattr(fast.bodies, field), getattr(general.bodies, field)
        assert a.tobytes() == b.tobytes(), field
    assert fast.bodies.restitution[0] == float(e)


def test_the_fast_lane_leaves_a_refusal_to_the_general_path(monkeypatch):
    monkeypatch.setattr(fastlane, "FAST_MIN_OBJECTS", 3)
    text = scene(long_list("restitution: 1") + long_list("friction: 2")[:0]).replace(
        "  - {shape: box, size: 4, position: [12, 0], restitution: 1}",
        "  - {shape: box, size: 4, position: [12, 0], restitution: 1.5}",
    )
    check_refused(text, "1.5", "objects[2].restitution must be at most 1, not 1.5")


def test_the_stepped_settings_reach_the_model_as_options():
    text = scene(
        model="{kind: stepped, iterations: 4, slop: 0.05, rest_speed: 3, sleep: false, "
        "sleep_after: 1.5, substeps: 2}"
    )
    s = loads(text)
    assert (s.iterations, s.slop, s.rest_speed, s.sleep, s.sleep_after) == (
        4,
        0.05,
        3.0,
        False,
        1.5,
    )
    given = {"iterations": 4, "slop": 0.05, "rest_speed": 3.0, "sleep": False, "sleep_after": 1.5}
    options = models.scenario_options(
        "stepped", substeps=2, geometry="box", max_events_per_tick=10, **given
    )
    assert options == {"substeps": 2, "geometry": "box", **given}
    # not given: none of them is passed, so that the model's defaults hold
    plain = loads(scene(model="stepped"))
    assert (plain.iterations, plain.slop, plain.rest_speed, plain.sleep, plain.sleep_after) == (
        (None,) * 5
    )
    assert make_model(plain).tick == 0


# ----------------------------------------------------------------------------- bad values


@pytest.mark.parametrize(
    "world, needle, fragment",
    [
        ("gravity: [1, 2, 3]", "[1, 2, 3]", "world.gravity must be one number g (meaning [0, g])"),
        ("gravity: .inf", ".inf", "world.gravity must be a finite number"),
        ("gravity: 1e13", "1e13", "world.gravity must be at most 1000000000000 px/s²"),
        ("gravity: [0, -2e12]", "-2e12", "world.gravity y must be at least -1000000000000 px/s²"),
        ("gravity: down", "down", "world.gravity must be a number"),
        ("gravity: 1, restitution: 1.5", "1.5", "world.restitution must be at most 1, not 1.5"),
        ("gravity: 1, friction: -0.1", "-0.1", "world.friction must be at least 0, not -0.1"),
        (
            "gravity: 1, friction: 1e7",
            "1e7",
            "world.friction must be at most 1000000, not 10000000",
        ),
    ],
)
def test_a_bad_world_value_is_refused_at_its_place(world, needle, fragment):
    check_refused(scene(world=world), needle, fragment)


@pytest.mark.parametrize(
    "obj, needle, fragment",
    [
        ("restitution: -0.5", "-0.5", "objects[0].restitution must be at least 0, not -0.5"),
        ("restitution: 2", "2}", "objects[0].restitution must be at most 1, not 2"),
        ("friction: -1", "-1", "objects[0].friction must be at least 0, not -1"),
        ("friction: 1e9", "1e9", "objects[0].friction must be at most 1000000, not 1000000000"),
        ("friction: high", "high", "objects[0].friction must be a number"),
    ],
)
def test_a_bad_object_value_is_refused_at_its_place(obj, needle, fragment):
    text = scene(f"  - {{shape: box, size: 5, position: [1, 1], {obj}}}\n")
    check_refused(text, needle, fragment)


@pytest.mark.parametrize(
    "setting, needle, fragment",
    [
        ("iterations: 0", "0}\nobj", "model.iterations must be at least 1, not 0"),
        ("iterations: 2.5", "2.5", "model.iterations must be a whole number"),
        ("iterations: 1001", "1001", "model.iterations must be at most 1000"),
        ("slop: -0.1", "-0.1", "model.slop must be at least 0 px, not -0.1"),
        ("rest_speed: -1", "-1", "model.rest_speed must be at least 0 px/s"),
        ("sleep: sometimes", "sometimes", "model.sleep must be true or false"),
        ("sleep_after: -2", "-2", "model.sleep_after must be at least 0 s"),
    ],
)
def test_a_bad_stepped_setting_is_refused_at_its_place(setting, needle, fragment):
    check_refused(scene(model=f"{{kind: stepped, {setting}}}"), needle, fragment)


@pytest.mark.parametrize(
    "setting, needle, fragment",
    [
        ("rest_height: -0.5", "-0.5", "model.rest_height must be at least 0 px, not -0.5"),
        ("rest_height: 2e9", "2e9", "model.rest_height must be at most 1000000000 px"),
        ("rest_height: .nan", ".nan", "model.rest_height must be a finite number"),
        ("rest_height: low", "low", "model.rest_height must be a number"),
    ],
)
def test_a_bad_rest_height_is_refused_at_its_place(setting, needle, fragment):
    check_refused(scene(model=f"{{kind: exact, {setting}}}"), needle, fragment)


def test_a_bad_table_cell_is_refused_at_its_row_and_column(tmp_path):
    rows = ["id,shape,w,h,x,y,restitution", "0,box,5,5,1,1,1", "1,box,5,5,10,1,1.25"]
    (tmp_path / "t.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "t.yaml").write_text(scene().replace("objects: []", "objects: {file: t.csv}"))
    with pytest.raises(Exception) as info:
        load(tmp_path / "t.yaml")
    err = info.value
    assert (err.line, err.col) == (3, 16)
    assert "row 2, column restitution: must be at most 1, not 1.25" in err.message


# ------------------------------------------------------------------------- what each model takes


@pytest.mark.parametrize(
    "world, objects, needle, key",
    [
        ("gravity: 980", "", "980", "gravity"),
        ("gravity: 0", "", "0}", "gravity"),
        ("restitution: 1", "", "1}", "restitution"),
        ("friction: 0.5", "", "0.5", "friction"),
        ("background: black", BALL, "0.8", "restitution"),
        ("background: black", BOX.replace("]}", "], friction: 0}"), "0}", "friction"),
    ],
)
def test_the_paper_model_refuses_each_key_at_its_line(world, objects, needle, key):
    text = scene(objects.replace("[20, 20]", "[20, 20]"), world=world, model="paper")
    err = check_refused(text, needle, f"the paper model has no {key}")
    assert "model: stepped" in err.message


def test_the_paper_model_refuses_them_in_a_block_and_a_table(tmp_path):
    gen = "generate:\n  - {count: 2, shape: box, size: 5, seed: 1, friction: 0.2}\n"
    said = "generate[0].friction cannot be given: the paper model has no friction"
    check_refused(scene(world="background: black", model="paper") + gen, "0.2", said)
    (tmp_path / "t.csv").write_text("id,shape,w,h,x,y,restitution\n0,box,5,5,1,1,1\n")
    text = scene(world="background: black", model="paper")
    (tmp_path / "t.yaml").write_text(text.replace("objects: []", "objects: {file: t.csv}"))
    with pytest.raises(Exception) as info:
        load(tmp_path / "t.yaml")
    assert (info.value.line, info.value.col) == (2, 15)
    assert "column restitution: cannot be given: the paper model has no restitution" in str(
        info.value
    )


def test_model_paper_on_the_command_line_names_the_option():
    err = refused(scene(BALL, world="gravity: 0"), overrides={"model": "paper"})
    lines = str(err).splitlines()
    assert len(lines) == 2  # world.gravity and the ball's restitution (its friction: one a row)
    assert all("--model paper: " in line for line in lines)
    assert "world.gravity cannot be given" in lines[0]
    assert "objects[0].restitution cannot be given" in lines[1]


@pytest.mark.parametrize("gravity", ["0", "980"])
def test_the_exact_model_takes_restitution_and_friction(gravity):
    world = f"gravity: {gravity}, restitution: 0.5, friction: 0.2"
    s = loads(scene(BALL, world=world, model="exact"))
    assert s.bodies.restitution.tolist() == [0.8] and s.bodies.friction.tolist() == [0.4]
    assert (s.world.restitution, s.world.friction) == (0.5, 0.2)


def test_the_exact_model_takes_the_defaults_written_out():
    text = scene(
        "  - {shape: box, size: 5, position: [1, 1], restitution: 1, friction: 0}\n",
        world="gravity: [0, 0], restitution: 1.0, friction: 0",
        model="exact",
    )
    s = loads(text)
    assert s.world.gravity == (0.0, 0.0) and s.bodies.restitution.tolist() == [1.0]


@pytest.mark.parametrize("kind", ["paper", "exact"])
@pytest.mark.parametrize("key", ["iterations: 4", "slop: 0.1", "rest_speed: 2", "sleep: true",
                                 "sleep_after: 0.5"])  # fmt: skip
def test_a_stepped_setting_under_another_model_is_refused_at_its_line(kind, key):
    name, value = key.split(": ")
    text = scene(world="background: black", model=f"{{kind: {kind}, {key}}}")
    check_refused(text, value + "}", f"{name} applies to the stepped model only, not to {kind}")


def test_a_model_given_on_the_command_line_drops_the_files_stepped_settings():
    s = loads(scene(model="{kind: stepped, iterations: 3}", world="gravity: 0"),
              overrides={"model": "exact"})  # fmt: skip
    assert s.model == "exact" and s.iterations is None


@pytest.mark.parametrize("kind", ["paper", "stepped"])
def test_rest_height_under_another_model_is_refused_at_its_line(kind):
    text = scene(world="background: black", model=f"{{kind: {kind}, rest_height: 0.5}}")
    check_refused(text, "0.5}", f"rest_height applies to the exact model only, not to {kind}")


def test_a_model_given_on_the_command_line_drops_the_files_rest_height():
    text = scene(model="{kind: exact, rest_height: 0.5}", world="gravity: 0")
    assert loads(text, overrides={"model": "stepped"}).rest_height is None
    assert loads(text, overrides={"model": "exact"}).rest_height == 0.5  # the same kind keeps it


# a ball of restitution 0.5 dropped from 1 px above the floor: its first impact leaves it
# 1 px · 0.5² = 0.25 px to rise, its fourth the first under the default 0.01 px
DROP = "  - {shape: circle, diameter: 10, position: [20, 89], restitution: 0.5}\n"


def dropped(model: str):
    """The events of the ball dropped under `model`, over 1 s (10 ticks)."""
    s = loads(scene(DROP, world="gravity: 980", model=model))
    found = make_model(s).advance(10)
    return s, found[(found["type"] == EV_WALL) | (found["type"] == EV_REST)]


def test_rest_height_reaches_the_exact_model_and_ends_the_bouncing_sooner():
    s, found = dropped("{kind: exact, rest_height: 0.5}")
    assert s.rest_height == 0.5
    assert models.scenario_options("exact", rest_height=0.5, slop=0.1) == {"rest_height": 0.5}
    assert found["type"].tolist() == [EV_WALL, EV_REST]  # at rest at its first impact
    plain, found = dropped("exact")
    assert plain.rest_height is None  # not given: the model's default holds
    assert found["type"].tolist() == [EV_WALL] * 4 + [EV_REST]
    _, found = dropped("{kind: exact, rest_height: 0.01}")  # the default written out
    assert found["type"].tolist() == [EV_WALL] * 4 + [EV_REST]


@pytest.mark.parametrize("gravity", ["980", "[1, 0]", "[0, -3]"])
def test_the_exact_model_takes_gravity(gravity):
    s = loads(scene(BOX, world=f"gravity: {gravity}", model="exact"))
    assert s.world.has_gravity and s.model == "exact"


def test_the_exact_model_under_gravity_takes_static_objects():
    floor = FLOOR.replace(", friction: 0.9", "")
    s = loads(scene(BOX + floor, world="gravity: 980", model="exact"))
    assert s.bodies.static.tolist() == [False, True]


def test_every_world_key_the_paper_model_has_not_is_refused_at_once():
    err = refused(scene(world="gravity: 9.8, restitution: 0.5, friction: 0.1", model="paper"))
    lines = str(err).splitlines()
    assert [line.split("error: ")[1].split(" cannot")[0] for line in lines] == [
        "world.gravity",
        "world.restitution",
        "world.friction",
    ]
