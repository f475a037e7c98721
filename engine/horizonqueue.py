"""The exact model's horizon queue: each moving object's one horizon, in an indexed 4-ary heap.

An object's horizon (its next wall contact or cell crossing, prediction.py) is replaced every
time the object is predicted again, so at most one is ever valid. Here it keeps one slot per
moving object, updated in place (sifted up or down), instead of an entry per prediction in the
event queue that would go stale at the object's next event: a crossing or a wall then costs one
sift, and the event queue (eventqueue.py) holds only pair contacts. Slots are ordered by (time,
key) with the event queue's keys (rank, id, side or direction), so ties go crossings first, then
walls, by id; no horizon is time inf. QT (m,) float64 and QK (m,) int64 are the times and keys by
slot, QP (n,) int64 each object's slot (-1: a static object, never in the queue).
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.eventqueue import A_SHIFT, ARITY, ID_MASK, RANK_SHIFT, RANK_WALL
from collide2d.engine.exactstate import INF, hot
from collide2d.engine.jit import njit


def new_horizons(static: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(QT, QK, QP) with every moving object in the queue, in id order, with no horizon."""
    moving = np.flatnonzero(~np.asarray(static, bool))
    QT = np.full(moving.size, INF)
    QK = (RANK_WALL << RANK_SHIFT) | (moving.astype(np.int64) << A_SHIFT)
    QP = np.full(len(static), -1, np.int64)
    QP[moving] = np.arange(moving.size)
    return QT, QK, QP


@hot
def _place(QT, QK, QP, s, t, key):
    QT[s] = t
    QK[s] = key
    QP[(key >> A_SHIFT) & ID_MASK] = s


@njit(cache=True)
def set_horizon(QT, QK, QP, i, t, key):
    """Object i's horizon becomes (t, key): its slot moves up past later parents, or down past
    earlier children."""
    s = QP[i]
    m = QT.shape[0]
    if t < QT[s] or (t == QT[s] and key < QK[s]):
        while s > 0:
            p = (s - 1) // ARITY
            if QT[p] < t or (QT[p] == t and QK[p] < key):
                break
            _place(QT, QK, QP, s, QT[p], QK[p])
            s = p
    else:
        while True:
            first = ARITY * s + 1
            if first >= m:
                break
            c = first
            tc = QT[first]
            for k in range(first + 1, min(first + ARITY, m)):
                tk = QT[k]
                if tk < tc or (tk == tc and QK[k] < QK[c]):
                    c = k
                    tc = tk
            if not (tc < t or (tc == t and QK[c] < key)):
                break
            _place(QT, QK, QP, s, tc, QK[c])
            s = c
    _place(QT, QK, QP, s, t, key)


@hot
def first_horizon(QT, QK, bound, stack):
    """The slot of the horizon to take next: of those no later than `bound` (the top's, at
    least), the one with the smallest key. They are the heap's top subtree of times within the
    bound; `stack` is scratch for walking it."""
    m = QT.shape[0]
    best = 0
    sp = 0
    for c in range(1, min(1 + ARITY, m)):
        if QT[c] <= bound:
            stack[sp] = c
            sp += 1
    while sp > 0:
        sp -= 1
        k = stack[sp]
        if QK[k] < QK[best]:
            best = k
        for c in range(ARITY * k + 1, min(ARITY * k + 1 + ARITY, m)):
            if QT[c] <= bound and sp < stack.shape[0]:
                stack[sp] = c
                sp += 1
    return best
