"""The paper model's records, read by field in every kernel: `State` (the objects, in integers),
`Plan` (the kernel's settings, whole numbers but the cell) and `Lists` (the candidate list kept
between calls, and the stages' scratch).

numba takes a named tuple as it takes a tuple; the kernel Python calls (`model._run`) takes each
record as a plain tuple of its fields and names it again inside, since numba reads the type of a
named tuple handed to it from Python field by field (microseconds a call).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class State(NamedTuple):
    """The objects' state, one row per object in id order (int32 when the world allows it, else
    int64; numba takes a named tuple as it takes a tuple, and the kernels read it by field)."""

    pos: np.ndarray  # (n, 2) top-left corners, px
    size: np.ndarray  # (n, 2) box sides, px
    room: np.ndarray  # (n, 2) world side - box side, px: the largest position inside the world
    step: np.ndarray  # (n, 2) the step V of each velocity component, px
    period: np.ndarray  # (n, 2) its period P, ticks
    count: np.ndarray  # (n, 2) its counter, ticks since it last fired
    movable: np.ndarray  # (n,) bool: what the broad phase pairs


class Plan(NamedTuple):
    """The kernel's settings, whole numbers but the cell."""

    window: int  # the candidate list's window, ticks (_WINDOW_TICKS)
    cap: int  # the largest margin, px (_MARGIN_MAX_PX)
    longest: int  # the longest window, ticks (_WINDOW_MAX_TICKS)
    cell: float  # the grid's cell side, px (broadphase.choose)
    chunks: int  # the split stages' chunks (threads.chunks_for; 1 for no split)


class Lists(NamedTuple):
    """The candidate list kept between calls, and the broad and narrow stages' scratch."""

    order: np.ndarray  # (n,) int64 sweep order
    fence: np.ndarray  # (n, 4) [x lo, x hi, y lo, y hi] the positions each object may hold while
    # the list lasts (made with the list)
    keys: np.ndarray  # candidate keys a << KEY_SHIFT | b
    near: np.ndarray  # this tick's near pairs (room for each thread's share past len(keys))
    disp: np.ndarray  # (n, 2) this tick's displacement
    lo: np.ndarray  # (n, 2) int64 grown reach boxes, low corners
    hi: np.ndarray  # (n, 2) int64 grown reach boxes, high corners
    found: np.ndarray  # (chunks, 3) int64 what each thread of a split stage found
    forced: np.ndarray  # int64 the periods of the steps longer than the largest margin, each once,
    # sorted (see _WINDOW_MAX_TICKS)
    finder: np.ndarray  # the method's marker (broadphase.marker: only that pair finder compiles)
    reach: np.ndarray  # (n, 4) reach boxes of this tick, for the narrow stage (`_reach`)
    ws: tuple  # the pair finders' scratch (broadphase.workspace)
