"""Broad phase: which pairs could touch, so that exact tests run only on near neighbours.

Input everywhere: boxes as corners `lo`, `hi` (n, 2) px (each box is [lo, hi) on both axes) and
which objects can move. Output: candidate pairs (a, b), a < b, as keys `a << KEY_SHIFT | b` (int64),
the pairs whose boxes overlap with positive area and that hold at least one movable object: two
static objects never become a pair (static objects never move: docs/models.md#common-rules).

- `sweep_candidates` sorts the boxes on x (an order kept from call to call and mended by
  insertion sort, since objects move little between calls) and sweeps: cheap when few boxes share
  an x interval (small scenes, narrow worlds).
- `grid_candidates` files every box in each cell of a uniform grid that the box meets and tests
  the pairs inside each cell; a pair is reported only in the cell that holds the lower corner of
  the two boxes' intersection, so each pair comes once without a set to deduplicate. Its cost
  grows with n, not with how many boxes share an x interval; large boxes meet many cells, so it
  suits mixed sizes (1x1 beside 500x500).
- `cell_candidates` files every box once, by its lower corner, in a grid whose cell is at least
  the largest box, and tests each box against its own cell and four neighbours: the cheapest
  for many boxes of similar sizes in a large world. Its counting sort by cell also gives the
  order in which the stepped model keeps its objects (near in space, near in memory).
- `choose` picks one of the three and its cell from the scene (object count, world size, box
  sizes); `candidates` dispatches to it; `find_pairs` and `sweep_pairs` give the answer as
  sorted (k, 2) pairs (`sweep_pairs` is the reference the tests hold the others to).

The candidate finders write into a caller's key buffer and return how many keys there are; when
that is more than the buffer holds, only the first keys were written and the caller grows the
buffer and asks again. Keys come in no particular order: the models sort the few they keep. They
allocate nothing (their scratch comes from `workspace`), so that kernels compiled without
numba's reference counting can call them.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.jit import njit, overload, prange
from collide2d.engine.sort import heap_argsort, median, sort_order
from collide2d.engine.threads import join_shares, shares_total

# A candidate pair (a, b) is one sortable int64 key, a << KEY_SHIFT | b (ids below 2**31).
KEY_SHIFT = 32
KEY_MASK = (1 << KEY_SHIFT) - 1

METHOD_SWEEP = 0
METHOD_GRID = 1
METHOD_CELLS = 2
METHODS = {"sweep": METHOD_SWEEP, "grid": METHOD_GRID, "cells": METHOD_CELLS}
# The sweep is chosen while a box shares its x interval with at most this many others on average
# (expected); past that the grid, whose cost does not grow with crowding along x, is cheaper.
# Tuned on the standard scene of `collide2d bench` (boxes 10x10 px, 5 % of a 4:3 world).
SWEEP_MAX_X_NEIGHBOURS = 6.0
# Boxes of similar sizes (the largest side at most this many times the median side) are filed
# once each in a grid whose cell is the largest side (`cell_candidates`); mixed sizes are filed in
# every cell they meet, on cells GRID_CELL_PER_SIDE x the median side (`grid_candidates`).
CELLS_MAX_SIDE_RATIO = 2.0
GRID_CELL_PER_SIDE = 1.5
# Bounds that keep the grid's memory and work linear in n: at most this many cells per object,
# and at most this many cell filings per object on average (large boxes meet many cells; the cell
# grows until the filings fit).
GRID_CELLS_PER_OBJECT = 4.0
GRID_FILINGS_PER_OBJECT = 16.0

# A grid's cell is this much larger than the largest box it is sized for, so that rounding at a
# cell crossing (~1e-12 px) can never hide a touching neighbour two cells away.
CELL_MARGIN = 1.01


def index(i):
    """i as the index of a hot loop: unsigned when compiled, as it is when interpreted.

    numba wraps a signed index that is negative (a[-1] is the last item), which costs three
    instructions per read that LLVM can rarely prove away (an index read from another array); an
    unsigned index has no such wrap. The loops that cast their indices (the cell pair tests and
    counting sort, the stepped model's move, pair tests, grown boxes and bands) run about a
    quarter fewer instructions. Every index cast is >= 0, so the results are the same; the
    interpreted lane keeps Python's int (a numpy unsigned scalar there costs more than it saves)."""
    return i


# Inlined where it is used (numba's IR), so that the cast has no compiled function of its own: as
# a function of its own, kernels loaded from a cache that other processes had written crashed on a
# call to address 0 in sweep workers and tests' subprocesses; inlined, none did (a whole suite on
# two workers from an empty cache).
@overload(index, inline="always")
def _index(i):
    def unsigned(i):
        return np.uint64(i)

    return unsigned


# --- candidate pairs ---------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _key(i, j):
    return (min(i, j) << KEY_SHIFT) | max(i, j)


def workspace(n: int, dtype=np.float64) -> tuple:
    """Scratch arrays for the candidate finders over n boxes with coordinates of `dtype`, so that
    they allocate nothing (the models' kernels run without numba's reference counting):
    (x starts, sorted x starts, cell keys, cell starts, boxes, cell spans, filed ids, filed boxes).
    """
    cells = int(4 * GRID_CELLS_PER_OBJECT * n) + 8
    filings = int(GRID_FILINGS_PER_OBJECT * n) + 16
    return (
        np.empty(n, dtype),
        np.empty(n, dtype),
        np.empty(n, np.int64),
        np.empty(cells, np.int64),
        np.empty((n, 4), dtype),
        np.empty((n, 4), np.int64),
        np.empty(filings, np.int64),
        np.empty((filings, 4), dtype),
    )


@njit(cache=True)
def sweep_candidates(lo, hi, movable, order, out, ws):
    """Candidate keys by sort-and-sweep on x; returns how many (see the module docstring).

    lo, hi (n, 2) px; movable (n,) bool; order (n,) int64 kept between calls (any permutation to
    start with); out (m,) int64 receives the keys; ws from `workspace`.
    """
    n = lo.shape[0]
    x_lo, sorted_lo = ws[0], ws[1]
    for i in range(n):
        x_lo[i] = lo[i, 0]
    sort_order(order, x_lo, sorted_lo)
    k = 0
    m = out.shape[0]
    for s in range(n):
        a = order[s]
        hax = hi[a, 0]
        lay = lo[a, 1]
        hay = hi[a, 1]
        ma = movable[a]
        for t in range(s + 1, n):
            if sorted_lo[t] >= hax:
                break
            b = order[t]
            # branch-free: write the key, keep it only when the y intervals meet too
            meet = (lo[b, 1] < hay) & (lay < hi[b, 1]) & (ma | movable[b]) & (lo[a, 0] < hi[b, 0])
            if k < m:
                out[k] = _key(a, b)
            k += meet
    return k


@njit(cache=True)
def _cell_of(x, x0, inv, last):
    """The grid column (or row) of coordinate x: floor((x - x0) / cell), at most `last`.

    Monotone in x, so the cell of max(x1, x2) is the max of their cells."""
    return min(int((x - x0) * inv), last)


@njit(cache=True)
def _bounds(lo, hi):
    """(x0, y0, x1, y1, largest side) of the boxes, px."""
    x0 = lo[0, 0]
    y0 = lo[0, 1]
    x1 = hi[0, 0]
    y1 = hi[0, 1]
    side = 0.0
    for i in range(lo.shape[0]):
        x0 = min(x0, lo[i, 0])
        y0 = min(y0, lo[i, 1])
        x1 = max(x1, hi[i, 0])
        y1 = max(y1, hi[i, 1])
        side = max(side, float(hi[i, 0] - lo[i, 0]), float(hi[i, 1] - lo[i, 1]))
    return float(x0), float(y0), float(x1), float(y1), side


@njit(cache=True)
def grid_candidates(lo, hi, movable, cell, out, ws):
    """Candidate keys from a uniform grid of square cells of side `cell` px; returns how many.

    lo, hi (n, 2) px; movable (n,) bool; out (m,) int64 receives the keys; ws from `workspace`.
    The grid starts at the boxes' lowest corner; its cell grows while the grid would have more
    than GRID_CELLS_PER_OBJECT cells per object or the boxes more filings than the workspace
    holds (any cell gives the same pairs, only the cost changes).
    """
    n = lo.shape[0]
    if n < 2:
        return 0
    span, start, f_id, f_box = ws[5], ws[3], ws[6], ws[7]
    x0, y0, x1, y1, _ = _bounds(lo, hi)
    span_x = max(x1 - x0, 1e-300)
    span_y = max(y1 - y0, 1e-300)
    cell = max(float(cell), math.sqrt(span_x * span_y / (GRID_CELLS_PER_OBJECT * n)))
    # each object's cell range [cx0, cx1] x [cy0, cy1]
    while True:
        nx = int(span_x / cell) + 1
        ny = int(span_y / cell) + 1
        if nx * ny + 1 > start.shape[0]:
            cell *= 2.0  # a long thin spread of boxes
            continue
        inv = 1.0 / cell
        total = 0
        for i in range(n):
            span[i, 0] = _cell_of(lo[i, 0], x0, inv, nx - 1)
            span[i, 1] = _cell_of(hi[i, 0], x0, inv, nx - 1)
            span[i, 2] = _cell_of(lo[i, 1], y0, inv, ny - 1)
            span[i, 3] = _cell_of(hi[i, 1], y0, inv, ny - 1)
            total += (span[i, 1] - span[i, 0] + 1) * (span[i, 3] - span[i, 2] + 1)
        if total <= f_id.shape[0]:
            break
        cell *= 2.0  # large boxes: fewer, larger cells
    # how many filings each cell gets, then the filings cell by cell in id order, each with a
    # copy of its box for local reads; cell c holds [start[c], start[c + 1]) at the end
    for c in range(nx * ny + 1):
        start[c] = 0
    for i in range(n):
        for cy in range(span[i, 2], span[i, 3] + 1):
            for cx in range(span[i, 0], span[i, 1] + 1):
                start[cy * nx + cx + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    for i in range(n - 1, -1, -1):
        for cy in range(span[i, 3], span[i, 2] - 1, -1):
            for cx in range(span[i, 1], span[i, 0] - 1, -1):
                c = cy * nx + cx + 1
                f = start[c] - 1
                start[c] = f
                f_id[f] = i
                f_box[f, 0] = lo[i, 0]
                f_box[f, 1] = lo[i, 1]
                f_box[f, 2] = hi[i, 0]
                f_box[f, 3] = hi[i, 1]
    # start[c + 1] is now where cell c begins: move each down by one, and close the last cell
    for c in range(nx * ny):
        start[c] = start[c + 1]
    start[nx * ny] = total
    k = 0
    m = out.shape[0]
    for c in range(nx * ny):
        cx = c % nx
        cy = c // nx
        for p in range(start[c], start[c + 1]):
            a = f_id[p]
            for q in range(p + 1, start[c + 1]):
                b = f_id[q]
                if not (
                    (f_box[q, 0] < f_box[p, 2])
                    & (f_box[p, 0] < f_box[q, 2])
                    & (f_box[q, 1] < f_box[p, 3])
                    & (f_box[p, 1] < f_box[q, 3])
                ):
                    continue
                # report only in the cell of the intersection's lower corner
                if max(span[a, 0], span[b, 0]) != cx or max(span[a, 2], span[b, 2]) != cy:
                    continue
                if movable[a] | movable[b]:
                    if k < m:
                        out[k] = (a << KEY_SHIFT) | b
                    k += 1
    return k


@njit(cache=True)
def cell_candidates(lo, hi, movable, cell, order, out, ws):
    """Candidate keys from a grid whose cell is at least every box's side; returns how many.

    Each box is filed once, by the cell of its lower corner; two overlapping boxes then sit in the
    same or neighbouring cells, and each box is tested against the later boxes of its own cell and
    the boxes of four of its eight neighbours, (+1, 0) and the three below (the other four test
    it), so each pair comes once. lo, hi (n, 2) px; movable (n,) bool; cell px (grown to
    CELL_MARGIN x the largest side when smaller, and while the grid would have more than
    GRID_CELLS_PER_OBJECT cells per object or more than the workspace holds); out (m,) int64
    receives the keys; order (n,) int64 receives the objects sorted by cell (row by row), in id
    order within a cell; ws from `workspace`.
    """
    n = lo.shape[0]
    for i in range(n):
        order[i] = i
    if n < 2:
        return 0
    grid = _cell_grid(lo, hi, cell, order, ws)  # the counting sort by cell
    return _cell_pairs(0, n, order, ws[3], ws[4], movable, grid, out, 0, out.shape[0])


@njit(cache=True)
def _cell_grid(lo, hi, cell, order, ws):
    """The counting sort of `cell_candidates`: its grid (nx, ny, x0, y0, 1 / cell: a box's column
    and row are `_cell_of` its lower corner); order, ws[2] (each box's cell), ws[3] (cell starts)
    and ws[4] (boxes by slot) filled."""
    n = lo.shape[0]
    key, start, box = ws[2], ws[3], ws[4]
    x0, y0, x1, y1, side = _bounds(lo, hi)
    span_x = x1 - x0
    span_y = y1 - y0
    cell = max(float(cell), side * CELL_MARGIN, 1e-300)
    cell = max(cell, math.sqrt(span_x * span_y / (GRID_CELLS_PER_OBJECT * n)))
    while (int(span_x / cell) + 1) * (int(span_y / cell) + 1) + 2 > start.shape[0]:
        cell *= 2.0  # a long thin spread of boxes
    nx = int(span_x / cell) + 1
    ny = int(span_y / cell) + 1
    inv = 1.0 / cell
    # counting sort by cell: cell c holds slots [start[c + 1], start[c + 2]) once the scatter
    # below has moved each cell's end back to its start
    for c in range(nx * ny + 2):
        start[c] = 0
    for i in range(n):
        cx = _cell_of(lo[i, 0], x0, inv, nx - 1)
        cy = _cell_of(lo[i, 1], y0, inv, ny - 1)
        c = cy * nx + cx
        key[i] = c
        start[index(c + 1)] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    start[nx * ny + 1] = n
    for r in range(n):  # unsigned indices (`index`), the objects from last to first
        i = index(n - 1 - r)
        c = index(key[i] + 1)
        slot = index(start[c] - 1)
        start[c] = slot
        order[slot] = i
        box[slot, 0] = lo[i, 0]
        box[slot, 1] = lo[i, 1]
        box[slot, 2] = hi[i, 0]
        box[slot, 3] = hi[i, 1]
    return nx, ny, x0, y0, inv


@njit(cache=True)
def _cell_pairs(s0, s1, order, start, box, movable, grid, out, base, room):
    """The pairs of `cell_candidates` for the boxes in slots s0 ... s1-1 (grid from `_cell_grid`:
    each box's column and row computed again from its corner, as the sort did, which costs less
    than reading them from memory), written to out[base:base + room] while they fit; returns how
    many. Its indices go through `index` (unsigned when compiled)."""
    nx, ny, x0, y0, inv = grid
    k = 0
    m = room
    for s in range(index(s0), index(s1)):
        a = order[s]
        ia = index(a)
        cx = _cell_of(box[s, 0], x0, inv, nx - 1)
        cy = _cell_of(box[s, 1], y0, inv, ny - 1)
        c = cy * nx + cx
        ma = movable[ia]
        lax, lay, hax, hay = box[s, 0], box[s, 1], box[s, 2], box[s, 3]
        # two runs of slots: the later boxes of its own cell and those of the cell to its right
        # (+1, 0); the cells (-1, +1), (0, +1), (+1, +1) of the next row, side by side in a row
        for run in range(2):
            if run == 0:
                first = s + index(1)
                last = index(start[index(c + 2 + (1 if cx + 1 < nx else 0))])
            else:
                if cy + 1 >= ny:
                    break
                g = c + nx
                first = index(start[index(g + (0 if cx > 0 else 1))])
                last = index(start[index(g + (3 if cx + 1 < nx else 2))])
            for t in range(first, last):
                b = order[t]
                # branch-free: write the key, keep it only when the boxes overlap
                meet = (
                    (box[t, 0] < hax)
                    & (lax < box[t, 2])
                    & (box[t, 1] < hay)
                    & (lay < box[t, 3])
                    & (ma | movable[index(b)])
                )
                if k < m:
                    out[index(base + k)] = _key(a, b)
                k += meet
    return k


@njit(cache=True, parallel=True)
def _cell_pairs_split(order, start, box, movable, grid, out, n, found):
    """`_cell_pairs` over all n slots cut into len(found) contiguous runs, one per thread, each
    writing into its own share of `out`; the shares are then moved together in run order, so the
    keys come in the order one thread gives. When a share is too small the count returned is
    more than `out` holds (the caller grows it and asks again). found (chunks,) int64: scratch."""
    chunks = found.shape[0]
    room = out.shape[0]
    share = room // chunks
    for c in prange(chunks):
        found[c] = _cell_pairs(
            c * n // chunks, (c + 1) * n // chunks, order, start, box, movable, grid, out,
            c * share, share,
        )
    total = shares_total(found, share, room)
    if total > room:
        return total
    return join_shares(found, share, out)


@njit(cache=True)
def cell_candidates_split_into(lo, hi, movable, cell, order, out, ws, found):
    """`cell_candidates` with its pair tests split among len(found) threads, `found` (chunks,)
    int64 its scratch: the same keys in the same order (or, when `out` is too small for a share,
    a count past its size). Allocates nothing (for kernels compiled without reference counting)."""
    n = lo.shape[0]
    for i in range(n):
        order[i] = i
    if n < 2:
        return 0
    grid = _cell_grid(lo, hi, cell, order, ws)
    return _cell_pairs_split(order, ws[3], ws[4], movable, grid, out, n, found)


def choose(
    width: float, height: float, size: np.ndarray, method: str | None = None
) -> tuple[int, float]:
    """(method, cell px) for boxes of these sizes (n, 2) px in a width x height world, px.

    The sweep while a box shares its x interval with at most SWEEP_MAX_X_NEIGHBOURS others on
    average. Else a grid: boxes of similar sizes on cells of the largest side (METHOD_CELLS),
    mixed sizes on cells GRID_CELL_PER_SIDE x the median side, doubled while the boxes would make
    more than GRID_FILINGS_PER_OBJECT filings per object (METHOD_GRID). `method` ("sweep",
    "grid", "cells", a key of METHODS) forces one; any gives the same pairs.
    """
    size = np.asarray(size, np.float64).reshape(-1, 2)
    n = size.shape[0]
    if method is not None and method not in METHODS:
        raise ValueError(f"unknown broad phase {method!r}; expected one of {', '.join(METHODS)}")
    if n < 2:
        return METHODS.get(method, METHOD_SWEEP), 1.0
    sides = size.max(axis=1)
    median_side, largest = median(sides), float(sides.max())
    if method is None:
        neighbours = (n - 1) * 2.0 * float(size[:, 0].mean()) / max(float(width), 1.0)
        if not neighbours > SWEEP_MAX_X_NEIGHBOURS:
            method = "sweep"
        elif largest <= CELLS_MAX_SIDE_RATIO * median_side:
            method = "cells"
        else:
            method = "grid"
    if method == "sweep":
        return METHOD_SWEEP, 1.0
    if method == "cells":
        return METHOD_CELLS, largest * CELL_MARGIN
    cell = max(GRID_CELL_PER_SIDE * median_side, 1e-6)
    while np.sum((np.floor(size / cell) + 2).prod(axis=1)) > GRID_FILINGS_PER_OBJECT * n:
        cell *= 2.0
    return METHOD_GRID, cell


@njit(cache=True)
def candidates(method, lo, hi, movable, cell, order, out, ws):
    """Candidate keys by `method` (`order` is the order kept by the sweep and the cells, `cell`
    the grid's cell, px); returns how many, as each finder does."""
    if method == METHOD_GRID:
        return grid_candidates(lo, hi, movable, cell, out, ws)
    if method == METHOD_CELLS:
        return cell_candidates(lo, hi, movable, cell, order, out, ws)
    return sweep_candidates(lo, hi, movable, order, out, ws)


# A kernel that takes its finder's *marker*, a zero-length array whose dtype names the method,
# calls `find(marker, ...)`: numba compiles that to the one finder the dtype names (the dtype is
# part of the kernel's signature, so each method is its own cached specialisation), where
# `candidates(method, ...)` compiles all three into every kernel that calls it.
_MARKER_DTYPES = (np.int8, np.int16, np.int32)  # METHOD_SWEEP, METHOD_GRID, METHOD_CELLS


def marker(method: int) -> np.ndarray:
    """The marker of `method` (METHOD_SWEEP, METHOD_GRID or METHOD_CELLS) for `find`."""
    return np.zeros(0, _MARKER_DTYPES[method])


def find(marker, lo, hi, movable, cell, order, out, ws):
    """`candidates` by the method `marker` names (this body runs only without the JIT)."""
    method = [np.dtype(d) for d in _MARKER_DTYPES].index(marker.dtype)
    return candidates(method, lo, hi, movable, cell, order, out, ws)


@overload(find)
def _find(marker, lo, hi, movable, cell, order, out, ws):
    bits = marker.dtype.bitwidth
    if bits == 8:

        def sweep(marker, lo, hi, movable, cell, order, out, ws):
            return sweep_candidates(lo, hi, movable, order, out, ws)

        return sweep
    if bits == 16:

        def grid(marker, lo, hi, movable, cell, order, out, ws):
            return grid_candidates(lo, hi, movable, cell, out, ws)

        return grid

    def cells(marker, lo, hi, movable, cell, order, out, ws):
        return cell_candidates(lo, hi, movable, cell, order, out, ws)

    return cells


def find_split(finder, lo, hi, movable, cell, order, out, ws, found):
    """`find`, the cells method's pair tests split among len(found) threads when more than one
    (`cell_candidates_split_into`: the same keys in the same order; found (chunks,) int64 is its
    scratch). A kernel compiles only the finder its marker names (this body runs only without the
    JIT)."""
    if found.shape[0] > 1 and finder.dtype == marker(METHOD_CELLS).dtype:
        return cell_candidates_split_into(lo, hi, movable, cell, order, out, ws, found)
    return find(finder, lo, hi, movable, cell, order, out, ws)


@overload(find_split)
def _find_split(finder, lo, hi, movable, cell, order, out, ws, found):
    if finder.dtype.bitwidth == 32:  # the cells method's marker (`marker`)

        def cells(finder, lo, hi, movable, cell, order, out, ws, found):
            if found.shape[0] > 1:
                return cell_candidates_split_into(lo, hi, movable, cell, order, out, ws, found)
            return find(finder, lo, hi, movable, cell, order, out, ws)

        return cells

    def one(finder, lo, hi, movable, cell, order, out, ws, found):
        return find(finder, lo, hi, movable, cell, order, out, ws)

    return one


def keys_to_pairs(keys: np.ndarray) -> np.ndarray:
    """(k, 2) int64 pairs (a, b) in ascending order from candidate keys."""
    keys = np.sort(np.asarray(keys, np.int64))
    return np.stack([keys >> KEY_SHIFT, keys & KEY_MASK], axis=1)


def find_pairs(method: int, lo: np.ndarray, hi: np.ndarray, movable: np.ndarray, cell: float = 1.0):
    """Pairs of boxes that overlap with positive area, at least one movable, found by `method`
    (METHOD_SWEEP, METHOD_GRID on cells of `cell` px, METHOD_CELLS): (k, 2) int64 in ascending
    (a, b), a < b. lo, hi (n, 2) px; movable (n,) bool."""
    lo = np.ascontiguousarray(lo)
    hi = np.ascontiguousarray(hi, dtype=lo.dtype)
    movable = np.ascontiguousarray(movable, bool)
    n = lo.shape[0]
    ws = workspace(n, lo.dtype)
    order = np.arange(n, dtype=np.int64)
    out = np.empty(max(16, n), np.int64)
    finder = marker(method)
    k = _find_keys(finder, lo, hi, movable, float(cell), order, out, ws)
    if k > out.shape[0]:
        out = np.empty(k, np.int64)
        k = _find_keys(finder, lo, hi, movable, float(cell), order, out, ws)
    return keys_to_pairs(out[:k])


@njit(cache=True)
def _find_keys(finder, lo, hi, movable, cell, order, out, ws):
    """`find` for callers outside the kernels: compiles only the finder `finder` names."""
    return find(finder, lo, hi, movable, cell, order, out, ws)


# --- the reference answer (tests) ----------------------------------------------------------------


@njit(cache=True)
def sweep_pairs(lo, hi, static):
    """Pairs of boxes that overlap with positive area, (k, 2) int64 in ascending (a, b), a < b.

    lo, hi (n, 2) float64: each box is [lo, hi) on both axes, px. static (n,) bool: pairs of two
    static objects are left out.
    """
    n = lo.shape[0]
    order = heap_argsort(lo[:, 0].copy())
    keys = np.empty(max(16, 2 * n), np.int64)
    k = 0
    for ii in range(n):
        i = order[ii]
        for jj in range(ii + 1, n):
            j = order[jj]
            if lo[j, 0] >= hi[i, 0]:
                break
            if static[i] and static[j]:
                continue
            if lo[j, 0] < hi[i, 0] and lo[i, 0] < hi[j, 0]:
                if lo[j, 1] < hi[i, 1] and lo[i, 1] < hi[j, 1]:
                    if k == keys.shape[0]:
                        grown = np.empty(2 * k, np.int64)
                        grown[:k] = keys
                        keys = grown
                    a = min(i, j)
                    b = max(i, j)
                    keys[k] = a * n + b
                    k += 1
    keys = keys[:k]
    sorted_keys = heap_argsort(keys)
    out = np.empty((k, 2), np.int64)
    for m in range(k):
        out[m, 0] = keys[sorted_keys[m]] // n
        out[m, 1] = keys[sorted_keys[m]] % n
    return out
