"""engine/horizonqueue.py: after any sequence of updates the top is the earliest horizon (ties by
key), every object's slot points at its own entry, and the next horizon of an instant is the one
of the smallest key; the same in both lanes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine import jit
from collide2d.engine.eventqueue import RANK_CROSS, RANK_WALL, make_key, split_key
from collide2d.engine.horizonqueue import first_horizon, new_horizons, set_horizon

# a few distinct times, so that ties in time are common; inf is "no horizon"
TIMES = (0.5, 1.0, 1.0 + 2.0**-52, 2.0, np.inf)

updates = st.lists(
    st.tuples(st.integers(0, 11), st.sampled_from(TIMES), st.booleans(), st.integers(0, 3)),
    max_size=60,
)


def _check(QT, QK, QP, static, expected):
    """The queue holds exactly `expected` ({object: (t, key)}) in heap order."""
    moving = np.flatnonzero(~static)
    assert sorted(QP[moving].tolist()) == list(range(moving.size))
    assert (QP[static] == -1).all()
    for i in moving:
        assert (QT[QP[i]], QK[QP[i]]) == expected[i]
        assert split_key(QK[QP[i]])[1] == i
    for s in range(1, QT.size):  # every parent no later than its children
        p = (s - 1) // 4
        assert (QT[p], QK[p]) <= (QT[s], QK[s])
    if moving.size:
        assert (QT[0], QK[0]) == min(expected.values())


@pytest.mark.parametrize("compiled", [False, True])
@settings(max_examples=40, deadline=None)
@given(moves=updates, seed=st.integers(0, 2**32 - 1))
def test_updates_keep_the_earliest_horizon_on_top(compiled, moves, seed):
    static = np.random.default_rng(seed).random(12) < 0.25
    QT, QK, QP = new_horizons(static)
    expected = {int(i): (np.inf, QK[QP[i]]) for i in np.flatnonzero(~static)}
    with jit.lane(compiled):
        for i, t, cross, side in moves:
            if static[i]:
                continue
            key = make_key(RANK_CROSS if cross else RANK_WALL, i, side, side)
            set_horizon(QT, QK, QP, i, t, key)
            expected[i] = (t, key)
            _check(QT, QK, QP, static, expected)
        if expected and QT[0] < np.inf:
            bound = QT[0] + 2.0**-40  # the instant of the top: its two nearest times at 1.0
            k = first_horizon(QT, QK, bound, np.zeros(64, np.int64))
            assert QK[k] == min(key for t, key in expected.values() if t <= bound)
