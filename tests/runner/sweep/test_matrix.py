"""The sweep's matrix: --set and --seeds read, the product expanded and each run's scenario
loaded with its values exactly as a file holding them would be."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from collide2d.runner.scenario.load import ScenarioError, load, loads
from collide2d.runner.sweep import matrix
from collide2d.runner.sweep.matrix import SweepError, parse_seeds, parse_set

from .planned import expand

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"
FIFTY = str(SCENARIOS / "paper_fifty_boxes.yaml")


def test_set_values_split_on_commas_outside_brackets():
    axis = parse_set("generate.0.size=[10, 12],8, [3,4]")
    assert axis.key == "generate.0.size"
    assert axis.texts == ("[10, 12]", "8", "[3,4]")
    assert [type(n).__name__ for n in axis.nodes] == ["SequenceNode", "ScalarNode", "SequenceNode"]


def test_a_comma_inside_a_quoted_value_stays_in_the_value():
    axis = parse_set("""objects.0.name='a, b',"c, \\"d\\", e",it's,'x''y, z',[' ]', 2],f""")
    assert axis.texts == ("'a, b'", '"c, \\"d\\", e"', "it's", "'x''y, z'", "[' ]', 2]", "f")
    values = [
        n.value if hasattr(n.value, "upper") else [v.value for v in n.value] for n in axis.nodes
    ]
    assert values == ["a, b", 'c, "d", e', "it's", "x'y, z", [" ]", "2"], "f"]


def test_a_side_past_its_bound_names_the_bound_whatever_the_number():
    for value, shown in (
        ("1e308", "1e308"),
        ("100000", "100000"),
        ("2e19", "20000000000000000000"),
    ):
        with pytest.raises(ScenarioError) as err:
            expand([FIFTY], [parse_set(f"world.width={value}")], None)
        assert err.value.message.endswith(
            f"world.width {shown} is past the limit of 16384 px per side; raise it with --max-side"
        )


@pytest.mark.parametrize(
    "option, said",
    [
        ("fps", "expected KEY=V1,V2"),
        ("=3", "expected KEY=V1,V2"),
        ("world..width=3", "is not a key to sweep"),
        ("0.count=3", "is not a key to sweep"),
        ("world.fps=3", "sweep 'world' with the run settings"),
        ("duration=3", "sweep 'duration' with the run settings"),
        ("fps=10,", "an empty value"),
        ("fps=[1", "is not a YAML value"),
    ],
)
def test_bad_set_options_are_refused(option, said):
    with pytest.raises(SweepError, match=said.replace("[", r"\[")):
        parse_set(option)


def test_seeds_ranges_and_lists():
    assert parse_seeds("3-5") == (3, 4, 5)
    assert parse_seeds("7") == (7,)
    assert parse_seeds("9,1-2,2") == (1, 2, 9)
    for bad in ("5-3", "a-b", "1-", "-1", f"0-{2**64}"):
        with pytest.raises(SweepError, match="--seeds"):
            parse_seeds(bad)


def test_settings_a_model_does_not_take_count_once():
    runs = expand(
        [FIFTY], [parse_set("model=paper,stepped,exact"), parse_set("substeps=1,4")], None
    )
    got = [(r.params["model"], r.params["substeps"], r.params["geometry"]) for r in runs]
    assert got == [
        ("exact", "", "exact"),
        ("paper", "", ""),
        ("stepped", "1", "box"),
        ("stepped", "4", "box"),
    ]
    stepped4 = runs[3].scenario
    assert (stepped4.model, stepped4.substeps) == ("stepped", 4)
    assert [r.index for r in runs] == [0, 1, 2, 3]


def test_rows_are_sorted_by_value_not_by_the_order_given():
    runs = expand([FIFTY], [parse_set("fps=60,10,30"), parse_set("world.width=640,320")], None)
    got = [(r.params["world.width"], r.params["fps"]) for r in runs]
    assert got == [(w, f) for w in ("320", "640") for f in ("10", "30", "60")]
    assert matrix.columns([parse_set("fps=1"), parse_set("world.width=1")], (1,)) == [
        "scenario",
        "world.width",
        "seed",
        "model",
        "fps",
        "ticks",
        "substeps",
        "geometry",
    ]


def test_dotted_keys_and_seeds_load_like_the_edited_file():
    text = open(FIFTY).read()
    runs = expand([FIFTY], [parse_set("world.width=400"), parse_set("generate.0.count=7")], (11,))
    assert len(runs) == 1
    got = runs[0].scenario
    edited = (
        text.replace("width: 320", "width: 400")
        .replace("count: 50", "count: 7")
        .replace("seed: 4", "seed: 11")
    )
    want = loads(edited, FIFTY)
    assert got.world == want.world and got.world.width == 400
    assert got.bodies.n == 7
    np.testing.assert_array_equal(got.bodies.pos, want.bodies.pos)
    np.testing.assert_array_equal(got.bodies.vel, want.bodies.vel)
    assert not np.array_equal(got.bodies.pos, load(FIFTY).bodies.pos[:7])


def test_a_key_the_file_lacks_is_added_and_checked():
    runs = expand(
        [FIFTY],
        [
            parse_set("world.height=300"),
            parse_set("model=stepped"),
            parse_set("geometry=exact"),
            parse_set("ticks=5"),
        ],
        None,
    )
    scn = runs[0].scenario
    assert (scn.world.height, scn.model, scn.geometry, scn.ticks) == (300, "stepped", "exact", 5)


def test_a_bad_value_is_refused_at_the_scenario_node_naming_the_run():
    with pytest.raises(ScenarioError) as err:
        expand([FIFTY], [parse_set("world.width=320,0")], (2,))
    text = str(err.value)
    assert text.startswith(f"{FIFTY}:6:")
    assert "in the sweep run world.width=0, seed=2: world.width" in text
    with pytest.raises(ScenarioError, match="in the sweep run world.widht=3: unknown key 'widht'"):
        expand([FIFTY], [parse_set("world.widht=3")], None)


def test_paths_that_lead_nowhere_are_refused():
    with pytest.raises(SweepError, match="has no generate.3"):
        expand([FIFTY], [parse_set("generate.3.count=4")], None)
    with pytest.raises(SweepError, match="name is a single value"):
        expand([FIFTY], [parse_set("name.x=4")], None)
    fig = str(SCENARIOS / "fig2_case1.yaml")
    with pytest.raises(SweepError, match="--seeds needs a generate block"):
        expand([fig], [], (1, 2))


def test_repeated_keys_and_values_and_unknown_models_are_refused():
    with pytest.raises(SweepError, match="fps is swept twice"):
        expand([FIFTY], [parse_set("fps=1"), parse_set("fps=2")], None)
    with pytest.raises(SweepError, match="given twice"):
        expand([FIFTY], [parse_set("fps=1,1")], None)
    with pytest.raises(SweepError, match="unknown model 'exakt'"):
        expand([FIFTY], [parse_set("model=exakt")], None)
