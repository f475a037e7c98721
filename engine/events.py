"""Events as data: one fixed record type for every model, and its one fixed text form.

A model's `advance()` returns a numpy array of `EVENT_DTYPE` records in the order the events
happened. `format_event` turns one record into the `events.jsonl` line of SPEC section 5, with
floats written one fixed way (`format_number`) so that logs diff line by line and the same run gives
the same bytes.
"""

from __future__ import annotations

import json
import math

import numpy as np

EV_WALL = 0
EV_PAIR = 1
TYPE_NAMES = ("wall", "pair")

AXIS_X = 0
AXIS_Y = 1
AXIS_XY = 2
AXIS_NORMAL = 3  # a contact normal that is not axis-aligned (exact shapes)
AXIS_NAMES = ("x", "y", "xy", "n")

SIDE_LEFT = 0
SIDE_RIGHT = 1
SIDE_TOP = 2
SIDE_BOTTOM = 3
SIDE_NAMES = ("left", "right", "top", "bottom")

# tick: the tick (1-based) the event belongs to; t: seconds (tick end in paper/stepped, the exact
# contact time in exact); type: EV_WALL or EV_PAIR; a: the object (wall) or the lower id (pair);
# b: the higher id, -1 for walls; code: a SIDE_* for walls, an AXIS_* for pairs;
# xdiff/ydiff: the overlap's width and height (paper model only, else -1).
EVENT_DTYPE = np.dtype(
    [
        ("tick", np.int64),
        ("t", np.float64),
        ("type", np.int8),
        ("a", np.int32),
        ("b", np.int32),
        ("code", np.int8),
        ("xdiff", np.int64),
        ("ydiff", np.int64),
    ]
)


def empty_events(n: int = 0) -> np.ndarray:
    return np.zeros(n, dtype=EVENT_DTYPE)


def format_number(x: float) -> str:
    """One fixed text for a number: whole floats as integers, others as the shortest repr."""
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"non-finite number {x!r} cannot be written")
    if x.is_integer() and abs(x) < 2**53:
        return str(int(x))
    return repr(x)


def event_dict(rec) -> dict:
    """The JSON object of one event record, keys in their fixed order."""
    d = {"tick": int(rec["tick"]), "t": float(rec["t"]), "type": TYPE_NAMES[rec["type"]]}
    if rec["type"] == EV_WALL:
        d["id"] = int(rec["a"])
        d["side"] = SIDE_NAMES[rec["code"]]
    else:
        d["a"] = int(rec["a"])
        d["b"] = int(rec["b"])
        d["axis"] = AXIS_NAMES[rec["code"]]
        if rec["xdiff"] >= 0:
            d["xdiff"] = int(rec["xdiff"])
            d["ydiff"] = int(rec["ydiff"])
    return d


def format_event(rec) -> str:
    """The events.jsonl line (no newline) of one record: `{"tick": 6, "t": 0.6, ...}`."""
    return json.dumps(event_dict(rec))
