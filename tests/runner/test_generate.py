"""The grid behind the start-overlap check and generated objects: exact, fast, and reproducible."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scenario_text import any_overlap

from collide2d.runner.scenario import generate

EMPTY = np.zeros((0, 2))


def brute_first_overlap(pos, size):
    """The smallest b overlapping some a < b, and the smallest such a, by checking every pair."""
    lo, hi = pos, pos + size
    for b in range(len(pos)):
        for a in range(b):
            if (
                lo[a, 0] < hi[b, 0]
                and lo[b, 0] < hi[a, 0]
                and lo[a, 1] < hi[b, 1]
                and lo[b, 1] < hi[a, 1]
            ):
                return a, b
    return None


# ----------------------------------------------------------------------------- first_overlap


@settings(max_examples=30, deadline=None)
@given(st.data())
def test_first_overlap_matches_all_pairs(data):
    n = data.draw(st.integers(0, 30))
    corner = st.tuples(st.integers(0, 60), st.integers(0, 60))
    side = st.tuples(st.integers(1, 20), st.integers(1, 20))
    pos = np.array(data.draw(st.lists(corner, min_size=n, max_size=n)), float).reshape(-1, 2)
    size = np.array(data.draw(st.lists(side, min_size=n, max_size=n)), float).reshape(-1, 2)
    if data.draw(st.booleans()):  # half pixels, as float positions under stepped/exact
        pos = pos / 2.0
    assert generate.first_overlap(pos, size) == brute_first_overlap(pos, size)


def test_first_overlap_with_mixed_sizes_matches_all_pairs():
    rng = np.random.default_rng(5)
    for _ in range(20):
        n = 300
        pos = rng.integers(0, 2000, size=(n, 2)).astype(float)
        size = rng.integers(1, 4, size=(n, 2)).astype(float)
        size[rng.integers(0, n, 3)] = [[900, 5], [4, 700], [300, 300]]  # a few long or large ones
        assert generate.first_overlap(pos, size) == brute_first_overlap(pos, size)


@settings(max_examples=40, deadline=None)
@given(st.data())
def test_the_numpy_check_says_apart_only_when_no_two_overlap(data):
    """generate._apart (numpy alone, before any kernel) may decline, but never misses an overlap."""
    n = data.draw(st.integers(2, 40))
    corner = st.tuples(st.integers(0, 30), st.integers(0, 30))
    side = st.tuples(st.integers(1, 6), st.integers(1, 6))
    pos = np.array(data.draw(st.lists(corner, min_size=n, max_size=n)), float) * 4.0
    size = np.array(data.draw(st.lists(side, min_size=n, max_size=n)), float)
    nudge = data.draw(st.sampled_from([0.0, 1e-9, -1e-9, 0.5]))
    pos[1:] += nudge * (np.arange(n - 1) % 2)[:, None]
    if generate._apart(pos, size):
        assert brute_first_overlap(pos, size) is None


def test_the_numpy_check_decides_a_spaced_lattice_and_finds_one_overlap():
    ys, xs = np.mgrid[0:300, 0:300]
    pos = np.stack([xs.ravel(), ys.ravel()], 1) * 12.0
    size = np.full_like(pos, 12.0)  # every box touches its neighbours
    assert generate._apart(pos, size)
    assert generate.first_overlap(pos, size) is None
    pos[77_777] += [0.0, 1e-6]  # now overlaps the box below it, 300 ids on
    assert not generate._apart(pos, size)
    assert generate.first_overlap(pos, size) == (77_777, 78_077)


def test_touching_is_not_overlapping():
    pos = np.array([[0, 0], [10, 0], [0, 10], [10, 10], [20, 0]], float)
    assert generate.first_overlap(pos, np.full((5, 2), 10.0)) is None
    assert generate.first_overlap(pos[:1], np.full((1, 2), 10.0)) is None
    assert generate.first_overlap(EMPTY, EMPTY) is None


def test_first_overlap_on_a_large_tiling():
    # 300 x 300 boxes of 3x3 px tiling a 900 x 900 square: every neighbour touches, none overlaps
    side = 300
    r, c = np.divmod(np.arange(side * side), side)
    pos = np.stack([3.0 * c, 3.0 * r], axis=1)
    size = np.full_like(pos, 3.0)
    generate.first_overlap(pos[:10], size[:10])  # compile outside the timing
    start = time.perf_counter()
    assert generate.first_overlap(pos, size) is None
    elapsed = time.perf_counter() - start
    # box k = (row 10, column 10) moved right by 1 px overlaps only its right neighbour k + 1
    k = 10 * side + 10
    pos[k, 0] += 1.0
    assert generate.first_overlap(pos, size) == (k, k + 1)
    assert elapsed < 2.0, f"{side * side} boxes took {elapsed:.2f} s"


def test_first_overlap_with_one_box_inside_a_large_one():
    pos = np.array([[0, 0], [200, 200], [50, 50]], float)
    size = np.array([[100, 100], [5, 5], [1, 1]], float)
    assert generate.first_overlap(pos, size) == (0, 2)


# ----------------------------------------------------------------------------- the stream


def place_by_hand(width, height, fixed_pos, fixed_size, rng, count, w, h):
    """The documented position rule, by brute force: batches of candidates, first that fits."""
    placed_pos, placed_size = list(fixed_pos), list(fixed_size)
    out = []
    while len(out) < count:
        cands = rng.integers(0, [width - w + 1, height - h + 1], size=(generate.POSITION_BATCH, 2))
        for x, y in cands:
            if len(out) == count:
                break
            fits = all(
                not (px < x + w and x < px + pw and py < y + h and y < py + ph)
                for (px, py), (pw, ph) in zip(placed_pos, placed_size, strict=True)
            )
            if fits:
                out.append((x, y))
                placed_pos.append((x, y))
                placed_size.append((w, h))
    return np.array(out, float).reshape(-1, 2)


def test_positions_then_speed_signs_follow_the_documented_stream():
    fixed_pos = np.array([[10, 10], [30, 5]], float)
    fixed_size = np.array([[12, 8], [6, 20]], float)
    spec = generate.BlockSpec(count=25, size=(5, 4), seed=9, speed=7.0)
    ((pos, vel),) = generate.generate(60, 40, fixed_pos, fixed_size, [spec])
    rng = np.random.default_rng(9)
    expected = place_by_hand(60, 40, fixed_pos, fixed_size, rng, 25, 5, 4)
    signs = rng.integers(0, 2, size=(25, 2))
    assert np.array_equal(pos, expected)
    assert np.array_equal(vel, (2.0 * signs - 1.0) * 7.0)


def test_speed_range_follows_the_documented_stream():
    spec = generate.BlockSpec(count=12, size=(3, 3), seed=4, speed_range=(2.0, 6.0))
    ((pos, vel),) = generate.generate(50, 50, EMPTY, EMPTY, [spec])
    rng = np.random.default_rng(4)
    place_by_hand(50, 50, [], [], rng, 12, 3, 3)
    mag = rng.uniform(2.0, 6.0, size=12)
    ang = rng.uniform(0.0, 2 * np.pi, size=12)
    assert np.array_equal(vel, np.stack([mag * np.cos(ang), mag * np.sin(ang)], axis=1))
    whole = generate.generate(
        50,
        50,
        EMPTY,
        EMPTY,
        [generate.BlockSpec(12, (3, 3), 4, speed_range=(2.0, 6.0), whole=True)],
    )[0][1]
    assert np.array_equal(whole, np.floor(vel + 0.5))


def test_velocity_range_follows_the_documented_stream():
    lo, hi = (-3.0, 1.0), (2.0, 4.0)
    for whole in (False, True):
        spec = generate.BlockSpec(20, (2, 2), 8, velocity_range=(lo, hi), whole=whole)
        ((_, vel),) = generate.generate(40, 40, EMPTY, EMPTY, [spec])
        rng = np.random.default_rng(8)
        place_by_hand(40, 40, [], [], rng, 20, 2, 2)
        if whole:
            want = rng.integers([-3, 1], [2, 4], size=(20, 2), endpoint=True).astype(float)
        else:
            want = rng.uniform(lo, hi, size=(20, 2))
        assert np.array_equal(vel, want)


def test_each_block_has_its_own_generator_and_avoids_earlier_blocks():
    a = generate.BlockSpec(30, (4, 4), seed=1)
    b = generate.BlockSpec(30, (6, 2), seed=1)
    (pa, va), (pb, vb) = generate.generate(80, 60, EMPTY, EMPTY, [a, b])
    assert np.all(va == 0) and np.all(vb == 0)
    pos = np.concatenate([pa, pb])
    size = np.concatenate([np.full((30, 2), 4.0), np.tile([6.0, 2.0], (30, 1))])
    assert not any_overlap(pos, size)
    # block b draws from default_rng(1) afresh, avoiding block a's boxes
    rng = np.random.default_rng(1)
    assert np.array_equal(pb, place_by_hand(80, 60, list(pa), [(4, 4)] * 30, rng, 30, 6, 2))


# ----------------------------------------------------------------------------- properties


@settings(max_examples=30, deadline=None)
@given(
    width=st.integers(20, 120),
    height=st.integers(20, 120),
    w=st.integers(1, 8),
    h=st.integers(1, 8),
    count=st.integers(0, 60),
    seed=st.integers(0, 2**32),
)
def test_generated_boxes_are_inside_whole_and_apart(width, height, w, h, count, seed):
    fixed_pos = np.array([[width / 4, height / 4]])
    fixed_size = np.array([[w + 2.5, h + 1.0]])
    # at 30 % coverage random placement is far from jamming (about 55 % for squares)
    assume((count + 1) * (w + 2.5) * (h + 1) <= 0.3 * width * height)
    ((pos, vel),) = generate.generate(
        width, height, fixed_pos, fixed_size, [generate.BlockSpec(count, (w, h), seed, speed=3.0)]
    )
    assert pos.shape == (count, 2) and vel.shape == (count, 2)
    assert np.all(pos == np.floor(pos))
    assert np.all(pos >= 0) and np.all(pos + [w, h] <= [width, height])
    all_pos = np.concatenate([fixed_pos, pos])
    all_size = np.concatenate([fixed_size, np.tile([float(w), float(h)], (count, 1))])
    assert not any_overlap(all_pos, all_size)
    assert np.all(np.abs(vel) == 3.0)


def test_seeds():
    spec = generate.BlockSpec(50, (3, 3), seed=21, speed=2.0)
    one = generate.generate(100, 100, EMPTY, EMPTY, [spec])[0]
    two = generate.generate(100, 100, EMPTY, EMPTY, [spec])[0]
    other = generate.generate(
        100, 100, EMPTY, EMPTY, [generate.BlockSpec(50, (3, 3), 22, speed=2.0)]
    )[0]
    assert np.array_equal(one[0], two[0]) and np.array_equal(one[1], two[1])
    assert not np.array_equal(one[0], other[0])


def test_speed_gives_both_signs_on_both_axes():
    ((_, vel),) = generate.generate(
        200, 200, EMPTY, EMPTY, [generate.BlockSpec(100, (2, 2), speed=5.0)]
    )
    for axis in (0, 1):
        assert set(np.unique(vel[:, axis])) == {-5.0, 5.0}


def test_speed_range_magnitudes_and_directions():
    spec = generate.BlockSpec(400, (2, 2), seed=3, speed_range=(4.0, 6.0))
    ((_, vel),) = generate.generate(300, 300, EMPTY, EMPTY, [spec])
    speed = np.hypot(vel[:, 0], vel[:, 1])
    assert np.all((speed >= 4.0 - 1e-12) & (speed <= 6.0 + 1e-12))
    quadrant = (vel[:, 0] > 0).astype(int) * 2 + (vel[:, 1] > 0)
    assert set(np.unique(quadrant)) == {0, 1, 2, 3}


def test_whole_velocity_range_reaches_both_ends():
    spec = generate.BlockSpec(
        300, (2, 2), seed=6, velocity_range=((-1.0, -1.0), (1.0, 1.0)), whole=True
    )
    ((_, vel),) = generate.generate(300, 300, EMPTY, EMPTY, [spec])
    for axis in (0, 1):
        assert set(np.unique(vel[:, axis])) == {-1.0, 0.0, 1.0}


# ----------------------------------------------------------------------------- refusals


def test_more_area_than_the_world_is_refused_at_once():
    start = time.perf_counter()
    with pytest.raises(generate.PlacementError) as info:
        generate.generate(320, 240, EMPTY, EMPTY, [generate.BlockSpec(5000, (10, 10))])
    assert time.perf_counter() - start < 0.1
    err = info.value
    assert str(err).startswith("cannot place 5000 boxes of 10x10 without overlap in 320x240")
    assert (err.block, err.count, err.placed) == (0, 5000, 0)


def test_a_jammed_world_is_refused_after_bounded_draws():
    with pytest.raises(generate.PlacementError) as info:
        generate.generate(
            320,
            240,
            EMPTY,
            EMPTY,
            [generate.BlockSpec(10, (2, 2)), generate.BlockSpec(700, (10, 10))],
        )
    err = info.value
    assert err.block == 1 and 0 < err.placed < 700
    assert str(err).startswith("cannot place 700 boxes of 10x10 without overlap in 320x240")
    budget = generate.MAX_DRAWS_PER_OBJECT_AVERAGE * 700 + generate.MAX_DRAWS_PER_OBJECT
    assert err.draws <= budget + generate.POSITION_BATCH


def test_a_box_larger_than_the_world():
    with pytest.raises(generate.PlacementError, match="larger than the world"):
        generate.generate(10, 10, EMPTY, EMPTY, [generate.BlockSpec(1, (11, 2))])


def test_overlapping_fixed_boxes_are_refused():
    with pytest.raises(ValueError):
        generate.generate(50, 50, np.array([[0, 0], [5, 5]], float), np.full((2, 2), 10.0), [])


def test_zero_count_block():
    ((pos, vel),) = generate.generate(
        10, 10, EMPTY, EMPTY, [generate.BlockSpec(0, (2, 2), speed=1.0)]
    )
    assert pos.shape == (0, 2) and vel.shape == (0, 2)


# ----------------------------------------------------------------------------- scale


def test_100k_boxes_at_5_percent_coverage_are_fast():
    # 100,000 boxes of 5x5 px = 2.5e6 px^2, 5 % of a 7072 x 7072 world
    generate.generate(
        50, 50, EMPTY, EMPTY, [generate.BlockSpec(5, (5, 5))]
    )  # compile outside the timing
    start = time.perf_counter()
    ((pos, _),) = generate.generate(
        7072, 7072, EMPTY, EMPTY, [generate.BlockSpec(100_000, (5, 5), seed=2)]
    )
    elapsed = time.perf_counter() - start
    assert pos.shape == (100_000, 2)
    assert generate.first_overlap(pos, np.full_like(pos, 5.0)) is None
    assert elapsed < 2.0, f"100,000 boxes took {elapsed:.2f} s"


SCRIPT = """
import json, numpy as np
from collide2d.runner.scenario import generate
fixed = np.array([[3.5, 4.0], [20.0, 20.0]]); fsize = np.array([[6.0, 6.0], [9.0, 2.0]])
blocks = [generate.BlockSpec(40, (3, 2), 5, speed_range=(1.0, 4.0), whole=True),
          generate.BlockSpec(20, (2, 2), 6, speed=2.5)]
out = generate.generate(64, 48, fixed, fsize, blocks)
pos = np.concatenate([fixed] + [o[0] for o in out]); size = np.concatenate(
    [fsize, np.tile([3.0, 2.0], (40, 1)), np.full((20, 2), 2.0)])
pos[-1] = pos[5]
print(json.dumps({"out": [[o[0].tolist(), o[1].tolist()] for o in out],
                  "overlap": generate.first_overlap(pos, size)}))
"""


def test_the_same_source_runs_without_the_compiler():
    compiled = subprocess.run(
        [sys.executable, "-c", SCRIPT],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "NUMBA_DISABLE_JIT": "0"},
    )
    plain = subprocess.run(
        [sys.executable, "-c", SCRIPT],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "NUMBA_DISABLE_JIT": "1"},
    )
    a, b = json.loads(compiled.stdout), json.loads(plain.stdout)
    assert a == b
    # box 61 (2x2) sits on the corner of box 5 (3x2), which overlaps nothing else
    assert a["overlap"] == [5, 61]
