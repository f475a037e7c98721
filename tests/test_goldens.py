"""The golden tests: every scenario in scenarios/ against its golden in goldens/ (docs/goldens.md).

One test per scenario file, `test_golden[fig2_case1]`, parametrised by the golden plugin
(`runner.golden.plugin`), and the same again with the kernels compiled and interpreted
(`test_golden_compiled_and_interpreted`): both lanes must give the golden's bytes. A test runs
the scenario, compares events, final state and golden frames with `goldens/NAME/`, and fails with
the same text `collide2d check` prints; a missing golden is a failure naming the command that
creates it. `pytest --update-goldens` blesses what runs instead.
"""

from __future__ import annotations

import pytest

# The whole goldens/ folder stays small enough to live in the repository (bytes).
GOLDENS_BUDGET_BYTES = 5 * 1024 * 1024


def test_golden(golden_scenario, golden_check):
    golden_check(golden_scenario)


@pytest.mark.parametrize("mode", ["on", "off"])
def test_golden_compiled_and_interpreted(golden_scenario, golden_check, mode):
    # the same bytes whichever lane runs the kernels (runner.lanes; `auto` picks one per run)
    from collide2d.runner import lanes

    lanes.set_mode(mode)
    try:
        golden_check(golden_scenario)
    finally:
        lanes.set_mode(None)


def test_goldens_stay_small(golden_root):
    folder = golden_root / "goldens"
    files = sorted(p for p in folder.rglob("*") if p.is_file()) if folder.is_dir() else []
    total = sum(p.stat().st_size for p in files)
    assert total <= GOLDENS_BUDGET_BYTES, f"goldens/ holds {total:,} bytes, past the budget"


# What the paper says the blessed goldens must show (section numbers point into the paper).


def _golden(root, name):
    from collide2d.runner.golden.store import GoldenError, GoldenStore

    try:
        return GoldenStore(root).read(name)
    except GoldenError as exc:
        problem = str(exc)
    pytest.fail(f"{problem}; create it with: collide2d bless scenarios/{name}.yaml", pytrace=False)


def _pairs(golden):
    return [e for e in golden.events if e["type"] == "pair"]


def test_tunnelling_at_1_fps_misses_the_collision(golden_root):
    # §III.A: at 1 fps the two boxes jump through each other without a collision.
    g = _golden(golden_root, "tunnelling_1fps")
    assert _pairs(g) == []
    left_x, right_x = g.final[0, 0], g.final[1, 0]
    assert left_x > right_x, "the boxes should have passed each other"
    assert g.final[0, 2] > 0 > g.final[1, 2], "neither box should have turned back"


def test_tunnelling_at_10_fps_bounces(golden_root):
    # §III.A: at 10 fps the same boxes collide and bounce back along x.
    g = _golden(golden_root, "tunnelling_10fps")
    pairs = _pairs(g)
    assert pairs and (pairs[0]["a"], pairs[0]["b"], pairs[0]["axis"]) == (0, 1, "x")
    assert g.final[0, 0] < g.final[1, 0], "the boxes should not have passed each other"


# §II.F, Figure 2: which velocity component each case flips.
FIG2_AXES = {"fig2_case1": "y", "fig2_case2": "x", "fig2_case3": "y", "fig2_case4": "y"}


def test_figure_2_cases_flip_the_axis_the_paper_gives(golden_root):
    for name, axis in FIG2_AXES.items():
        pairs = _pairs(_golden(golden_root, name))
        assert pairs, f"{name}: no collision in the golden"
        assert pairs[0]["axis"] == axis, f"{name}: first collision flips {pairs[0]['axis']}"
        assert (pairs[0]["xdiff"] > pairs[0]["ydiff"]) == (axis == "y"), name


def test_section_iv_demo_keeps_fifty_boxes(golden_root):
    # §IV: 50 boxes of 10x10 px at 10 px/s on each axis, 10 fps.
    g = _golden(golden_root, "paper_fifty_boxes")
    assert g.final.shape == (50, 4)
    assert set(abs(g.final[:, 2:]).ravel()) == {10.0}
    assert 0 in g.frames and len(g.frames) >= 2
