"""The public API refuses what the command line refuses, naming the argument.

Every argument of `collide2d.load`, `run` and `check` (and `collide2d.Limits`) of the wrong type is
a TypeError, out of its range a ValueError, the message starting with the argument as it was given
(`scale=0: ...`); a scenario dict holds numpy numbers, arrays and tuples as the numbers and lists
YAML would give, and any other value is a ScenarioError naming its place, never a crash of the
YAML writer.
"""

from __future__ import annotations

import collections

import numpy as np
import pytest
import yaml

import collide2d


def two_boxes(**world) -> dict:
    """Two 10x10 boxes closing at 10 px/s each, in plain Python values."""
    return {
        "version": 1,
        "name": "two-boxes",
        "world": {"width": 320, "height": 240, "fps": 10} | world,
        "model": "exact",
        "ticks": 60,
        "objects": [
            {"name": "left", "shape": "box", "size": 10, "position": [100, 115]}
            | {"velocity": [10, 0], "fill": True},
            {"name": "right", "shape": "box", "size": 10, "position": [210, 115]}
            | {"velocity": [-10, 0], "mass": 2.5},
        ],
        "output": {"frames": "none", "gif": False, "events": True},
        "golden": {"frames": [0, 60]},
    }


def with_numpy() -> dict:
    """two_boxes() written with numpy values, tuples, arrays and a Mapping that is not a dict."""
    scene = two_boxes(fps=np.int64(10), width=np.float64(320.0))
    scene["world"] = collections.OrderedDict(scene["world"])
    scene["name"] = np.str_("two-boxes")
    scene["ticks"] = np.uint16(60)
    left, right = scene["objects"]
    left["position"] = np.array([100, 115])
    left["velocity"] = (np.float32(10.0), np.int8(0))
    left["fill"] = np.bool_(True)
    right["position"] = np.array([210.0, 115.0])
    right["velocity"] = [np.float64(-10.0), 0]
    right["mass"] = np.float64(2.5)
    scene["objects"] = np.array([left, right], dtype=object)
    scene["golden"]["frames"] = np.arange(0, 61, 60)
    scene["output"]["gif"] = np.False_
    return scene


def test_numpy_values_in_a_scenario_dict_are_the_numbers_and_lists_yaml_gives():
    plain = collide2d.run(two_boxes())
    given = collide2d.run(with_numpy())
    assert given.events.tobytes() == plain.events.tobytes() and len(plain.events)
    assert given.positions.tobytes() == plain.positions.tobytes()
    a, b = plain.scenario, given.scenario
    for field in ("name", "ticks", "world", "golden"):
        assert getattr(b, field) == getattr(a, field), field
    assert b.bodies.mass.tobytes() == a.bodies.mass.tobytes()


def test_numpy_values_load_under_another_model_too():
    scenario = collide2d.load(with_numpy())
    assert collide2d.run(scenario, model="stepped").scenario.model == "stepped"


@pytest.mark.parametrize(
    "where, value, said",
    [
        (("ticks",), 1j, "ticks: a scenario holds numbers, text, true/false, lists and mappings"),
        (("objects", 1, "velocity"), object(), "objects[1].velocity: a scenario holds"),
        (("objects", 0, "position"), np.array([1 + 2j, 3]), "objects[0].position[0]: a scen"),
        (("world", "fps"), np.datetime64("2020-01-01"), "world.fps: a scenario holds"),
        (("name",), b"two", "name: a scenario holds numbers, text"),
        (("golden", "frames"), {0, 20}, "golden.frames: a scenario holds"),
        pytest.param(
            ("world", "width"), 10**5000, "world.width: a whole number too long", id="long"
        ),
    ],
)
def test_a_value_yaml_would_not_give_is_refused_at_its_place(where, value, said):
    """At the place the value takes in the YAML text the dict is written as."""
    scene = two_boxes()
    target = scene
    for key in where[:-1]:
        target = target[key]
    target[where[-1]] = value
    with pytest.raises(collide2d.ScenarioError) as info:
        collide2d.load(scene)
    assert info.value.message.startswith(said)
    target[where[-1]] = "x" * 34  # text as long as what the refused value is written as
    if isinstance(value, np.ndarray):
        target[where[-1]] = ["x" * 34, 3]
    text = yaml.safe_dump(scene, sort_keys=False, allow_unicode=True, default_flow_style=None)
    at = text.index("x" * 34)
    assert (info.value.line, info.value.col) == (
        text.count("\n", 0, at) + 1,
        at - text.rfind("\n", 0, at),
    )


