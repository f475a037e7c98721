"""Tests of the `rests` overlay (runner/output/overlay.py, runner/output/rests.py; docs/drawing.md):
under the exact model and gravity it draws, in its own colour and nowhere else, a line from each
resting object's centre to its edge, a mark across the contact on its support and a line on to a
supporting object's centre, from the tick of the `rest` event (or tick 0 for an object that starts
still on a wall) until the `wake` or `leave`, the ticks no frame draws included; other models draw
nothing for it; the schema and `--overlay` take it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from collide2d.engine.picture.pixels import dda_line
from collide2d.engine.picture.raster import round_positions
from collide2d.runner.command import main
from collide2d.runner.output.overlay import COLORS, MARK_PX, Overlay
from collide2d.runner.output.rests import Rests
from collide2d.runner.run import drive, make_model
from collide2d.runner.scenario.load import ScenarioError, load, loads
from collide2d.runner.scenario.schema import json_schema
from collide2d.runner.scenario.sections import OVERLAY_NAMES

ROOT = Path(__file__).resolve().parents[2]
GREEN = (0, 230, 0)

# ledge 0, a box resting on it from tick 1, and a shot from below that wakes it at tick 6 (it
# rests again at 10) and at tick 25 (again at 26)
WAKE = """version: 1
world: {width: 120, height: 100, fps: 30, gravity: 980}
model: exact
ticks: 30
objects:
  - {shape: box, size: [40, 8], position: [10, 50], static: true, color: white, fill: true}
  - {shape: box, size: [20, 10], position: [40, 40], restitution: 0, color: cyan, fill: true}
  - {shape: box, size: [6, 6], position: [52, 90], velocity: [0, -300], restitution: 1,
     color: yellow, fill: true}
"""
# a platform 0 with box 1 dropped on it (rest at tick 7), box 2 dropped on the floor (tick 9) and
# box 3 dropped on box 2, off its centre (tick 11): a stack of two on the floor
STACK = """version: 1
world: {width: 120, height: 80, fps: 30, gravity: 980}
model: exact
ticks: 20
objects:
  - {shape: box, size: [40, 8], position: [10, 50], static: true, color: white, fill: true}
  - {shape: box, size: [10, 10], position: [25, 20], restitution: 0, color: cyan, fill: true}
  - {shape: box, size: [12, 6], position: [80, 30], restitution: 0, color: yellow, fill: true}
  - {shape: box, size: [8, 8], position: [86, 5], restitution: 0, color: magenta, fill: true}
"""
# placed still: box 0 on the floor (resting from the start, no event), box 1 on box 0 (event at
# tick 1), box 2 sliding on the floor, box 3 against the right wall (gravity does not pull it in)
PLACED = """version: 1
world: {width: 120, height: 80, fps: 30, gravity: 980}
model: exact
ticks: 4
objects:
  - {shape: box, size: [20, 10], position: [50, 70], restitution: 0, color: cyan, fill: true}
  - {shape: box, size: [20, 10], position: [50, 60], restitution: 0, color: yellow, fill: true}
  - {shape: box, size: [10, 10], position: [0, 70], velocity: [20, 0], color: white}
  - {shape: box, size: [10, 10], position: [110, 30], velocity: [0, 5], color: white}
