"""Events as data: one fixed record type for every model, and its one fixed text form.

A model's `advance()` returns a numpy array of `EVENT_DTYPE` records in the order the events
happened. `format_event` turns one record into the `events.jsonl` line of docs/outputs.md#event-log,
with floats written one fixed way (`format_number`) so that logs diff line by line and the same run
gives the same bytes.

The event log the models write while they run is one layout for all three: rows (k, 7) int64
(columns ROW_TICK ... ROW_YDIFF: tick, type, a, b, code, xdiff, ydiff; xdiff/ydiff -1 but in the
paper model) and times (k,) float64, the event's `t` (the paper model keeps no times: its `t` is
the tick's end, tick / fps, given when the rows become records). `new_log` makes the buffers,
`put_event` writes a row inside a kernel (the caller made room), `log_event` writes one and grows
the buffers when full, `grown` doubles a buffer between kernel calls, and `event_records` turns
the first n rows into EVENT_DTYPE records.
"""

from __future__ import annotations

import json
import math

import numpy as np

from collide2d.engine.jit import njit

EV_WALL = 0
EV_PAIR = 1
# the exact model under gravity: an object comes to rest on a wall or a box's face (a static box,
# or one resting still in a stack), stops sliding on it, is knocked off it, or slides past the
# box's edge (`code` is the side it presses into, `b` the box, -1 for a wall)
EV_REST = 2
EV_STOP = 3
EV_WAKE = 4
EV_LEAVE = 5
TYPE_NAMES = ("wall", "pair", "rest", "stop", "wake", "leave")

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
# contact time in exact); type: EV_WALL ... EV_LEAVE; a: the object (a wall, rest, stop, wake or
# leave) or the lower id (pair); b: the higher id (pair), the static box rested on (rest, stop,
# wake, leave), else -1; code: a SIDE_* (the wall; of a rest, stop, wake or leave the side it
# presses into), an AXIS_* for pairs;
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
    if rec["type"] != EV_PAIR:  # an object's own event: its id, the side, the static box (`on`)
        d["id"] = int(rec["a"])
        d["side"] = SIDE_NAMES[rec["code"]]
        if rec["b"] >= 0:
            d["on"] = int(rec["b"])
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


# --- the event log the models write ------------------------------------------------------------

# Columns of the log's rows (int64).
ROW_TICK, ROW_TYPE, ROW_A, ROW_B, ROW_CODE, ROW_XDIFF, ROW_YDIFF = range(7)
ROW_COLUMNS = 7
# Rows of a fresh log; it doubles when full.
LOG_ROWS = 1024


def new_log(log: bool = True, rows: int = LOG_ROWS) -> tuple[np.ndarray, np.ndarray]:
    """Empty log buffers (rows (k, 7) int64, times (k,) float64); one row when `log` is False."""
    k = rows if log else 1
    return np.empty((k, ROW_COLUMNS), np.int64), np.empty(k)


@njit(cache=True, inline="always")
def put_row(rows, n, tick, kind, a, b, code, xdiff, ydiff):
    """Write row n (the caller made room); returns n + 1."""
    rows[n, ROW_TICK] = tick
    rows[n, ROW_TYPE] = kind
    rows[n, ROW_A] = a
    rows[n, ROW_B] = b
    rows[n, ROW_CODE] = code
    rows[n, ROW_XDIFF] = xdiff
    rows[n, ROW_YDIFF] = ydiff
    return n + 1


@njit(cache=True, inline="always")
def put_event(rows, times, n, tick, t, kind, a, b, code):
    """Write event n at time t (s; no xdiff/ydiff) (the caller made room); returns n + 1."""
    times[n] = t
    return put_row(rows, n, tick, kind, a, b, code, -1, -1)


@njit(cache=True)
def log_event(rows, times, n, tick, t, kind, a, b, code):
    """Write event n, doubling the buffers first when full; returns the (rows, times) to use."""
    if n >= rows.shape[0]:
        more_rows = np.empty((max(2 * rows.shape[0], 16), ROW_COLUMNS), np.int64)
        more_times = np.empty(more_rows.shape[0])
        for r in range(n):  # by element: a slice copy compiles numba's broadcast check
            more_times[r] = times[r]
            for c in range(ROW_COLUMNS):
                more_rows[r, c] = rows[r, c]
        rows, times = more_rows, more_times
    put_event(rows, times, n, tick, t, kind, a, b, code)
    return rows, times


def grown(a: np.ndarray, extra: int = 0) -> np.ndarray:
    """a with twice its rows (and `extra` more), the old rows kept."""
    out = np.empty((2 * a.shape[0] + extra,) + a.shape[1:], a.dtype)
    out[: a.shape[0]] = a
    return out


def event_records(rows: np.ndarray, times: np.ndarray, n: int) -> np.ndarray:
    """The first n logged events as EVENT_DTYPE records."""
    out = np.zeros(n, dtype=EVENT_DTYPE)
    out["tick"] = rows[:n, ROW_TICK]
    out["t"] = times[:n]
    out["type"] = rows[:n, ROW_TYPE]
    out["a"] = rows[:n, ROW_A]
    out["b"] = rows[:n, ROW_B]
    out["code"] = rows[:n, ROW_CODE]
    out["xdiff"] = rows[:n, ROW_XDIFF]
    out["ydiff"] = rows[:n, ROW_YDIFF]
    return out
