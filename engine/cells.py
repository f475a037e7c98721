"""The exact model's uniform grid: per-cell doubly linked lists of the moving objects.

Moving objects are filed by their box centre in cells of side `cell` px (gnx × gny cells);
`cells` (gnx·gny, 2) int64 holds each cell's first object (-1: none) and count, N's NEXT and PREV
columns the links, N's CELL column each object's cell. Static objects never move: they are filed
once by broadphase.static_cells (every cell their box covers). `room_around` and `room_needed`
bound the heap entries one prediction or one event may push.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.broadphase import static_cells
from collide2d.engine.eventqueue import RANK_CROSS, RANK_PAIR
from collide2d.engine.exactstate import (
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
from collide2d.engine.jit import njit

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
    gnx, gny = world[4], world[5]
    room = 1
    for cy in range(max(gy - 1, 0), min(gy + 1, gny - 1) + 1):
        for cx in range(max(gx - 1, 0), min(gx + 1, gnx - 1) + 1):
            c = cy * gnx + cx
            room += cells[c, C_COUNT] + s_start[c + 1] - s_start[c]
    return room


@hot
def room_needed(rank, a, b, HT, st, N, cells, s_start, world):
    """Heap entries the event (rank, a, b) may push at most; when the heap has room for the worst
    case of any event (two predictions against everything), it is not counted."""
    if HT.shape[0] - st[S_HEAP_N] >= 2 * (N.shape[0] + 1):
        return 0
    gnx = world[4]
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
