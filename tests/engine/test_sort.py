"""engine/sort.py: each sort gives numpy's order (or sorted()'s, for pairs of time and key), for
nearly sorted and reshuffled input alike; `median` is numpy.median bit for bit (but a zero's sign),
and leaves numpy.ma unimported."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from collide2d.engine.sort import (
    heap_argsort,
    median,
    sort_by_time,
    sort_keys,
    sort_order,
    sort_pair_keys,
)

keys = st.lists(st.integers(-50, 50), max_size=200).map(lambda v: np.array(v, np.int64))


@settings(max_examples=60, deadline=None)
@given(keys, st.integers(0, 2**32 - 1), st.booleans())
def test_sort_order_mends_an_earlier_order(key, seed, reshuffle):
    rng = np.random.default_rng(seed)
    order = np.argsort(key, kind="stable").astype(np.int64)
    if reshuffle:
        rng.shuffle(order)  # far off: the heap sort takes over
    elif len(order) > 1:
        i = rng.integers(0, len(order) - 1)
        order[[i, i + 1]] = order[[i + 1, i]]  # a neighbour swap: insertion sort mends it
    sorted_key = np.empty_like(key)
    sort_order(order, key, sorted_key)
    assert sorted(order.tolist()) == list(range(len(key)))
    assert np.array_equal(sorted_key, np.sort(key)) and np.array_equal(key[order], sorted_key)


@settings(max_examples=60, deadline=None)
@given(keys)
def test_sort_keys_sorts_the_first_n_in_place(key):
    n = len(key) // 2 + len(key) % 2
    got = key.copy()
    sort_keys(got, n)
    assert np.array_equal(got[:n], np.sort(key[:n])) and np.array_equal(got[n:], key[n:])


# Pair keys as the candidate lists make them: the first object's id in the high bits.
SHIFT = 32


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 40),
    st.lists(st.tuples(st.integers(0, 39), st.integers(0, 2**31)), max_size=400, unique=True),
    st.integers(0, 2**32 - 1),
)
def test_sort_pair_keys_sorts_the_first_k_by_bucket_then_key(n, pairs, seed):
    rng = np.random.default_rng(seed)
    key = np.unique(np.array([(a % n) << SHIFT | b for a, b in pairs], np.int64))
    rng.shuffle(key)
    tail = rng.integers(0, 2**62, 3)  # past k: left alone
    got = np.concatenate([key, tail])
    heads = np.full(2 * n + 1, 7, np.int64)  # scratch, whatever it held
    sort_pair_keys(got, len(key), SHIFT, heads)
    assert np.array_equal(got[: len(key)], np.sort(key)) and np.array_equal(got[len(key) :], tail)


@settings(max_examples=60, deadline=None)
@given(keys.map(lambda k: k.astype(np.float64)))
def test_heap_argsort_orders_the_keys(key):
    idx = heap_argsort(key)
    assert sorted(idx.tolist()) == list(range(len(key)))
    assert np.array_equal(key[idx], np.sort(key))


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.sampled_from([-np.inf, 0.0, 0.25, 0.5, 1.0]), st.integers(0, 40)),
        max_size=150,
    )
)
def test_sort_by_time_orders_by_time_then_key(entries):
    when = np.array([t for t, _ in entries], np.float64)
    keys = np.array([k for _, k in entries], np.int64)
    n = len(entries) - len(entries) // 3
    w, k = when.copy(), keys.copy()
    sort_by_time(w, k, n)
    assert list(zip(w[:n].tolist(), k[:n].tolist(), strict=True)) == sorted(entries[:n])
    assert np.array_equal(w[n:], when[n:]) and np.array_equal(k[n:], keys[n:])


floats = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=200, deadline=None)
@given(st.lists(floats, min_size=1, max_size=40))
@example([0.0, 0.0, -0.0, 0.0, 0.0])  # numpy's partition puts 0.0 in the middle, a sort -0.0
@example([1.0, np.nan, 2.0])
def test_median_is_numpy_median_bit_for_bit_but_a_zeros_sign(values):
    v = np.array(values, np.float64)
    with np.errstate(invalid="ignore"):  # inf + -inf in the middle: NaN in both
        expected = np.median(v)
    got = median(v)
    assert isinstance(got, float)
    assert np.array_equal(np.float64(got), expected, equal_nan=True)
    if expected != 0.0 and not np.isnan(expected):  # a zero's sign is numpy's partition's
        assert np.float64(got).tobytes() == expected.tobytes()


def test_median_does_not_import_numpy_ma():
    import subprocess
    import sys

    code = (
        "import sys, numpy as np; print('numpy.ma' in sys.modules); "
        "from collide2d.engine.sort import median; "
        "median(np.array([3.0, 1.0, 2.0])); print('numpy.ma' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    by_numpy, after = done.stdout.split()
    if by_numpy == "True":
        pytest.skip("this numpy imports numpy.ma itself (numpy < 2)")
    assert after == "False"
