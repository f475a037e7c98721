"""Broad phase: which pairs could touch, so that exact tests run only on near neighbours.

Two tools, nothing else:

- `sweep_pairs` (the stepped model): sort-and-sweep on x over the objects' boxes. Input: box
  corners `lo`, `hi` (n, 2) px and which objects are static. Output: the (k, 2) int64 pairs
  (a, b), a < b, whose boxes overlap with positive area, in ascending (a, b) order, static–static
  pairs left out. The same answer as testing every pair, at O(n log n + k).
- a uniform grid (the exact model): square cells of side `cell` px over the world, each moving
  object filed by the cell of its box's centre. With the cell at least the largest moving box
  (plus a margin), two moving objects that touch are in the same or adjacent cells, so an object
  predicts contacts only against the 3×3 cells around its own. Static objects never move; each is
  filed in every cell its closed box meets (`static_cells`), so a mover finds it the same way.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# The grid's cell is this much larger than the largest moving box, so that rounding at a cell
# crossing (~1e-12 px) can never hide a touching neighbour two cells away.
CELL_MARGIN = 1.01
# Aim for about this many moving objects per cell when they are sparse: larger cells mean fewer
# cell crossings but more neighbours to test. Tuned on benchmarks/bench_exact.py (10,000 boxes).
TARGET_PER_CELL = 0.6
# The grid never has more cells than this per moving object (and at least one cell).
MAX_CELLS_PER_OBJECT = 4


@njit(cache=True)
def sweep_pairs(lo, hi, static):
    """Pairs of boxes that overlap with positive area, (k, 2) int64 in ascending (a, b), a < b.

    lo, hi (n, 2) float64: each box is [lo, hi) on both axes, px. static (n,) bool: pairs of two
    static objects are left out.
    """
    n = lo.shape[0]
    order = np.argsort(lo[:, 0], kind="mergesort")
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
    keys = np.sort(keys[:k])
    out = np.empty((k, 2), np.int64)
    for m in range(k):
        out[m, 0] = keys[m] // n
        out[m, 1] = keys[m] % n
    return out


def grid_cell(width: float, height: float, size: np.ndarray, static: np.ndarray) -> float:
    """Side of the exact model's grid cells, px.

    At least CELL_MARGIN × the largest side of a moving box; larger when moving objects are sparse
    (about TARGET_PER_CELL per cell); never so small that the grid exceeds MAX_CELLS_PER_OBJECT
    cells per moving object.
    """
    moving = ~np.asarray(static, bool)
    count = int(moving.sum())
    extent = float(size[moving].max()) if count else 1.0
    cell = max(extent * CELL_MARGIN, 1e-9)
    if count:
        cell = max(cell, math.sqrt(width * height * TARGET_PER_CELL / count))
        cell = max(cell, math.sqrt(width * height / (MAX_CELLS_PER_OBJECT * count)))
    return cell


def grid_dims(width: float, height: float, cell: float) -> tuple[int, int]:
    """(columns, rows) of cells of side `cell` covering [0, width) × [0, height)."""
    return max(1, math.ceil(width / cell)), max(1, math.ceil(height / cell))


@njit(cache=True)
def static_cells(pos, size, static, cell, nx, ny):
    """Cells each static object is filed in: every cell its closed box meets.

    pos, size (n, 2) px; static (n,) bool; cell px; nx × ny cells. Returns (start, items): the
    static objects of cell c (c = cy·nx + cx) are items[start[c]:start[c+1]], in id order.
    """
    n = pos.shape[0]
    span = np.empty((n, 4), np.int64)
    counts = np.zeros(nx * ny, np.int64)
    for i in range(n):
        span[i, 0] = min(max(int(pos[i, 0] // cell), 0), nx - 1)
        span[i, 1] = min(max(int((pos[i, 0] + size[i, 0]) // cell), 0), nx - 1)
        span[i, 2] = min(max(int(pos[i, 1] // cell), 0), ny - 1)
        span[i, 3] = min(max(int((pos[i, 1] + size[i, 1]) // cell), 0), ny - 1)
        if static[i]:
            for cy in range(span[i, 2], span[i, 3] + 1):
                for cx in range(span[i, 0], span[i, 1] + 1):
                    counts[cy * nx + cx] += 1
    start = np.zeros(nx * ny + 1, np.int64)
    for c in range(nx * ny):
        start[c + 1] = start[c] + counts[c]
    items = np.empty(start[nx * ny], np.int64)
    fill = start[:-1].copy()
    for i in range(n):
        if static[i]:
            for cy in range(span[i, 2], span[i, 3] + 1):
                for cx in range(span[i, 0], span[i, 1] + 1):
                    c = cy * nx + cx
                    items[fill[c]] = i
                    fill[c] += 1
    return start, items
