"""Tests of runner/golden/compare.py: truth tables of the event, final-state and frame rules."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from collide2d.runner.golden.compare import compare_events, compare_final, compare_frame
from collide2d.runner.golden.serialize import pixel_sha256

WALL = {"tick": 2, "t": 0.5, "type": "wall", "id": 1, "side": "left"}
PAIR = {"tick": 3, "t": 0.75, "type": "pair", "a": 0, "b": 1, "axis": "x", "xdiff": 2, "ydiff": 5}


def _frame(changes=(), size=(4, 5)):
    """A black (h, w) frame with (x, y, delta) pixels raised by delta in the red channel."""
    h, w = size
    rgb = np.zeros((h, w, 3), np.uint8)
    for x, y, d in changes:
        rgb[y, x, 0] = d
    return rgb


# (color_threshold, max_diff_pixels, changed pixels as (x, y, delta), passes?)
FRAME_TABLE = [
    (0, 0, [], True),
    (0, 0, [(1, 1, 1)], False),
    (1, 0, [(1, 1, 1)], True),
    (1, 0, [(1, 1, 2)], False),
    (0, 1, [(1, 1, 255)], True),
    (0, 1, [(1, 1, 255), (2, 2, 1)], False),
    (10, 2, [(0, 0, 11), (3, 3, 11)], True),
    (10, 2, [(0, 0, 11), (3, 3, 11), (4, 2, 11)], False),
    (10, 2, [(0, 0, 10), (3, 3, 10), (4, 2, 10), (1, 1, 10)], True),
    (255, 0, [(0, 0, 255)], True),
]


@pytest.mark.parametrize("threshold, budget, changes, passes", FRAME_TABLE)
def test_frame_truth_table(threshold, budget, changes, passes):
    d = compare_frame(
        6, _frame(), _frame(changes), color_threshold=threshold, max_diff_pixels=budget
    )
    assert d.passed is passes
    assert d.n_diff == sum(delta > threshold for _x, _y, delta in changes)
    assert d.n_changed == len(changes)


def test_frame_counts_the_largest_channel_difference():
    e = np.zeros((2, 2, 3), np.uint8)
    a = e.copy()
    a[1, 0] = (3, 9, 4)
    d = compare_frame(0, e, a, color_threshold=8)
    assert (d.n_diff, d.max_delta) == (1, 9)
    assert compare_frame(0, e, a, color_threshold=9).passed


def test_frame_bounding_box_and_message():
    d = compare_frame(6, _frame(), _frame([(1, 3, 7), (3, 0, 200)]))
    assert d.bbox == (1, 0, 3, 3)
    assert not d.passed
    msg = d.message()
    assert "frame 6: 2 pixel(s) differ" in msg
    assert "x 1..3, y 0..3" in msg
    assert "largest channel difference 200" in msg


def test_frame_size_mismatch_fails_whatever_the_budget():
    d = compare_frame(
        4, _frame(size=(4, 5)), _frame(size=(5, 4)), color_threshold=255, max_diff_pixels=10**6
    )
    assert d.size_mismatch and not d.passed
    assert d.message() == "frame 4: size differs: golden 5x4, run 4x5"


def test_frame_hash_fast_path_and_fallback():
    e, a = _frame(), _frame([(2, 2, 50)])
    same = compare_frame(0, a, a, expected_sha256=pixel_sha256(a))
    assert same.passed and same.mask is None
    # A hash that is not the run's never lets a frame through: the pixels decide.
    d = compare_frame(0, e, a, expected_sha256=pixel_sha256(e))
    assert not d.passed and d.n_diff == 1


@settings(max_examples=30, deadline=None)
@given(
    e=arrays(np.uint8, (3, 4, 3)),
    a=arrays(np.uint8, (3, 4, 3)),
    threshold=st.integers(0, 255),
    budget=st.integers(0, 12),
)
def test_frame_matches_a_pixel_by_pixel_reference(e, a, threshold, budget):
    n = 0
    for y in range(3):
        for x in range(4):
            if max(abs(int(e[y, x, c]) - int(a[y, x, c])) for c in range(3)) > threshold:
                n += 1
    d = compare_frame(0, e, a, color_threshold=threshold, max_diff_pixels=budget)
    assert d.n_diff == n
    assert d.passed == (n <= budget)


def _changed(ev, **kw):
    out = dict(ev)
    out.update(kw)
    return out


# (golden events, run events, time_tolerance, index of the first divergence or None, reason part)
EVENT_TABLE = [
    ([WALL, PAIR], [WALL, PAIR], 0.0, None, ""),
    ([], [], 0.0, None, ""),
    ([WALL, PAIR], [WALL, _changed(PAIR, type="wall")], 0.0, 1, "type differs"),
    ([WALL, PAIR], [WALL, _changed(PAIR, b=2)], 0.0, 1, "b differs"),
    ([WALL, PAIR], [_changed(WALL, id=0), PAIR], 0.0, 0, "id differs"),
    ([WALL, PAIR], [_changed(WALL, side="top"), PAIR], 0.0, 0, "side differs"),
    ([WALL, PAIR], [WALL, _changed(PAIR, axis="xy")], 0.0, 1, "axis differs"),
    ([WALL, PAIR], [WALL, _changed(PAIR, xdiff=3)], 0.5, 1, "xdiff differs"),
    ([WALL, PAIR], [WALL, _changed(PAIR, tick=4)], 0.0, 1, "tick differs"),
    ([WALL, PAIR], [WALL, _changed(PAIR, t=1.0)], 0.0, 1, "t differs by 0.25 s"),
    ([WALL, PAIR], [WALL, _changed(PAIR, t=1.0)], 0.25, None, ""),
    ([WALL, PAIR], [WALL, _changed(PAIR, t=1.0)], 0.125, 1, "past time_tolerance 0.125 s"),
    ([WALL, PAIR], [WALL, _changed(PAIR, t=1.0, tick=4)], 0.25, None, ""),
    ([WALL, PAIR], [WALL, _changed(PAIR, t=float("nan"))], 1.0, 1, "t differs"),
    ([WALL, PAIR], [WALL], 0.0, 1, "missing from the run"),
    ([WALL], [WALL, PAIR], 0.0, 1, "not in the golden"),
    ([WALL, PAIR], [PAIR, WALL], 0.0, 0, "differ"),
]


@pytest.mark.parametrize("golden, run, tol, index, reason", EVENT_TABLE)
def test_events_truth_table(golden, run, tol, index, reason):
    m = compare_events(golden, run, tol)
    if index is None:
        assert m is None
    else:
        assert m is not None and m.index == index
        assert reason in m.reason


def test_event_message_names_the_first_divergence():
    m = compare_events([WALL, PAIR], [WALL, _changed(PAIR, axis="y")], 0.0)
    lines = m.message().splitlines()
    assert lines[0].startswith("events: first divergence at event #2 (tick 3, pair, 0-1): axis")
    assert "(golden 2 events, run 2)" in lines[0]
    assert lines[1].strip().startswith('expected: {"tick": 3')
    assert '"axis": "x"' in lines[1] and '"axis": "y"' in lines[2]


def test_event_message_when_the_run_stops_early():
    m = compare_events([WALL, PAIR], [WALL], 0.0)
    assert "event #2 (tick 3, pair, 0-1): missing from the run" in m.message()
    assert m.message().splitlines()[2].strip() == "actual:   (none)"


STATE = np.array([[10.0, 20.0, 4.0, -3.0], [0.0, 5.0, 0.0, 0.0]])


def _state(i, c, value):
    s = STATE.copy()
    s[i, c] = value
    return s


# (run state, time_tolerance, passes?); bounds are tol * (max(|v_c|) + 1) per axis c.
FINAL_TABLE = [
    (STATE, 0.0, True),
    (_state(0, 0, np.nextafter(10.0, 11.0)), 0.0, False),
    (_state(0, 0, 10.5), 0.1, True),  # |dx| 0.5 <= 0.1 * (4 + 1)
    (_state(0, 0, 10.5625), 0.1, False),
    (_state(0, 1, 19.6), 0.1, True),  # |dy| 0.4 <= 0.1 * (3 + 1)
    (_state(0, 1, 19.5), 0.1, False),
    (_state(1, 1, 5.0625), 0.0625, True),  # at rest: the bound is tol * 1
    (_state(1, 1, 5.125), 0.0625, False),
    (_state(0, 2, 4.5), 0.125, True),  # |dvx| 0.5 <= 0.125 * (4.5 + 1)
    (_state(0, 2, 5.0), 0.125, False),
    (_state(0, 2, -4.0), 1.0, False),  # a reversed velocity is a change, whatever the speed
    (_state(1, 0, np.nan), 10.0, False),
    (STATE[:1], 10.0, False),
]


@pytest.mark.parametrize("run, tol, passes", FINAL_TABLE)
def test_final_truth_table(run, tol, passes):
    assert (compare_final(STATE, run, tol) is None) is passes


def test_final_bound_uses_the_larger_speed():
    # vx 4 -> 9 with tol 0.5: the bound is 0.5 * (9 + 1) = 5 on x and vx, either way round;
    # with the golden's speed alone (0.5 * 5 = 2.5) the x below would fail.
    run = _state(0, 2, 9.0)
    run[0, 0] = 14.5
    assert compare_final(STATE, run, 0.5) is None
    assert compare_final(run, STATE, 0.5) is None
    run[0, 0] = 15.25
    m = compare_final(STATE, run, 0.5)
    assert (m.obj, m.column, m.allowed) == (0, "x", 5.0)


def test_final_messages():
    m = compare_final(STATE, _state(1, 1, 6.0), 0.0)
    assert m.message() == (
        "final state: 1 value(s) past tolerance, first object 1 y: expected 5.0, actual 6.0 "
        "(allowed ±0)"
    )
    assert compare_final(STATE, STATE[:1], 0.0).message() == (
        "final state: golden has 2 objects, the run 1"
    )