def test_a_key_that_is_not_text_is_refused_at_its_place():
    scene = two_boxes()
    scene["world"][("width",)] = 3
    with pytest.raises(collide2d.ScenarioError) as info:
        collide2d.load(scene)
    assert info.value.message == "world: keys are names (text), not tuple"


def test_a_dict_that_holds_itself_or_nests_past_the_bound_is_refused_not_a_crash():
    scene = two_boxes()
    scene["objects"].append(scene["objects"])
    with pytest.raises(collide2d.ScenarioError, match=r"objects\[2\]: the value holds itself"):
        collide2d.load(scene)
    deep = two_boxes()
    nested: list = []
    deep["description"] = nested
    for _ in range(5000):
        nested.append([])
        nested = nested[0]
    with pytest.raises(collide2d.ScenarioError, match=r"description(\[0\])+: nested more than"):
        collide2d.load(deep)


def test_a_shared_list_stays_one_yaml_value_so_the_alias_bound_holds():
    """Ten levels of ten references to one list would be 10**10 values written out whole."""
    scene = two_boxes()
    item: list = [1]
    for _ in range(10):
        item = [item] * 10
    scene["description"] = item
    with pytest.raises(collide2d.ScenarioError, match="alias"):
        collide2d.load(scene)


@pytest.mark.parametrize(
    "kwargs, error, said",
    [
        ({"model": 3}, TypeError, "model=3: expected a model name (text), not int"),
        ({"fps": "10"}, TypeError, "fps='10': expected a whole number, not str"),
        ({"fps": 2.0}, TypeError, "fps=2.0: expected a whole number, not float"),
        ({"fps": True}, TypeError, "fps=True: expected a whole number, not bool"),
        ({"ticks": np.float64(3)}, TypeError, f"ticks={np.float64(3)!r}: expected a whole number"),
        ({"max_events_per_tick": 0}, ValueError, "max_events_per_tick=0: must be at least 1"),
        ({"ticks": 10**5000}, ValueError, "ticks: a whole number too long to write out"),
        ({"limits": {"max_objects": 1}}, TypeError, "limits={'max_objects': 1}: expected a"),
        ({"defaults": [("kind", "exact")]}, TypeError, "defaults=[('kind', 'exact')]: expected"),
        ({"defaults": {"substep": 2}}, ValueError, "defaults: no model setting 'substep'; did"),
        ({"defaults": {"substeps": "2"}}, TypeError, "defaults['substeps']='2': expected a whole"),
        ({"defaults": {"substeps": 0}}, ValueError, "defaults['substeps']=0: must be at least 1"),
        ({"defaults": {"kind": "warp"}}, ValueError, "defaults['kind']='warp': must be one of"),
        ({"defaults": {"geometry": 1}}, ValueError, "defaults['geometry']=1: must be one of"),
    ],
)
def test_load_refuses_a_wrong_argument_naming_it(kwargs, error, said):
    with pytest.raises(error) as info:
        collide2d.load(two_boxes(), **kwargs)
    assert str(info.value).startswith(said)


@pytest.mark.parametrize("source", [5, None, [two_boxes()], b"scene.yaml"])
def test_load_and_run_refuse_a_source_that_is_neither_a_file_nor_a_dict(source):
    for call in (collide2d.load, collide2d.run):
        with pytest.raises(TypeError, match="expected a scenario file"):
            call(source)


def test_numpy_whole_numbers_are_whole_numbers_for_load():
    scenario = collide2d.load(
        two_boxes(), fps=np.int64(20), ticks=np.uint8(7), max_events_per_tick=np.int32(9),
        defaults={"substeps": np.int64(3)}, model=np.str_("stepped"),
    )  # fmt: skip
    assert (scenario.world.fps, scenario.ticks, scenario.model) == (20, 7, "stepped")
    assert type(scenario.ticks) is int


