"""engine/models/exact/horizonqueue.py: after any sequence of updates (and looks at the first
horizon between them, as the event loop makes) the first horizon found is the earliest one (ties
by key), every horizon is filed once, in its own bucket, and the next horizon of an instant is the
one of the smallest key; for any bucket width (walks of one bucket, a whole ring without a horizon,
times too far for a bucket number), in both lanes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine import jit
from collide2d.engine.models.exact.heap import RANK_CROSS, RANK_WALL, make_key, split_key
from collide2d.engine.models.exact.horizonqueue import (
    FAR,
    Q_NEXT,
    QS_AT,
    QS_TOP,
    bucket_width,
    first_horizon,
    horizon_key,
    new_horizons,
    next_top,
    set_horizon,
)

# a few distinct times, so that ties in time are common; inf is "no horizon"
TIMES = (0.5, 1.0, 1.0 + 2.0**-52, 1.001, 2.0, 700.0, np.inf)
# bucket widths: far apart buckets (the walk laps the ring), a few per bucket, one bucket for all,
# times past any bucket number
WIDTHS = (1e-3, 0.3, 10.0, 1e-300)

updates = st.lists(
    st.tuples(
        st.integers(0, 11), st.sampled_from(TIMES), st.booleans(), st.integers(0, 3), st.booleans()
    ),
    max_size=60,
)


def _bucket(t, rate):
    a = t * rate
    return int(a) if a < FAR else FAR


def _check(Q, static, expected):
    """The queue holds exactly `expected` ({object: (t, key)}), each finite one filed once in the
    list of its bucket's slot."""
    QT, QL, QH, QS = Q.time, Q.links, Q.heads, Q.state
    mask = QH.size - 1
    seen = []
    for s in range(QH.size):
        j = QH[s]
        while j >= 0:
            assert _bucket(QT[j], Q.rate) & mask == s
            assert _bucket(QT[j], Q.rate) >= QS[QS_AT]  # never behind the walk
            seen.append(int(j))
            j = QL[j, Q_NEXT]
    filed = sorted(i for i, (t, _) in expected.items() if t < np.inf)
    assert sorted(seen) == filed
    for i, (t, key) in expected.items():
        assert (QT[i], horizon_key(Q, i)) == (t, key)
        assert split_key(horizon_key(Q, i))[1] == i
    assert not static[seen].any()


@pytest.mark.parametrize("compiled", [False, True])
@settings(max_examples=40, deadline=None)
@given(
    moves=updates,
    seed=st.integers(0, 2**32 - 1),
    width=st.sampled_from(WIDTHS),
    n=st.sampled_from((5, 12)),  # few objects are looked at in place, more walked to
)
def test_updates_keep_the_first_horizon_known(compiled, moves, seed, width, n):
    static = np.random.default_rng(seed).random(n) < 0.25
    Q = new_horizons(static, width)
    QT = Q.time
    expected = {int(i): (np.inf, horizon_key(Q, i)) for i in np.flatnonzero(~static)}
    with jit.lane(compiled):
        for i, t, cross, side, look in moves:
            i %= n
            if static[i]:
                continue
            rank = RANK_CROSS if cross else RANK_WALL
            key = make_key(rank, i, side, side)
            set_horizon(Q, i, t, rank, side)
            expected[i] = (t, key)
            _check(Q, static, expected)
            if not look:
                continue
            top = next_top(Q)
            finite = [(t, key, j) for j, (t, key) in expected.items() if t < np.inf]
            if not finite:
                assert top == -1
                continue
            assert (QT[top], horizon_key(Q, top), top) == min(finite)
            assert Q.state[QS_TOP] == top
            bound = QT[top] + 2.0**-40  # the instant of the top: its two nearest times at 1.0
            k = first_horizon(Q, bound)
            assert horizon_key(Q, k) == min(key for t, key, _ in finite if t <= bound)


def test_the_bucket_width_is_about_a_cell_crossing_per_object():
    F = np.zeros((4, 8))
    F[:, 2:4] = [[10.0, -20.0], [0.0, 0.0], [-40.0, 5.0], [0.0, 30.0]]
    static = np.array([False, False, False, True])
    # crossing times of a 10 px cell at 20 and 40 px/s: median 0.375 s, over 2 moving objects
    assert bucket_width(F, static, 10.0, 100.0, 100.0) == pytest.approx(0.375 / 2)
    assert bucket_width(F, static, 10.0, 5.0, 100.0) == pytest.approx(0.1875 / 2)
    assert bucket_width(np.zeros((2, 8)), np.zeros(2, bool), 10.0, 100.0, 100.0) == 1.0
