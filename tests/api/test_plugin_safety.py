"""A model plugin never ends a command quietly and never corrupts what collide2d writes: whatever
it raises (sys.exit, GeneratorExit, any BaseException but Ctrl-C's KeyboardInterrupt), in any call
or when its module is imported, is its error, told by name with exit 3 and never blessed; what it
prints never reaches a machine-readable stdout; the arrays it is handed are its own copies; and
every answer it gives is held to the model protocol (docs/how-to/plugins.md).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml

import collide2d
from collide2d.runner.command.main import main
from collide2d.testing import check_model, problems

# A plugin that misbehaves as COLLIDE2D_TEST_BAD says, "WHERE:HOW", read at each call: WHERE is
# the call (import, build, advance, positions, velocities, event_counts, tick) and HOW what it
# does there (exit0, exit1, exittext, exitnone, genexit, base, kbi). PRINT=1 prints everywhere.
SOURCE = """
import os
import sys

import numpy as np
from boxflip import BoxFlip


class Odd(BaseException):
    pass


def blow(where):
    said = os.environ.get("COLLIDE2D_TEST_BAD", "")
    if os.environ.get("COLLIDE2D_TEST_PRINT"):
        print("plugin says hello from", where)
        sys.stdout.flush()
        os.write(1, b"plugin writes to fd 1\\n")
    if not said.startswith(where + ":"):
        return
    how = said.split(":", 1)[1]
    if how == "exit0":
        sys.exit(0)
    if how == "exit1":
        sys.exit(1)
    if how == "exittext":
        sys.exit("bye")
    if how == "exitnone":
        sys.exit()
    if how == "genexit":
        raise GeneratorExit
    if how == "base":
        raise Odd("odd")
    if how == "kbi":
        raise KeyboardInterrupt


blow("import")


class Bad(BoxFlip):
    def __init__(self, world, bodies):
        blow("build")
        super().__init__(world, bodies)

    @property
    def tick(self):
        if self._tick > 0:
            blow("tick")
        return self._tick

    @tick.setter
    def tick(self, value):
        self._tick = value

    def advance(self, ticks, log=True):
        blow("advance")
        return super().advance(ticks, log)

    def positions(self):
        blow("positions")
        return super().positions()

    def velocities(self):
        blow("velocities")
        return super().velocities()

    def event_counts(self):
        blow("event_counts")
        return super().event_counts()

    def __del__(self):
        blow("del")


class Mutates(BoxFlip):
    def __init__(self, world, bodies):
        super().__init__(world, bodies)
        bodies.pos[:] += 37.0
        bodies.size[:] = 1.0
        bodies.vel[:] = 0.0
        bodies.looks.color[:] = 0


class Reuses(BoxFlip):
    def positions(self):
        if not hasattr(self, "buf"):
            self.buf = np.zeros((len(self.pos), 2))
        self.buf[:] = super().positions()
        return self.buf


class Escapes(BoxFlip):
    def positions(self):
        p = super().positions()
        if self.tick >= 5:
            p[0] = (10 * self.width, 10.0)
        return p


class Miscounts(BoxFlip):
    def event_counts(self):
        return (0, 0)


class IntPositions(BoxFlip):
    def positions(self):
        return super().positions().astype(np.int64)


class InfCounts(BoxFlip):
    def event_counts(self):
        return (float("inf"), 0)


class Unprintable(Exception):
    def __str__(self):
        raise RuntimeError("no str for you")


class BadStr(BoxFlip):
    def advance(self, ticks, log=True):
        raise Unprintable()
