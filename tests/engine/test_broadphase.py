"""Broad phase: sort-and-sweep finds exactly the overlapping pairs; the grid files statics right."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.broadphase import (
    CELL_MARGIN,
    MAX_CELLS_PER_OBJECT,
    grid_cell,
    grid_dims,
    static_cells,
    sweep_pairs,
)


def brute_pairs(lo, hi, static):
    n = len(lo)
    out = []
    for a in range(n):
        for b in range(a + 1, n):
            if static[a] and static[b]:
                continue
            if (lo[a] < hi[b]).all() and (lo[b] < hi[a]).all():
                out.append((a, b))
    return out


scenes = st.integers(0, 40).flatmap(
    lambda n: st.tuples(
        st.lists(st.tuples(st.integers(0, 60), st.integers(0, 60)), min_size=n, max_size=n),
        st.lists(st.tuples(st.integers(1, 15), st.integers(1, 15)), min_size=n, max_size=n),
        st.lists(st.booleans(), min_size=n, max_size=n),
    )
)


@settings(max_examples=30, deadline=None)
@given(scenes)
def test_sweep_finds_exactly_the_overlapping_pairs_in_order(scene):
    # Integer corners make touching boxes common: they must not count as overlapping.
    pos, size, static = scene
    lo = np.array(pos, float).reshape(-1, 2)
    hi = lo + np.array(size, float).reshape(-1, 2)
    static = np.array(static, bool)
    got = [tuple(p) for p in sweep_pairs(lo, hi, static).tolist()]
    assert got == brute_pairs(lo, hi, static)  # same set, ascending (a, b)


def test_sweep_handles_many_pairs_and_identical_boxes():
    lo = np.zeros((30, 2))
    hi = np.ones((30, 2))
    pairs = sweep_pairs(lo, hi, np.zeros(30, bool))
    assert len(pairs) == 30 * 29 // 2
    assert pairs[0].tolist() == [0, 1] and pairs[-1].tolist() == [28, 29]


def test_grid_cell_is_larger_than_every_moving_box():
    size = np.array([[10.0, 4.0], [3.0, 25.0], [400.0, 400.0]])
    static = np.array([False, False, True])  # the large static box does not count
    cell = grid_cell(320, 240, size, static)
    assert cell >= 25.0 * CELL_MARGIN
    nx, ny = grid_dims(320, 240, cell)
    assert nx * cell >= 320 and ny * cell >= 240
    assert (nx - 1) * cell < 320 and (ny - 1) * cell < 240


def test_grid_stays_small_for_tiny_objects():
    size = np.full((50, 2), 1e-3)
    cell = grid_cell(10_000, 10_000, size, np.zeros(50, bool))
    nx, ny = grid_dims(10_000, 10_000, cell)
    assert nx * ny <= MAX_CELLS_PER_OBJECT * 50 + 2 * (nx + ny)


@settings(max_examples=30, deadline=None)
@given(scenes, st.floats(4.0, 30.0))
def test_statics_are_filed_in_every_cell_their_box_meets(scene, cell):
    pos, size, static = scene
    pos = np.array(pos, float).reshape(-1, 2)
    size = np.array(size, float).reshape(-1, 2)
    static = np.array(static, bool)
    nx, ny = grid_dims(80, 80, cell)  # every box lies within [0, 75]: no clipping at the edge
    start, items = static_cells(pos, size, static, cell, nx, ny)
    lo, hi = pos, pos + size
    for cy in range(ny):
        for cx in range(nx):
            c = cy * nx + cx
            # The half-open cell [c·cell, (c+1)·cell) on each axis meets the closed box.
            expected = [
                i
                for i in range(len(pos))
                if static[i]
                and cx * cell <= hi[i, 0]
                and lo[i, 0] < (cx + 1) * cell
                and cy * cell <= hi[i, 1]
                and lo[i, 1] < (cy + 1) * cell
            ]
            assert items[start[c] : start[c + 1]].tolist() == expected


def test_a_static_wall_across_the_world_is_in_every_cell_it_crosses():
    pos = np.array([[0.0, 50.0]])
    size = np.array([[320.0, 4.0]])
    cell = 20.0
    nx, ny = grid_dims(320, 240, cell)
    start, items = static_cells(pos, size, np.array([True]), cell, nx, ny)
    rows = {c // nx for c in range(nx * ny) if start[c + 1] > start[c]}
    cols = {c % nx for c in range(nx * ny) if start[c + 1] > start[c]}
    assert rows == {math.floor(50 / cell)}
    assert cols == set(range(nx))
    assert items.tolist() == [0] * len(items)
