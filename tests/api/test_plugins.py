"""Model plugins: a model of another package, registered under the entry point group
`collide2d.models`, named in scenarios like a built-in one; held to the model protocol; never a
module a scenario names by path.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import collide2d
from collide2d.runner.command.main import main
from collide2d.testing import check_model, problems

BOXFLIP = {"boxflip": "boxflip:BoxFlip"}


def head_on(model="boxflip", fps=10, ticks=60, extra=()) -> dict:
    return {
        "version": 1,
        "name": "head-on",
        "world": {"width": 320, "height": 240, "fps": fps},
        "model": model,
        "ticks": ticks,
        "objects": [
            {"shape": "box", "size": 10, "position": [100, 115], "velocity": [10, 0]},
            {"shape": "box", "size": 10, "position": [210, 115], "velocity": [-10, 0]},
            *extra,
        ],
        "output": {"frames": "none", "gif": False, "events": True},
    }


def line_of(scene: dict, text: str) -> int:
    """The 1-based line of the first line holding `text` in the YAML `collide2d.load` makes of
    `scene`."""
    lines = yaml.safe_dump(scene, sort_keys=False, default_flow_style=None).splitlines()
    return next(i for i, line in enumerate(lines, start=1) if text in line)


def test_the_example_plugin_meets_the_protocol(register):
    register(BOXFLIP)
    check_model("boxflip")
    from boxflip import BoxFlip

    check_model(BoxFlip)


def test_a_registered_model_is_named_like_a_built_in_one(register):
    register(BOXFLIP)
    result = collide2d.run(head_on())
    # the paper's flip at 10 fps: they touch at 5 s, overlap 2 px wide and 10 px high at tick 51
    # (ydiff > xdiff: axis x), go back to where tick 50 left them, reversed, for 9 more ticks
    pairs = [e for e in result.event_log() if e["type"] == "pair"]
    assert [(e["tick"], e["a"], e["b"], e["axis"]) for e in pairs] == [(51, 0, 1, "x")]
    assert result.final["vx"].tolist() == [-10.0, 10.0]
    assert result.final["x"].tolist() == [150.0 - 9, 160.0 + 9]
    as_kind = collide2d.run(head_on({"kind": "boxflip"}))
    assert as_kind.events.tobytes() == result.events.tobytes()
    assert collide2d.run(head_on("paper"), model="boxflip").scenario.model == "boxflip"


def test_the_command_line_runs_a_plugin(register, tmp_path, capsys):
    register(BOXFLIP)
    path = tmp_path / "head-on.yaml"
    path.write_text(yaml.safe_dump(head_on("paper")))
    assert main(["run", str(path), "--model", "boxflip", "--out", str(tmp_path), "--quiet"]) == 0
    final = (tmp_path / "head-on" / "final.csv").read_text().splitlines()
    assert final[1:] == ["0,141,115,-10,0", "1,169,115,10,0"]


@pytest.mark.parametrize("named", ["os:system", "this:x", "antigravity", "boxflip.BoxFlip"])
def test_a_scenario_never_names_a_module_to_import(register, named):
    register(BOXFLIP)
    before = set(sys.modules)
    with pytest.raises(collide2d.ScenarioError) as info:
        collide2d.load(head_on(named))
    assert f"unknown model '{named}'" in str(info.value)
    assert info.value.line == line_of(head_on(named), "model:")
    assert set(sys.modules) - before <= {"boxflip"}  # only the registered plugin, if that
    assert "this" not in sys.modules and "antigravity" not in sys.modules


def test_an_unknown_model_is_answered_with_the_plugins_too(register):
    register(BOXFLIP)
    with pytest.raises(collide2d.ScenarioError, match="did you mean 'boxflip'"):
        collide2d.load(head_on("boxflp"))


def test_a_shape_the_plugin_does_not_take_is_refused_at_its_line(register):
    register(BOXFLIP)
    circle = {"shape": "circle", "diameter": 8, "position": [10, 10], "velocity": [1, 0]}
    with pytest.raises(collide2d.ScenarioError) as info:
        collide2d.load(head_on(extra=[circle]))
    assert "object 2 is a circle, a shape the model 'boxflip' does not take" in str(info.value)
    assert info.value.line == line_of(head_on(extra=[circle]), "circle")


def test_a_plugin_cannot_take_a_built_in_models_name(register):
    register({"exact": "boxflip:BoxFlip", "Bad Name": "boxflip:BoxFlip"})
    from collide2d.engine import models

    assert "exact" not in models.plugins() and "Bad Name" not in models.plugins()
    assert models.names()[:3] == ("paper", "stepped", "exact")
    assert collide2d.run(head_on("exact")).summary["model"] == "exact"


BAD = """
import numpy as np
from boxflip import BoxFlip