def test_limits_refuse_what_the_max_options_refuse():
    assert collide2d.Limits(max_objects=np.int64(5)).max_objects == 5
    assert type(collide2d.Limits(max_objects=np.int64(5)).max_objects) is int
    with pytest.raises(ValueError, match=r"^max_objects=0: must be at least 1"):
        collide2d.Limits(max_objects=0)
    with pytest.raises(TypeError, match=r"^max_ticks='9': expected a whole number"):
        collide2d.Limits(max_ticks="9")
    with pytest.raises(TypeError, match=r"^max_side=1.5: expected a whole number"):
        collide2d.Limits(max_side=1.5)
    with pytest.raises(ValueError, match=r"^max_frames: a whole number too long to write out"):
        collide2d.Limits(max_frames=10**5000)


@pytest.mark.parametrize(
    "kwargs, error, said",
    [
        ({"frames": True}, TypeError, "frames=True: expected frame numbers"),
        ({"frames": 5}, TypeError, "frames=5: expected frame numbers"),
        ({"frames": {1: 2}}, TypeError, "frames={1: 2}: expected frame numbers"),
        ({"frames": [1.5]}, TypeError, "frames: item 0 (1.5) is not a whole number"),
        ({"frames": ["3"]}, TypeError, "frames: item 0 ('3') is not a whole number"),
        ({"frames": [2, True]}, TypeError, "frames: item 1 (True) is not a whole number"),
        ({"frames": "ALL"}, ValueError, "frames='ALL': expected frame numbers or one of"),
        ({"events": "no"}, TypeError, "events='no': expected True or False"),
        ({"events": None}, TypeError, "events=None: expected True or False"),
        ({"model": ["exact"]}, TypeError, "model=['exact']: expected a model name"),
        ({"limits": 5}, TypeError, "limits=5: expected a collide2d.Limits"),
        ({"png": True}, ValueError, "png=True: applies to a run written to a folder"),
        ({"overlay": ["boxes"]}, ValueError, "overlay=['boxes']: applies to a run written"),
        ({"scale": 2}, ValueError, "scale=2: applies to a run written to a folder"),
        ({"quiet": False}, ValueError, "quiet=False: applies to a run written to a folder"),
    ],
)
def test_run_refuses_a_wrong_argument_naming_it(kwargs, error, said):
    with pytest.raises(error) as info:
        collide2d.run(two_boxes(), **kwargs)
    assert str(info.value).startswith(said)


@pytest.mark.parametrize(
    "kwargs, error, said",
    [
        ({"overlay": ["nope"]}, ValueError, "overlay=['nope']: unknown overlay nope; choose from"),
        ({"overlay": "velocity,nope"}, ValueError, "overlay='velocity,nope': unknown overlay"),
        ({"overlay": ""}, ValueError, "overlay='': unknown overlay ''"),
        ({"overlay": [3]}, TypeError, "overlay=[3]: expected overlay names"),
        ({"overlay": 3}, TypeError, "overlay=3: expected overlay names"),
        ({"scale": 0}, ValueError, "scale=0: must be at least 1"),
        ({"scale": 1.5}, TypeError, "scale=1.5: expected a whole number"),
        ({"png": "yes"}, TypeError, "png='yes': expected True or False (or None"),
        ({"gif": 0}, TypeError, "gif=0: expected True or False (or None"),
        ({"viewer": "no"}, TypeError, "viewer='no': expected True or False (or None"),
        ({"quiet": None}, TypeError, "quiet=None: expected True or False"),
        ({"frames": [1]}, ValueError, "frames=[1]: frames are kept in memory"),
        ({"out": 5}, TypeError, "out=5: expected a folder (str or os.PathLike)"),
        ({"out": ""}, ValueError, "out='': names no folder"),
    ],
)
def test_run_into_a_folder_refuses_what_collide2d_run_refuses(
    tmp_path, monkeypatch, kwargs, error, said
):
    monkeypatch.chdir(tmp_path)  # out="" would name the current folder
    kwargs = {"out": tmp_path / "out"} | kwargs
    with pytest.raises(error) as info:
        collide2d.run(two_boxes(), **kwargs)
    assert str(info.value).startswith(said)
    assert not any(tmp_path.iterdir())


