"""The exact model's uniform grid: its cell size, and per-cell doubly linked lists of the moving
objects.

Square cells of side `cell` px cover the world (`grid_cell`, `grid_dims`). With the cell at least
the largest moving box (plus a margin), two moving objects that touch are in the same or adjacent
cells, so an object predicts contacts only against the 3×3 cells around its own. Moving objects are
filed by their box centre in cells of side `cell` px (gnx × gny cells); `cells` (gnx·gny, 2) int64
holds each cell's first object (-1: none) and count, N's NEXT and PREV columns the links, N's CELL
column each object's cell. Static objects never move: they are filed once by `static_cells` (every
cell their closed box meets), so a mover finds them the same way. `room_around` and `room_needed`
bound the heap entries one prediction or one event may push.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.broadphase import CELL_MARGIN
from collide2d.engine.jit import njit
from collide2d.engine.models.exact.heap import RANK_CROSS, RANK_PAIR
from collide2d.engine.models.exact.state import (
    CELL,
    DIR_DOWN,
    DIR_LEFT,
    DIR_RIGHT,
    DIR_UP,
    NEXT,
    PREV,
    S_HEAP_N,
    SH,
    STATIC,
    SW,
    X,
    Y,
    hot,
)

# Aim for about this many moving objects per cell when they are sparse: larger cells mean fewer
# cell crossings but more neighbours to test. Tuned on a gas of 10,000 boxes (`collide2d bench
# --part exact`): with crossings filed in constant time (horizonqueue.py), 0.25 (23 px cells)
# ran about 5 % more events/s than 0.6 (35 px); 0.15 and 0.1 (18, 14 px) fewer.
TARGET_PER_CELL = 0.25
# The grid never has more cells than this per moving object (and at least one cell).
MAX_CELLS_PER_OBJECT = 4


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


# Grid cells (gnx·gny, 2) int64: the first moving object filed there (-1: none) and how many.
C_HEAD, C_COUNT = range(2)

# --- grid cells: doubly linked lists of the moving objects in each cell -----------------------


@hot
def cell_insert(N, cells, i, c):
    N[i, CELL] = c
    N[i, PREV] = -1
    N[i, NEXT] = cells[c, C_HEAD]
    if cells[c, C_HEAD] >= 0:
        N[cells[c, C_HEAD], PREV] = i
    cells[c, C_HEAD] = i
    cells[c, C_COUNT] += 1


@hot
def cell_remove(N, cells, i):
    if N[i, PREV] >= 0:
        N[N[i, PREV], NEXT] = N[i, NEXT]
    else:
        cells[N[i, CELL], C_HEAD] = N[i, NEXT]
    if N[i, NEXT] >= 0:
        N[N[i, NEXT], PREV] = N[i, PREV]
    cells[N[i, CELL], C_COUNT] -= 1


@njit(cache=True)
def build_grid(F, N, cell, gnx, gny):
    """Grid (cells, static_start, static_items); moving objects filed by their box centre."""
    cells = np.zeros((gnx * gny, 2), np.int64)
    cells[:, C_HEAD] = -1
    static = N[:, STATIC] != 0
    s_start, s_items = static_cells(
        F[:, X : Y + 1].copy(), F[:, SW : SH + 1].copy(), static, cell, gnx, gny
    )
    for i in range(F.shape[0] - 1, -1, -1):  # lists then run in id order
        N[i, CELL] = -1
        if not static[i]:
            cx = min(max(int((F[i, X] + 0.5 * F[i, SW]) // cell), 0), gnx - 1)
            cy = min(max(int((F[i, Y] + 0.5 * F[i, SH]) // cell), 0), gny - 1)
            cell_insert(N, cells, i, cy * gnx + cx)
    return cells, s_start, s_items


@hot
def room_around(gx, gy, N, cells, s_start, world):
    """Heap entries a prediction in cell (gx, gy) may push: a horizon, and one contact per object
    filed in the 3×3 cells around it (moving and static)."""
    gnx, gny = world.gnx, world.gny
    room = 1
    for cy in range(max(gy - 1, 0), min(gy + 1, gny - 1) + 1):
        for cx in range(max(gx - 1, 0), min(gx + 1, gnx - 1) + 1):
            c = cy * gnx + cx
            room += cells[c, C_COUNT] + s_start[c + 1] - s_start[c]
    return room


@hot
def room_needed(rank, a, b, S):
    """Heap entries the event (rank, a, b) may push at most; when the heap has room for the worst
    case of any event (two predictions against everything), it is not counted."""
    N, cells, s_start, world = S.N, S.cells, S.s_start, S.world
    if S.HT.shape[0] - S.st[S_HEAP_N] >= 2 * (N.shape[0] + 1):
        return 0
    gnx = world.gnx
    gx = N[a, CELL] % gnx
    gy = N[a, CELL] // gnx
    if rank == RANK_CROSS:
        gx += 1 if b == DIR_RIGHT else -1 if b == DIR_LEFT else 0
        gy += 1 if b == DIR_DOWN else -1 if b == DIR_UP else 0
        return room_around(gx, gy, N, cells, s_start, world)
    room = room_around(gx, gy, N, cells, s_start, world)
    if rank == RANK_PAIR:
        room += room_around(N[b, CELL] % gnx, N[b, CELL] // gnx, N, cells, s_start, world)
    return room