"""


def _frames(scn, frames, names=("rests",)):
    """{frame: (H, W, 3) RGB} of the run drawing `names`, and the overlay."""
    layer = Overlay(scn, names)
    seen = {}
    drive(scn, frames=frames, on_frame=lambda k, idx: seen.__setitem__(k, idx.copy()),
          overlay=layer)  # fmt: skip
    return {k: layer.palette[idx] for k, idx in seen.items()}, layer


def _green(rgb) -> np.ndarray:
    return (rgb == GREEN).all(axis=2)


def _positions(scn, ticks) -> dict:
    """{tick: rounded positions} of a plain run of the scenario."""
    model, out = make_model(scn), {}
    for k in sorted(ticks):
        model.advance(k - model.tick, False)
        out[k] = round_positions(model.positions())
    return out


def _expected(shape, ipos, sizes, rests) -> np.ndarray:
    """The pixels docs/drawing.md says `rests` paints, for rests {object: support or None} all on
    `bottom` and whole-box sprites: centre to bottom edge, a mark 2 * MARK_PX + 1 wide on the row
    below (the frame's last row for the floor), and from its middle to the support's centre."""
    h, w = shape
    mask = np.zeros(shape, bool)

    def line(a, b):
        pts = dda_line(*a, *b)
        ok = (pts[:, 0] >= 0) & (pts[:, 0] < w) & (pts[:, 1] >= 0) & (pts[:, 1] < h)
        mask[pts[ok, 1], pts[ok, 0]] = True

    def centre(i):
        return (ipos[i][0] + (sizes[i][0] - 1) // 2, ipos[i][1] + (sizes[i][1] - 1) // 2)

    for i, on in rests.items():
        cx, cy = centre(i)
        bottom = ipos[i][1] + sizes[i][1] - 1
        face = min(bottom + 1, h - 1)
        line((cx, cy), (cx, bottom))
        line((cx - MARK_PX, face), (cx + MARK_PX, face))
        if on is not None:
            line((cx, face), centre(on))
    return mask


def _sizes(scn):
    return np.asarray(scn.bodies.size, np.int64).tolist()


# ----------------------------------------------------------------------------- the ledges


LEDGES = ROOT / "scenarios" / "exact_ledges.yaml"


def _ledges_rests(k: int) -> dict:
    """What rests on what at tick k in exact_ledges (goldens/exact_ledges/events.jsonl): block 2
    on the upper ledge 0 from tick 1 until it leaves at 68, then on the lower ledge 1 from 106;
    crate 4 on ledge 1 from 1; ball 3 on ledge 1 from 48."""
    rests = {}
    if 1 <= k < 68:
        rests[2] = 0
    if k >= 106:
        rests[2] = 1
    if k >= 48:
        rests[3] = 1
    if k >= 1:
        rests[4] = 1
    return rests


def test_the_ledges_show_each_rest_from_its_tick_to_its_end_ticks_between_frames_included():
    """Frames every 5 ticks: the ball's rest (tick 48), the block's leave (68) and its rest again
    (106) all fall between frames; each frame shows exactly the rests of its tick."""
    scn = load(LEDGES, overrides={"ticks": 110})
    ticks = range(0, 111, 5)
    frames, layer = _frames(scn, ticks)
    assert layer.index["rests"] == len(scn.palette)  # the only overlay: the first colour after
    positions = _positions(scn, ticks)
    for k in ticks:
        want = _expected(frames[k].shape[:2], positions[k], _sizes(scn), _ledges_rests(k))
        assert np.array_equal(_green(frames[k]), want), k
    assert not _green(frames[0]).any()


def test_the_ball_is_marked_where_it_lies_once_at_rest_and_not_before():
    scn = load(LEDGES, overrides={"ticks": 50})
    frames, _ = _frames(scn, (45, 50))
    # the ball (diameter 12) lies at (270, 158) on the lower ledge's top (y 170): a line from its
    # centre (275, 163) down to its bottom row (169), a mark on the ledge's row 170 from 272 to
    # 278, and a line from (275, 170) to the ledge's centre (140 + 79, 170 + 5)
    drawn = _green(frames[50])
    assert drawn[163:170, 275].all()
    assert drawn[170, 272:279].all() and not drawn[170, 279]  # the link runs left from 275
    link = dda_line(275, 170, 219, 175)
    assert drawn[link[:, 1], link[:, 0]].all()
    assert not _green(frames[45])[158:171, 264:282].any()  # still bouncing at tick 45


def test_the_block_that_leaves_the_upper_ledge_loses_its_marks():
    scn = load(LEDGES, overrides={"ticks": 70})
    frames, _ = _frames(scn, (65, 70))
    # the upper ledge: x 20 to 139, y 80 to 91; the block rests on it until tick 68
    assert _green(frames[65])[60:92, 20:140].any()
    assert not _green(frames[70])[:100, :].any()  # nothing rests above the lower ledge


# ----------------------------------------------------------------------------- wake, stacks


def test_a_woken_object_loses_its_marks_until_it_rests_again():
    scn = loads(WAKE)
    frames, _ = _frames(scn, range(31))
    resting = {k for k in range(31) if 1 <= k < 6 or 10 <= k < 25 or k >= 26}
    assert {k for k, rgb in frames.items() if _green(rgb).any()} == resting
    # frames every 4 ticks see the same: nothing at 8 (woken at 6), the box again at 12
    every, _ = _frames(scn, range(0, 31, 4))
    for k, rgb in every.items():
        assert np.array_equal(rgb, frames[k]), k
    positions = _positions(scn, (12,))
    want = _expected(frames[12].shape[:2], positions[12], _sizes(scn), {1: 0})
    assert np.array_equal(_green(frames[12]), want)


def test_a_stack_shows_the_line_from_the_upper_box_to_the_lower_one():
    scn = loads(STACK)
    frames, _ = _frames(scn, (8, 10, 11, 20))
    # box 3 (8x8) lies at (86, 66) on box 2 (12x6 at (80, 74)): its centre (89, 69), down to its
    # bottom row 73, the mark on box 2's top row 74 and on to box 2's centre (85, 76); box 2's
    # own line goes from (85, 76) down to the floor's row 79, its mark from 82 to 88 there
    link = dda_line(89, 74, 85, 76)
    for k in (11, 20):
        drawn = _green(frames[k])
        assert drawn[link[:, 1], link[:, 0]].all(), k
        assert drawn[69:74, 89].all() and drawn[74, 86:93].all()
        assert drawn[76:80, 85].all() and drawn[79, 82:89].all()
        ipos = _positions(scn, (k,))[k]
        want = _expected(drawn.shape, ipos, _sizes(scn), {1: 0, 2: None, 3: 2})
        assert np.array_equal(drawn, want), k
    # box 3 still falls at tick 10: no link (its end, box 2's centre, is on box 2's own line)
    assert not _green(frames[10])[link[:-1, 1], link[:-1, 0]].any()
    assert _green(frames[10])[79, 82:89].all()  # box 2 rests from tick 9
    assert not _green(frames[8])[60:80, 60:100].any()


def test_objects_placed_still_on_the_floor_rest_from_tick_0():
    scn = loads(PLACED)
    frames, _ = _frames(scn, (0, 1))
    positions = _positions(scn, (0, 1))
    shape = frames[0].shape[:2]
    sizes = _sizes(scn)
    assert np.array_equal(
        _green(frames[0]), _expected(shape, positions[0], sizes, {0: None, 2: None})
    )
    want = _expected(shape, positions[1], sizes, {0: None, 1: 0, 2: None})
    assert np.array_equal(_green(frames[1]), want)


@pytest.mark.parametrize(
    "text", [WAKE, STACK, PLACED, LEDGES], ids=["wake", "stack", "placed", "ledges"]
)
def test_the_rests_followed_from_the_events_are_the_models_at_every_tick(text):
    """The events (and the rests at the start) give what the model itself reports (its
    `rests()`) after every chunk of ticks."""
    scn = load(text, overrides={"ticks": 120}) if isinstance(text, Path) else loads(text)
    model, rests = make_model(scn), Rests()
    rests.start(model)
    for step in [1, 2, 3, 5, 7, 11] * 10:
        if model.tick + step > scn.ticks:
            break
        rests.events(model.advance(step))
        assert rests.at(model.tick) == model.rests(), model.tick


# ----------------------------------------------------------------------------- other models


STEPPED_STACK = STACK.replace("model: exact", "model: stepped")


@pytest.mark.parametrize(
    "source, overrides",
    [
        ("gravity_stack", {"ticks": 60}),  # stepped: boxes resting under gravity
        (STEPPED_STACK, None),  # the stack above under stepped
        ("fig2_case1", None),  # paper
        ("wall_bounces", {"ticks": 30, "model": "exact"}),  # exact without gravity
    ],
    ids=["stepped-stack", "stepped-drop", "paper", "exact-no-gravity"],
)
def test_other_models_and_no_gravity_draw_nothing(source, overrides):
    if source == STEPPED_STACK:
        scn = loads(source)
    else:
        scn = load(ROOT / "scenarios" / f"{source}.yaml", overrides=overrides)
    rests = Rests()
    rests.start(make_model(scn))
    assert rests.at(0) == {}
    ticks = (0, 1, min(30, scn.ticks), scn.ticks)
    drawn, _ = _frames(scn, ticks)
    plain, _ = _frames(scn, ticks, names=())
    for k in ticks:
        assert np.array_equal(drawn[k], plain[k]), k


def test_the_colours_of_the_other_overlays_keep_their_palette_places():
    scn = load(ROOT / "scenarios" / "fig2_case1.yaml")
    base = len(scn.palette)
    before = Overlay(scn, OVERLAY_NAMES[:-1])  # the five overlays there were
    assert OVERLAY_NAMES[-1] == "rests" and COLORS["rests"] == GREEN
    keys = ["velocity", "boxes", "contacts", "labels", "overlap", "ghost"]
    assert before.index == {k: base + j for j, k in enumerate(keys)}
    every = Overlay(scn, OVERLAY_NAMES)
    assert every.index == {**{k: base + j for j, k in enumerate(keys[:5])}, "rests": base + 5,
                           "ghost": base + 6}  # fmt: skip
    assert every.palette[base + 5].tolist() == list(GREEN)


# ----------------------------------------------------------------------------- schema, CLI


def test_the_schema_and_the_loader_take_rests_and_refuse_a_near_name_at_its_place():
    items = json_schema()["properties"]["output"]["properties"]["overlay"]["items"]["enum"]
    assert items == ["velocity", "boxes", "contacts", "labels", "overlap", "rests"]
    assert loads("version: 1\noutput: {overlay: [rests, boxes]}\n").output.overlay == (
        "boxes",
        "rests",
    )
    with pytest.raises(ScenarioError) as err:
        loads("version: 1\noutput: {overlay: [boxes, rest]}\n")
    assert (err.value.line, err.value.col) == (2, 27)
    assert "did you mean 'rests'" in err.value.message


def test_run_overlay_rests_draws_into_the_png_and_refuses_an_unknown_name(tmp_path, capsys):
    argv = ["run", str(LEDGES), "--out", str(tmp_path), "--png", "--quiet", "--ticks", "50"]
    assert main.main([*argv, "--no-gif", "--overlay", "rests"]) == 0
    folder = tmp_path / "exact_ledges" / "frames"

    def green(k):
        return _green(np.array(Image.open(folder / f"frame_{k:06d}.png").convert("RGB")))

    assert green(50)[170, 272:279].all()  # the ball's mark on the lower ledge
    assert not green(0).any()
    with pytest.raises(SystemExit):
        main.main([*argv, "--overlay", "rests,rest"])
    err = capsys.readouterr().err
    assert "unknown overlay rest;" in err and "overlap, rests or none" in err