def test_run_takes_overlays_as_the_command_line_does(tmp_path):
    """A comma-separated text as `--overlay` takes it, or a sequence of names, in any order;
    `none` or an empty list for none: the same frames for the same overlays."""
    scene = two_boxes()
    scene["ticks"], scene["golden"]["frames"] = 2, [0, 2]
    pictures = {}
    for k, overlay in enumerate(
        ("velocity,boxes", ["boxes", "velocity"], np.array(["velocity", "boxes"]), "none", []),
    ):
        out = tmp_path / str(k)
        collide2d.run(scene, out=out, overlay=overlay, png=True, scale=np.int64(1))
        pictures[k] = (out / "two-boxes" / "frames" / "frame_000001.png").read_bytes()
    assert pictures[0] == pictures[1] == pictures[2] != pictures[3] == pictures[4]


def test_frames_take_numpy_whole_numbers():
    result = collide2d.run(two_boxes(), frames=np.array([0, 5]))
    assert sorted(result.frames) == [0, 5]
    assert sorted(collide2d.run(two_boxes(), frames=[np.int64(3)]).frames) == [3]


def test_limits_given_to_run_hold_for_the_scenario_it_reads():
    with pytest.raises(collide2d.ScenarioError, match="past the limit of 1 objects"):
        collide2d.run(two_boxes(), limits=collide2d.Limits(max_objects=1))


def project(tmp_path, *scenes: dict):
    (tmp_path / "scenarios").mkdir(parents=True)
    for k, scene in enumerate(scenes):
        (tmp_path / "scenarios" / f"s{k}.yaml").write_text(yaml.safe_dump(scene))
    return tmp_path


@pytest.mark.parametrize(
    "kwargs, error, said",
    [
        ({"root": "no_such_dir"}, ValueError, "root='no_such_dir' has no scenarios/ folder"),
        ({"root": 5}, TypeError, "root=5: expected a folder (str or os.PathLike)"),
        ({"scenarios": 5}, TypeError, "scenarios=5: expected a Scenario, a scenario file"),
        ({"scenarios": [two_boxes(), 5]}, TypeError, "scenarios[1]=5: expected a Scenario"),
        ({"scenarios": b"s0"}, TypeError, "scenarios=b's0': expected a Scenario"),
        ({"scenarios": []}, ValueError, "scenarios=[]: no scenario to check"),
        ({"bless": "no"}, TypeError, "bless='no': expected True or False"),
        ({"report": 5}, TypeError, "report=5: expected a folder"),
        ({"report": "r", "bless": True}, ValueError, "report='r': a report is written by"),
        ({"scenarios": ["s0", "s0"]}, ValueError, "scenarios/s0.yaml and scenarios/s0.yaml are"),
    ],
)
def test_check_refuses_what_collide2d_check_refuses(tmp_path, monkeypatch, kwargs, error, said):
    monkeypatch.delenv("CI", raising=False)
    monkeypatch.chdir(project(tmp_path, two_boxes()))
    with pytest.raises(error) as info:
        collide2d.check(**kwargs)
    assert str(info.value).startswith(said), str(info.value)
    assert not (tmp_path / "goldens").exists() and not (tmp_path / "r").exists()


def test_check_of_a_project_without_scenarios_is_refused_not_ok(tmp_path, monkeypatch):
    monkeypatch.delenv("CI", raising=False)  # in CI, bless is refused before anything is read
    (tmp_path / "scenarios").mkdir()
    with pytest.raises(ValueError, match="no scenario files in"):
        collide2d.check(root=tmp_path)
    with pytest.raises(ValueError, match="no scenario files in"):
        collide2d.check(root=tmp_path, bless=True)


def test_check_refuses_a_report_folder_that_holds_the_project(tmp_path):
    root = project(tmp_path / "p", two_boxes())
    with pytest.raises(ValueError, match="^report .* name a folder of its own"):
        collide2d.check(root=root, report=tmp_path)


def test_check_takes_numpy_flags_and_paths(tmp_path, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    root = project(tmp_path, two_boxes())
    assert collide2d.check(root=str(root), bless=np.bool_(True)).ok
    assert collide2d.check(("s0",), root=root).ok
    assert len(collide2d.check(root=root).scenarios) == 1
