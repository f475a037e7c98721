"""Messages that say everything at once: every error of a file (up to 20, in line order), errors
of command-line options named by the option, `radius` pointing to `diameter`, tabs explained,
overlap judged by the real shapes under `geometry: exact`, duplicate object names."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.runner.command.main import main
from collide2d.runner.run import simulate
from collide2d.runner.scenario.load import ScenarioError, loads
from collide2d.runner.scenario.nodes import MAX_ERRORS

FOUR_MISTAKES = """version: 1
ticks: 10
objects:
  - {shape: circle, radius: 5, position: [1, 1]}
  - {shape: box, size: 5, position: [1, 20], mass: -1}
  - {shape: box, size: 5, position: [10, 40], color: notacolor}
output: {frames: [0, 99]}
"""


def refused(text: str, **kwargs) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        loads(text, "s.yaml", **kwargs)
    return info.value


def test_every_error_of_a_file_is_reported_in_line_order():
    err = refused(FOUR_MISTAKES)
    lines = str(err).splitlines()
    assert [line.split(": error: ")[0] for line in lines] == [
        "s.yaml:4:21",
        "s.yaml:5:52",
        "s.yaml:6:54",
        "s.yaml:7:22",
    ]
    assert "unknown key 'radius'" in lines[0] and "mass must be at least" in lines[1]
    assert "unknown colour 'notacolor'" in lines[2] and "frame 99 is past the last" in lines[3]
    assert (err.line, err.col) == (4, 21)  # as a ScenarioError it is the first


def test_validate_prints_them_all(tmp_path, capsys):
    path = tmp_path / "s.yaml"
    path.write_text(FOUR_MISTAKES)
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 4 and all(line.startswith(f"{path}:") for line in err)


def test_at_most_twenty_errors_are_reported():
    objects = "".join(
        f"  - {{shape: box, size: 2, position: [{3 * i}, 1], mass: -1}}\n" for i in range(30)
    )
    err = refused(f"version: 1\nobjects:\n{objects}")
    lines = str(err).splitlines()
    assert len(lines) == MAX_ERRORS == 20
    assert [int(line.split(":")[1]) for line in lines] == list(range(3, 23))


def test_an_error_that_follows_from_another_is_not_reported():
    # the world is refused, so the objects (which depend on it) are not judged against it
    err = refused(
        "version: 1\nworld: {width: -5}\nobjects:\n  - {shape: box, size: 500, position: [0, 0]}\n"
    )
    assert str(err).count("\n") == 0 and "world.width" in str(err)


def test_an_option_error_names_the_option_not_line_one():
    err = refused("version: 1\n", overrides={"ticks": 2_000_000_000})
    assert str(err).startswith("s.yaml: error: --ticks 2000000000: ticks is past the limit")


def test_radius_points_to_diameter():
    err = refused("version: 1\nobjects:\n  - {shape: circle, radius: 4, position: [1, 1]}\n")
    assert (
        "unknown key 'radius' in object; did you mean 'diameter'? (a circle is given by its"
        in str(err)
    )


def test_a_tab_in_the_indentation_is_explained():
    err = refused("version: 1\nworld:\n\twidth: 100\n")
    assert (err.line, err.col) == (3, 1)
    assert "a tab character in the indentation: YAML indents with spaces only" in err.message


RACK = """version: 1
model: {kind: MODEL}
world: {width: 100, height: 80}
ticks: 20
objects:
  - {shape: circle, diameter: 20, position: [10, 10], velocity: [0, 5]}
  - {shape: circle, diameter: 20, position: [30, 10]}
  - {shape: circle, diameter: 20, position: [20, 28]}
