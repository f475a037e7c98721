"""Broad phase: every candidate finder gives exactly the all-pairs answer; the scene picks one;
the exact model's grid files statics right."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.broadphase import (
    CELL_MARGIN,
    GRID_FILINGS_PER_OBJECT,
    METHOD_CELLS,
    METHOD_GRID,
    METHOD_SWEEP,
    METHODS,
    candidates,
    choose,
    find_pairs,
    sweep_pairs,
    workspace,
)
from collide2d.engine.models.exact.cells import (
    MAX_CELLS_PER_OBJECT,
    grid_cell,
    grid_dims,
    static_cells,
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


# --- the candidate finders: sweep, grid and cells give exactly the all-pairs answer -------------

MIXED_SIDES = [1, 1, 2, 3, 10, 10, 40, 500]
mixed_scenes = st.integers(0, 45).flatmap(
    lambda n: st.tuples(
        st.lists(st.tuples(st.integers(-40, 700), st.integers(-40, 500)), min_size=n, max_size=n),
        st.lists(
            st.tuples(st.sampled_from(MIXED_SIDES), st.sampled_from(MIXED_SIDES)),
            min_size=n,
            max_size=n,
        ),
        st.lists(st.booleans(), min_size=n, max_size=n),
        st.booleans(),  # integer corners, or shifted by a fraction of a pixel
        st.sampled_from([0.5, 3.0, 11.0, 64.0, 1000.0]),  # a grid cell to start from
    )
)


def brute_movable_pairs(lo, hi, movable):
    return [
        (a, b)
        for a in range(len(lo))
        for b in range(a + 1, len(lo))
        if (movable[a] or movable[b]) and (lo[a] < hi[b]).all() and (lo[b] < hi[a]).all()
    ]


@settings(max_examples=40, deadline=None)
@given(mixed_scenes)
def test_every_method_finds_exactly_the_all_pairs_answer_with_mixed_sizes(scene):
    # 1x1 boxes beside 500x500 ones, touching corners, negative coordinates: sweep, the grid
    # (filed in every cell met) and the cells (filed once, lower corner) all give the pairs of
    # the all-pairs check, on float and on integer coordinates.
    pos, size, movable, whole, cell = scene
    lo = np.array(pos, float).reshape(-1, 2)
    if not whole:
        lo += 0.25
    hi = lo + np.array(size, float).reshape(-1, 2)
    movable = np.array(movable, bool)
    expected = brute_movable_pairs(lo, hi, movable)
    for method in METHODS.values():
        got = [tuple(p) for p in find_pairs(method, lo, hi, movable, cell).tolist()]
        assert got == expected, method
        if whole:
            got = find_pairs(method, lo.astype(np.int64), hi.astype(np.int64), movable, cell)
            assert [tuple(p) for p in got.tolist()] == expected, method


def test_the_grid_finds_the_pairs_of_a_large_random_scene():
    rng = np.random.default_rng(2)
    n = 3000
    lo = rng.uniform(0, 2000, (n, 2))
    hi = lo + rng.choice([1.0, 6.0, 12.0, 300.0], (n, 2), p=[0.3, 0.4, 0.29, 0.01])
    movable = rng.random(n) < 0.8
    reference = find_pairs(METHOD_SWEEP, lo, hi, movable)
    assert len(reference) > 200
    for method in (METHOD_GRID, METHOD_CELLS):
        assert np.array_equal(find_pairs(method, lo, hi, movable, 9.0), reference)
    assert np.array_equal(sweep_pairs(lo, hi, ~movable), reference)


def test_boxes_on_one_line_and_identical_boxes_keep_the_grid_small():
    # all boxes on a horizontal line: a grid of span_x by ~0 must not explode; identical boxes
    # all overlap each other
    n = 200
    lo = np.stack([np.arange(n) * 7.0, np.zeros(n)], axis=1)
    hi = lo + 8.0
    movable = np.ones(n, bool)
    expected = [(a, a + 1) for a in range(n - 1)]
    for method in METHODS.values():
        assert [tuple(p) for p in find_pairs(method, lo, hi, movable, 1e-3).tolist()] == expected
    same = np.zeros((30, 2))
    for method in METHODS.values():
        assert len(find_pairs(method, same, same + 1.0, np.ones(30, bool))) == 30 * 29 // 2


def test_a_full_key_buffer_reports_how_many_it_needed():
    n = 40
    lo = np.zeros((n, 2))
    hi = np.ones((n, 2))
    out = np.empty(10, np.int64)
    ws = workspace(n)
    for method in METHODS.values():
        k = candidates(method, lo, hi, np.ones(n, bool), 1.0, np.arange(n), out, ws)
        assert k == n * (n - 1) // 2


def test_the_scene_chooses_the_method():
    # few boxes in a small world: the sweep; many similar boxes in a wide world: cells filed
    # once; mixed sizes: the grid filing each box in every cell it meets
    small = np.full((50, 2), 10.0)
    assert choose(320, 240, small)[0] == METHOD_SWEEP
    many = np.full((100_000, 2), 10.0)
    method, cell = choose(16330, 12248, many)
    assert method == METHOD_CELLS and cell >= 10.0
    mixed = np.concatenate([np.full((5000, 2), 4.0), np.full((50, 2), 400.0)])
    method, cell = choose(4000, 3000, mixed)
    assert method == METHOD_GRID
    filings = (np.floor(mixed / cell) + 2).prod(axis=1).sum()
    assert filings <= GRID_FILINGS_PER_OBJECT * len(mixed)
    assert choose(16330, 12248, many, "sweep")[0] == METHOD_SWEEP
    with pytest.raises(ValueError, match="unknown broad phase"):
        choose(320, 240, small, "octree")
