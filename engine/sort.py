"""Sorting without allocating, for the broad phase and the models' pair lists.

`sort_order` keeps an order of objects sorted by a key from call to call, mending it by insertion
sort (objects move a little between calls) or sorting it afresh by heap sort when it is far off;
`sort_keys` sorts a short list of pair keys in place, `sort_pair_keys` a long one by its first
object's bucket, `sort_by_time` a list of pair keys by the times beside them; `heap_argsort` gives
the order of a key array (heap sort: O(n log n), compiles quickly, allocates only the result). All
numba kernels, but `median`: numpy.median's value, without the import of numpy.ma that
numpy.median's first call costs (tens of ms of a small run's start).
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.jit import njit

# An insertion sort that has to shift more than this many places per object falls back to a full
# sort (a scene that reshuffled, e.g. objects crossing the world in one step).
SHIFTS_PER_OBJECT = 8

# Pair-key lists up to this long are sorted by insertion, faster than a heap sort there.
INSERTION_SORT_MAX = 64


@njit(cache=True)
def _heapsort_order(order, key):
    """Sort `order` in place so that key[order] ascends (heap sort: allocates nothing)."""
    n = order.shape[0]
    top = np.int64(0)  # a typed 0: a literal 0 would compile _sift_order once more
    for root in range(n // 2 - 1, -1, -1):
        _sift_order(order, key, root, n)
    for end in range(n - 1, 0, -1):
        order[0], order[end] = order[end], order[0]
        _sift_order(order, key, top, end)


@njit(cache=True)
def _sift_order(order, key, root, n):
    while True:
        c = 2 * root + 1
        if c >= n:
            return
        if c + 1 < n and key[order[c + 1]] > key[order[c]]:
            c += 1
        if key[order[root]] >= key[order[c]]:
            return
        order[root], order[c] = order[c], order[root]
        root = c


@njit(cache=True)
def sort_order(order, key, sorted_key):
    """Mend `order` so key[order] ascends, and set sorted_key = key[order].

    order (n,) int64, the order of an earlier call (nearly sorted: objects move a little between
    calls) is mended by insertion sort, or sorted afresh when it is far off.
    """
    n = order.shape[0]
    for s in range(n):
        sorted_key[s] = key[order[s]]
    budget = SHIFTS_PER_OBJECT * n + 16
    shifts = 0
    for i in range(1, n):
        cur = order[i]
        k = sorted_key[i]
        j = i - 1
        while j >= 0 and sorted_key[j] > k:
            order[j + 1] = order[j]
            sorted_key[j + 1] = sorted_key[j]
            j -= 1
        shifts += i - 1 - j
        order[j + 1] = cur
        sorted_key[j + 1] = k
        if shifts > budget:
            _heapsort_order(order, key)
            for s in range(n):
                sorted_key[s] = key[order[s]]
            return


@njit(cache=True)
def heap_argsort(keys):
    """Indices that sort the 1-D `keys` ascending (heapsort: O(n log n), compiles quickly)."""
    idx = np.arange(keys.shape[0])
    _heapsort_order(idx, keys)
    return idx


@njit(cache=True)
def sort_keys(keys, n):
    """Sort keys[:n] in place, allocating nothing: insertion sort for the usual handful (the
    pairs that overlap in one step), a heap sort past INSERTION_SORT_MAX."""
    if n > INSERTION_SORT_MAX:
        top = np.int64(0)  # a typed 0: a literal 0 would compile _sift_keys once more
        for root in range(n // 2 - 1, -1, -1):
            _sift_keys(keys, root, n)
        for end in range(n - 1, 0, -1):
            keys[0], keys[end] = keys[end], keys[0]
            _sift_keys(keys, top, end)
        return
    _insertion_sort(keys, n)


@njit(cache=True)
def _insertion_sort(keys, n):
    """Sort keys[:n] in place by insertion: quick for a handful, or for keys each near its place."""
    for i in range(1, n):
        key = keys[i]
        j = i - 1
        while j >= 0 and keys[j] > key:
            keys[j + 1] = keys[j]
            j -= 1
        keys[j + 1] = key


@njit(cache=True)
def _sift_keys(keys, root, n):
    while True:
        c = 2 * root + 1
        if c >= n:
            return
        if c + 1 < n and keys[c + 1] > keys[c]:
            c += 1
        if keys[root] >= keys[c]:
            return
        keys[root], keys[c] = keys[c], keys[root]
        root = c


@njit(cache=True)
def sort_pair_keys(keys, k, shift, heads):
    """Sort keys[:k] in place, each key's high part (key >> shift) an object in [0, n); heads
    (2n + 1,) int64 is scratch. The keys are put in their high part's bucket in place (an American
    flag sort: one counting pass, then each key swapped to where its bucket fills), then an
    insertion sort orders each bucket (a handful of keys): O(k + n), where `sort_keys` is
    O(k log k) past its handful and jumps about memory (a candidate list of 22,000 keys: a fifth
    of the time)."""
    n = (heads.shape[0] - 1) // 2
    if k <= INSERTION_SORT_MAX or n == 0:
        sort_keys(keys, k)
        return
    start = heads[: n + 1]
    fill = heads[n + 1 :]
    start[:] = 0
    for c in range(k):
        start[(keys[c] >> shift) + 1] += 1
    for b in range(n):
        start[b + 1] += start[b]
        fill[b] = start[b]
    for b in range(n):
        end = start[b + 1]
        while fill[b] < end:
            i = fill[b]
            h = keys[i] >> shift
            if h == b:
                fill[b] += 1
            else:
                j = fill[h]
                fill[h] += 1
                keys[i], keys[j] = keys[j], keys[i]
    _insertion_sort(keys, k)  # each key is in its bucket: it moves only within it


@njit(cache=True, inline="always")
def _before(when, keys, i, j):
    """Whether entry i comes before entry j: earlier time, then smaller key."""
    return when[i] < when[j] or (when[i] == when[j] and keys[i] < keys[j])


@njit(cache=True)
def sort_by_time(when, keys, n):
    """Sort when[:n] and keys[:n] together in place by (time, key), allocating nothing: insertion
    sort for the usual handful, a heap sort past INSERTION_SORT_MAX."""
    if n > INSERTION_SORT_MAX:
        _heap_sort_timed(when, keys, n)
        return
    for i in range(1, n):
        t = when[i]
        key = keys[i]
        j = i - 1
        while j >= 0 and (when[j] > t or (when[j] == t and keys[j] > key)):
            when[j + 1] = when[j]
            keys[j + 1] = keys[j]
            j -= 1
        when[j + 1] = t
        keys[j + 1] = key


@njit(cache=True)
def _heap_sort_timed(when, keys, n):
    """`sort_by_time`'s heap sort: the heap built, then its top taken n - 1 times, every sift
    in this one loop, so that no call inside hands the arrays on (each costs reference counts:
    a sort of a thousand pairs made thousands of calls)."""
    half = n // 2
    for r in range(half + n - 1):
        if r < half:  # build: each inner node sifted, the last first
            root = half - 1 - r
            end = n
        else:  # take the top: it goes to the end, the new top sifts down
            end = n - 1 - (r - half)
            when[0], when[end] = when[end], when[0]
            keys[0], keys[end] = keys[end], keys[0]
            root = 0
        while True:
            c = 2 * root + 1
            if c >= end:
                break
            if c + 1 < end and _before(when, keys, c, c + 1):
                c += 1
            if not _before(when, keys, root, c):
                break
            when[root], when[c] = when[c], when[root]
            keys[root], keys[c] = keys[c], keys[root]
            root = c


def median(v: np.ndarray) -> float:
    """numpy.median of a non-empty 1-D array (the middle value, or the mean of the two middle
    ones; NaN when any is NaN), without numpy.median's first-call import of numpy.ma. Bit for bit
    but for the sign of a zero median: numpy's partition may put 0.0 or -0.0, which compare
    equal, in the middle (every caller takes the median as a size, where the two are the same)."""
    s = np.sort(np.asarray(v, dtype=np.float64).ravel())
    if np.isnan(s[-1]):
        return math.nan
    k = s.shape[0] // 2
    if s.shape[0] % 2:
        return float(s[k])
    return float((s[k - 1] + s[k]) / 2.0)