"""

POINTS = {
    "boxflip": "boxflip:BoxFlip",
    "bad": "badmodel_safety:Bad",
    "mutates": "badmodel_safety:Mutates",
    "reuses": "badmodel_safety:Reuses",
    "escapes": "badmodel_safety:Escapes",
    "miscounts": "badmodel_safety:Miscounts",
    "intpositions": "badmodel_safety:IntPositions",
    "infcounts": "badmodel_safety:InfCounts",
    "badstr": "badmodel_safety:BadStr",
}


@pytest.fixture
def plugin(register, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    monkeypatch.delenv("COLLIDE2D_TEST_BAD", raising=False)
    monkeypatch.delenv("COLLIDE2D_TEST_PRINT", raising=False)
    register(POINTS, {"badmodel_safety": SOURCE})

    def misbehave(where="", how="exit0"):
        monkeypatch.setenv("COLLIDE2D_TEST_BAD", f"{where}:{how}" if where else "")

    return misbehave


def scene(model="bad", ticks=30) -> dict:
    return {
        "version": 1,
        "name": "head-on",
        "world": {"width": 320, "height": 240, "fps": 10},
        "model": model,
        "ticks": ticks,
        "objects": [
            {"shape": "box", "size": 10, "position": [100, 115], "velocity": [10, 0]},
            {"shape": "box", "size": 10, "position": [210, 115], "velocity": [-10, 0]},
            {"shape": "box", "size": 10, "position": [5, 5], "velocity": [-30, -20]},
        ],
        "golden": {"frames": [0, ticks]},
        "output": {"frames": "none", "gif": False, "events": True},
    }


def project(tmp_path, model="bad"):
    folder = tmp_path / "scenarios"
    folder.mkdir(exist_ok=True)
    path = folder / "head-on.yaml"
    path.write_text(yaml.safe_dump(scene(model)))
    return path


def one_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err and "this is a bug" not in err
    return lines[0]


@pytest.mark.parametrize(
    "where, said",
    [
        ("import", "called sys.exit(0) when its module was imported (badmodel_safety:Bad)"),
        ("build", "called sys.exit(0) when built"),
        ("advance", "called sys.exit(0) in advance() at tick 1"),
        ("positions", "called sys.exit(0) in positions() at tick 0"),
        ("velocities", "called sys.exit(0) in velocities() at tick 0"),
        ("event_counts", "called sys.exit(0) in event_counts() at tick 0"),
        ("tick", "called sys.exit(0) when its tick was read after advance() at tick 1"),
    ],
)
def test_sys_exit_in_any_call_is_the_plugins_error(plugin, tmp_path, capsys, where, said):
    plugin(where)
    path = project(tmp_path)
    status = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    line = one_line(capsys.readouterr().err)
    assert status == 3
    assert f"the model 'bad' {said}" in line
    assert not (tmp_path / "out" / "head-on").exists()


@pytest.mark.parametrize(
    "how, said",
    [
        ("exit1", "called sys.exit(1)"),
        ("exittext", "called sys.exit('bye')"),
        ("exitnone", "called sys.exit()"),
        ("genexit", "raised GeneratorExit"),
        ("base", "raised Odd"),
    ],
)
def test_any_base_exception_is_the_plugins_error(plugin, tmp_path, capsys, how, said):
    plugin("advance", how)
    path = project(tmp_path)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 3
    line = one_line(capsys.readouterr().err)
    assert f"the model 'bad' {said} in advance() at tick 1" in line
    with pytest.raises(collide2d.ModelError) as info:
        collide2d.run(scene())
    assert info.value.model == "bad"


def test_ctrl_c_still_passes_through_a_plugin(plugin):
    """A plugin's sys.exit is its error; the KeyboardInterrupt of Ctrl-C stays the user's."""
    plugin("import", "kbi")
    with pytest.raises(KeyboardInterrupt):
        collide2d.load(scene())
    plugin("advance", "exit0")
    with pytest.raises(collide2d.ModelError, match="sys.exit"):
        collide2d.run(scene())
    plugin("advance", "kbi")
    with pytest.raises(KeyboardInterrupt):
        collide2d.run(scene())


def test_check_with_a_plugin_that_exits_is_an_error_case_never_green(plugin, tmp_path, capsys):
    project(tmp_path)
    root = ["--root", str(tmp_path), "--quiet"]
    assert main(["bless", *root]) == 0  # the golden, blessed while the plugin behaved
    capsys.readouterr()
    plugin("advance", "exit0")
    junit = tmp_path / "j.xml"
    status = main(["check", *root, "--junit", str(junit), "--format", "json"])
    out, err = capsys.readouterr()
    assert status == 3
    doc = json.loads(out)
    assert doc["errors"] and "the model 'bad' called sys.exit(0)" in json.dumps(doc["errors"])
    case = ET.parse(junit).getroot().find("testcase")
    assert case.get("name") == "head-on"
    assert "the model 'bad' called sys.exit(0)" in case.find("error").get("message")
    assert "the model 'bad' called sys.exit(0) in advance()" in err
    # nothing blessed from a plugin that exits
    golden = tmp_path / "goldens" / "head-on" / "events.jsonl"
    before = golden.read_bytes()
    assert main(["bless", *root]) == 3
    assert golden.read_bytes() == before
    assert "the model 'bad' called sys.exit(0)" in capsys.readouterr().err


def test_check_with_a_plugin_that_exits_on_import_is_never_green(plugin, tmp_path, capsys):
    project(tmp_path)
    plugin("import", "exit0")
    junit = tmp_path / "j.xml"
    status = main(["check", "--root", str(tmp_path), "--quiet", "--junit", str(junit)])
    assert status == 3
    assert ET.parse(junit).getroot().get("errors") == "1"
    assert "called sys.exit(0) when its module was imported" in capsys.readouterr().err


def test_a_check_that_checks_none_of_its_scenarios_is_never_green(tmp_path, capsys):
    """Whatever stops a scenario's run, even a SystemExit not of a plugin, it is an error case."""
    from collide2d.runner.golden import cli

    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "s.yaml").write_text(yaml.safe_dump(scene("paper")))

    def simulate(scenario, **kwargs):
        raise SystemExit(0)

    junit = tmp_path / "j.xml"
    argv = ["check", "--root", str(tmp_path), "--quiet", "--junit", str(junit)]
    assert cli.main(argv, simulate=simulate) == 3
    assert ET.parse(junit).getroot().get("errors") == "1"


