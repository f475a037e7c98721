"""Event records and their one fixed text form (docs/outputs.md#event-log)."""

import json

import numpy as np
import pytest

from collide2d.engine.events import (
    AXIS_X,
    EV_PAIR,
    EV_WALL,
    SIDE_LEFT,
    empty_events,
    format_event,
    format_number,
)


def record(**fields):
    rec = empty_events(1)
    for key, value in fields.items():
        rec[key] = value
    return rec[0]


def test_pair_line_matches_the_spec_byte_for_byte():
    rec = record(tick=6, t=0.6, type=EV_PAIR, a=0, b=1, code=AXIS_X, xdiff=2, ydiff=10)
    assert format_event(rec) == (
        '{"tick": 6, "t": 0.6, "type": "pair", "a": 0, "b": 1, "axis": "x", '
        '"xdiff": 2, "ydiff": 10}'
    )


def test_wall_line_matches_the_spec_byte_for_byte():
    rec = record(tick=9, t=0.9, type=EV_WALL, a=3, b=-1, code=SIDE_LEFT, xdiff=-1, ydiff=-1)
    assert format_event(rec) == '{"tick": 9, "t": 0.9, "type": "wall", "id": 3, "side": "left"}'


def test_models_without_overlap_sizes_leave_xdiff_out():
    rec = record(tick=2, t=0.123456789, type=EV_PAIR, a=1, b=4, code=AXIS_X, xdiff=-1, ydiff=-1)
    assert json.loads(format_event(rec)) == {
        "tick": 2,
        "t": 0.123456789,
        "type": "pair",
        "a": 1,
        "b": 4,
        "axis": "x",
    }


def test_times_round_trip_exactly():
    t = np.nextafter(0.1, 1.0)
    rec = record(tick=1, t=t, type=EV_WALL, a=0, b=-1, code=SIDE_LEFT)
    assert json.loads(format_event(rec))["t"] == t


@pytest.mark.parametrize(
    "x, text",
    [
        (3.0, "3"),
        (-0.0, "0"),
        (2.5, "2.5"),
        (0.1, "0.1"),
        (1e15, "1000000000000000"),
        (1e20, "1e+20"),
        (1e300, "1e+300"),
    ],
)
def test_format_number(x, text):
    assert format_number(x) == text


def test_format_number_refuses_non_finite():
    with pytest.raises(ValueError):
        format_number(float("nan"))