"""


@pytest.mark.parametrize("model", ["stepped", "exact"])
def test_a_tight_rack_of_circles_is_legal_when_shapes_are_exact(model):
    # the third circle's box overlaps both others' boxes; the circles are 20.6 px apart
    text = RACK.replace("MODEL", model + (", geometry: exact" if model == "stepped" else ""))
    result = simulate(loads(text), log_events=True)
    assert np.isfinite(result.final_pos).all()
    err = refused(text.replace("geometry: exact", "geometry: box") if model == "stepped" else
                  text.replace("{kind: exact}", "{kind: exact, geometry: box}"))  # fmt: skip
    assert "overlaps objects[0]" in err.message and "boxes [20, 40)" in err.message
    err = refused(text.replace("[20, 28]", "[20, 25]"))  # 18.0 px apart: the circles overlap
    assert "overlaps objects[0]" in err.message and "shapes in boxes" in err.message


def test_duplicate_object_names_are_refused():
    err = refused(
        "version: 1\nobjects:\n  - {name: a, shape: box, size: 2, position: [1, 1]}\n"
        "  - {name: a, shape: box, size: 2, position: [5, 1]}\n"
    )
    assert (err.line, err.col) == (4, 5)
    assert "objects[1] is named 'a', like object 0 (line 3); names must differ" in err.message


def test_an_object_with_a_name_is_named_in_its_messages():
    text = (
        "version: 1\nobjects:\n  - {name: floor, shape: box, size: 20, position: [1, 1]}\n"
        "  - {name: ball, shape: box, size: 2, position: [50, 5], mass: -1}\n"
        "  - {shape: box, size: 4, position: [15, 15]}\n"
    )
    assert "objects[1] (ball).mass must be at least 1e-15, not -1" in str(refused(text))
    # an object it overlaps is named too, and an object without a name by its place alone
    err = refused(text.replace("mass: -1", "mass: 1"))
    assert "objects[2] (line 5) overlaps objects[0] (floor, line 3) at the start" in str(err)


def test_a_runaway_names_the_objects_it_stopped_on():
    from collide2d.engine.errors import NoRoom
    from collide2d.runner.run import _names_of

    said = _names_of(NoRoom("objects 1 and 2 have no room", (1, 2)), ("a", "cup", None))
    assert said == " (object 1 is cup)"
    assert _names_of(NoRoom("object 2", (2,)), ("a", "cup", None)) == ""


@pytest.mark.parametrize(
    "text, said",
    [
        # a physics collide2d lacks: said so, never "did you mean 'position'?"
        ("objects:\n  - {shape: box, size: 2, position: [1, 1], rotation: 45}",
         "unknown key 'rotation' in object; collide2d has no rotation"),
        ("objects:\n  - {shape: box, size: 2, position: [1, 1], angular_velocity: 1}",
         "collide2d has no rotation: objects keep their orientation"),
        ("objects:\n  - {shape: box, size: 2, position: [1, 1], damping: 0.1}",
         "collide2d has no damping"),
        ("objects:\n  - {shape: box, size: 2, position: [1, 1], density: 3}",
         "collide2d has no density: give an object's mass"),
        ("generate:\n  - {count: 2, shape: box, size: 2, torque: 3}", "collide2d has no rotation"),
        # a key of another section: where it belongs
        ("gravity: 980", "unknown key 'gravity' in the scenario; gravity belongs to the world"),
        ("model: paper\nsubsteps: 4", "substeps is a model setting: model: {kind: ..., substeps"),
        ("world: {iterations: 4}", "unknown key 'iterations' in world; iterations is a model"),
        ("model: {kind: stepped, gravity: 9}", "in model; gravity belongs to the world"),
        ("model: {kind: stepped, friction: 1}", "friction belongs to each object, or to world"),
        # a key of another name
        ("objects:\n  - {shape: box, size: 2, position: [1, 1], elasticity: 0.5}",
         "did you mean 'restitution'? (collide2d calls it restitution"),
    ],
)  # fmt: skip
def test_a_key_collide2d_lacks_or_keeps_elsewhere_says_so(text, said):
    err = refused("version: 1\n" + text + "\n")
    assert said in str(err)
    assert "did you mean 'position'" not in str(err)