def test_a_plugins_prints_never_reach_the_json_on_stdout(plugin, tmp_path, capfd, monkeypatch):
    project(tmp_path)
    root = ["--root", str(tmp_path), "--quiet"]
    assert main(["bless", *root]) == 0
    capfd.readouterr()
    monkeypatch.setenv("COLLIDE2D_TEST_PRINT", "1")
    assert main(["check", *root, "--format", "json"]) == 0
    out, err = capfd.readouterr()
    assert json.loads(out)["passed"] == 1
    assert "plugin says hello from advance" in err and "plugin writes to fd 1" in err


def test_a_plugin_editing_its_bodies_changes_nothing_collide2d_writes(plugin):
    scenario = collide2d.load(scene("mutates"))
    pos, size, color = (a.copy() for a in (scenario.bodies.pos, scenario.bodies.size,
                                           scenario.bodies.looks.color))  # fmt: skip
    mutated = collide2d.run(scenario, frames=[0, 30])
    assert np.array_equal(scenario.bodies.pos, pos)
    assert np.array_equal(scenario.bodies.size, size)
    assert np.array_equal(scenario.bodies.looks.color, color)
    honest = collide2d.run(scene("boxflip"), frames=[0, 30])
    for k in (0, 30):
        assert np.array_equal(mutated.frames[k], honest.frames[k])
    assert mutated.events.tobytes() == honest.events.tobytes()
    check_model("mutates")  # each build gets its own copy: the kit's runs agree


def test_an_answer_is_collide2d_s_own_copy(plugin):
    from collide2d.engine.models import make

    scenario = collide2d.load(scene("reuses"))
    model = make("reuses", scenario.world, scenario.bodies)
    first = model.positions()
    kept = first.copy()
    model.advance(5)
    assert not np.array_equal(model.positions(), kept)
    assert np.array_equal(first, kept)  # not the buffer the plugin filled again


@pytest.mark.parametrize(
    "model, said",
    [
        ("escapes", "with object 0 at (3200, 10), outside the 320x240 world by more than the"),
        # (how many events came before the check depends on how the run split its ticks)
        ("miscounts", "returned event_counts() (0, 0) at tick"),
        ("intpositions", "returned positions() of dtype int64 at tick 0"),
        ("infcounts", "returned event_counts() (inf, 0) at tick 0, not two whole counts >= 0"),
        ("badstr", "raised Unprintable in advance() at tick 1: <str() failed>"),
    ],
)
def test_every_answer_is_checked_at_run_time(plugin, tmp_path, capsys, model, said):
    path = project(tmp_path, model)
    status = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    line = one_line(capsys.readouterr().err)
    assert status == 3
    assert f"the model '{model}' " in line and said in line


def test_the_kit_names_the_registered_models_for_an_unknown_one(plugin):
    with pytest.raises(ValueError) as info:
        check_model("nosuch")
    said = str(info.value)
    assert "unknown model 'nosuch'" in said
    assert all(name in said for name in ("paper", "stepped", "exact", "boxflip", "mutates"))


def test_the_kit_tells_infinite_counts_as_the_models(plugin):
    import badmodel_safety as bad

    found = problems(bad.InfCounts)
    assert found and all("returned event_counts() (inf, 0)" in p for p in found)


def test_a_plugins_error_is_whole_across_processes():
    """`check --workers` runs scenarios on Dask workers: the error comes back pickled."""
    import pickle

    err = collide2d.ModelError("bad", "called sys.exit(0) in advance() at tick 1")
    again = pickle.loads(pickle.dumps(err))
    assert type(again) is collide2d.ModelError and again.model == "bad"
    assert str(again) == "the model 'bad' called sys.exit(0) in advance() at tick 1"