class Raises(BoxFlip):
    def advance(self, ticks, log=True):
        if self.tick + ticks >= 20:
            raise ZeroDivisionError("a bug of the plugin")
        return super().advance(ticks, log)


class WrongShape(BoxFlip):
    def positions(self):
        return super().positions()[:, 0]


class Nan(BoxFlip):
    def velocities(self):
        v = super().velocities()
        v[0, 0] = np.nan
        return v


class Unordered(BoxFlip):
    def advance(self, ticks, log=True):
        events = super().advance(ticks, log)
        return events[::-1].copy()


class Wanders(BoxFlip):
    def _walls(self, moved):
        return []
"""


@pytest.mark.parametrize(
    "kind, said",
    [
        ("raises", "raised ZeroDivisionError in advance() at ticks"),
        ("wrongshape", "returned positions() of shape (3,)"),
        ("nan", "returned velocities() with NaN"),
        ("unordered", "events out of order"),
    ],
)
def test_a_bad_plugin_is_told_by_name_without_a_traceback(
    register, tmp_path, capsys, monkeypatch, kind, said
):
    monkeypatch.delenv("CI", raising=False)  # bless is refused in CI, before any model runs
    classes = {"raises": "Raises", "wrongshape": "WrongShape", "nan": "Nan"}
    register({kind: f"badmodel:{classes.get(kind, 'Unordered')}"}, {"badmodel": BAD})
    walls = [{"shape": "box", "size": 10, "position": [5, 5], "velocity": [-30, -20]}]
    path = tmp_path / "scenarios" / "head-on.yaml"
    path.parent.mkdir()
    path.write_text(yaml.safe_dump(head_on(kind, extra=walls)))
    status = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert status == 3
    assert f"the model '{kind}' " in err and said in err
    assert "Traceback" not in err
    assert not (tmp_path / "out" / "head-on").exists()
    # a golden is never written from a run that broke the protocol
    assert main(["bless", "--root", str(tmp_path), "--quiet"]) == 3
    assert f"the model '{kind}' " in capsys.readouterr().err
    assert not (tmp_path / "goldens" / "head-on").exists()


def test_debug_shows_the_plugins_traceback(register, tmp_path, capsys):
    register({"raises": "badmodel:Raises"}, {"badmodel": BAD})
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(head_on("raises")))
    assert main(["run", str(path), "--out", str(tmp_path), "--quiet", "--debug"]) == 3
    err = capsys.readouterr().err
    assert "Traceback" in err and "ZeroDivisionError: a bug of the plugin" in err


def test_the_api_raises_model_error_naming_the_model(register):
    register({"nan": "badmodel:Nan"}, {"badmodel": BAD})
    with pytest.raises(collide2d.ModelError) as info:
        collide2d.run(head_on("nan"))
    assert info.value.model == "nan"


def test_the_kit_finds_what_a_model_does_wrong(register):
    register({}, {"badmodel": BAD})
    import badmodel

    found = problems(badmodel.Wanders)
    assert any("outside the world" in p and "no wall event" in p for p in found)
    assert any("out of order" in p for p in problems(badmodel.Unordered))
    with pytest.raises(AssertionError, match="NaN"):
        check_model(badmodel.Nan)


def test_the_kit_passes_the_built_in_models_state_shapes():
    """The protocol's checks hold for a built-in model too (the paper model, one scene)."""
    scene = head_on("paper", fps=10, ticks=20)
    assert problems("paper", scenes=[scene]) == []
    assert np.array_equal(collide2d.run(scene).final["vx"], [10.0, -10.0])


def test_the_example_project_checks_against_its_goldens(register, monkeypatch):
    """examples/boxflip's scenarios name the plugin; its goldens were blessed with it (CI checks
    them again from a fresh virtualenv with the plugin installed)."""
    register(BOXFLIP)
    monkeypatch.setenv("CI", "true")  # compare only
    found = collide2d.check(root=Path(__file__).resolve().parents[2] / "examples" / "boxflip")
    assert [s.name for s in found.scenarios] == ["boxflip_gas", "boxflip_head_on"]
    assert found.ok, [s.message for s in found.scenarios]
