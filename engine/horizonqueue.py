"""The exact model's horizon queue: each moving object's one horizon, filed by time in buckets.

An object's horizon (its next wall contact or cell crossing, prediction.py) is replaced every
time the object is predicted again, so at most one is ever valid, and a new one is never before
the present. Here they are filed as in a calendar queue: bucket b holds the horizons of times in
[b·w, (b+1)·w) (w the bucket width, `bucket_width`), bucket b in ring slot b mod the number of
slots, an unsorted doubly linked list. Replacing a horizon (a crossing, a wall) is then a constant
number of steps, where a heap of 10,000 objects took five levels of sifting. The first horizon
(by time, then key) is kept known; when it is replaced by a later one, the next is found by
walking the buckets on from the current one (`find_top`), each seen once per pass of time: about
one bucket per horizon taken when w matches how often they come, and after a whole ring of slots
without one, a look at every object. `first_horizon` takes, of the horizons within an instant of
the first, the one with the smallest key, as the event queue does for its contacts. The order is
that of (time, key) exactly, whatever w is: w only sets how much walking finding the next takes.

The queue is one tuple Q = (QT, QK, QL, QH, QS, QW): each object's horizon time QT (n,) float64
(inf: none, or a static object) and key QK (n,) int64 (eventqueue.py keys: rank, id, side or
direction, so ties go crossings first, then walls, by id); its links QL (n, 3) int64 (next and
previous object in its bucket's list, -1 for none, and its bucket, -1 when in none); the first
object of each ring slot QH (slots,) int64 (-1: empty; slots a power of two); the scalar state QS
(the bucket the walk is at, every filed horizon's bucket being at least it; the object of the
first horizon, -1 when not known; how many horizons are filed) and the width QW (1,) float64, s.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.eventqueue import A_SHIFT, RANK_SHIFT, RANK_WALL
from collide2d.engine.exactstate import INF, hot
from collide2d.engine.jit import njit

# Columns of QL: the next and previous object in the same bucket's list, and the bucket.
Q_NEXT, Q_PREV, Q_BUCKET = range(3)
# QS: the bucket the walk is at, the object of the first horizon (-1: not known), horizons filed.
QS_AT, QS_TOP, QS_FILED = range(3)
# A horizon this many bucket widths away or more is filed in the bucket FAR (no int64 overflow).
FAR = 1 << 62
# Ring slots per moving object (rounded up to a power of two), and at least MIN_SLOTS.
SLOTS_PER_OBJECT = 1
MIN_SLOTS = 8


def bucket_width(F: np.ndarray, static: np.ndarray, cell: float, width: float, height: float):
    """A bucket width (s) for about one horizon per bucket: the median time a moving object
    takes to cross a cell (or the world, if smaller) at its speed along its faster axis, over
    the number of moving objects. Any width gives the same order; this one only keeps the walk
    short."""
    moving = ~np.asarray(static, bool)
    speed = np.abs(F[moving, 2:4]).max(axis=1) if moving.any() else np.zeros(0)
    speed = speed[speed > 0.0]
    if speed.size == 0:
        return 1.0
    span = min(cell, width, height)
    with np.errstate(over="ignore"):  # (a subnormal speed: no width from it)
        w = float(np.median(span / speed)) / speed.size
    return w if np.isfinite(w) and w > 0.0 else 1.0


def new_horizons(static: np.ndarray, width: float) -> tuple:
    """The queue Q of `static`'s objects: none has a horizon yet; buckets `width` s wide."""
    static = np.asarray(static, bool)
    n = static.size
    slots = MIN_SLOTS
    while slots < SLOTS_PER_OBJECT * int((~static).sum()):
        slots *= 2
    QT = np.full(n, INF)
    QK = (RANK_WALL << RANK_SHIFT) | (np.arange(n, dtype=np.int64) << A_SHIFT)
    QL = np.full((n, 3), -1, np.int64)
    QH = np.full(slots, -1, np.int64)
    QS = np.zeros(3, np.int64)
    QS[QS_TOP] = -1
    QW = np.array([float(width)])
    return QT, QK, QL, QH, QS, QW


@hot
def _before(QT, QK, i, j):
    """Object i's horizon comes before object j's, by (time, key)."""
    return QT[i] < QT[j] or (QT[i] == QT[j] and QK[i] < QK[j])


@njit(cache=True)
def set_horizon(Q, i, t, key):
    """Object i's horizon becomes (t, key) (t >= the present; inf: none): it leaves its bucket
    for that of t, and the first horizon stays known unless it was i's and i's is now later."""
    QT, QK, QL, QH, QS, QW = Q
    mask = QH.shape[0] - 1
    if QL[i, Q_BUCKET] >= 0:  # unlink
        nxt, prv = QL[i, Q_NEXT], QL[i, Q_PREV]
        if prv >= 0:
            QL[prv, Q_NEXT] = nxt
        else:
            QH[QL[i, Q_BUCKET] & mask] = nxt
        if nxt >= 0:
            QL[nxt, Q_PREV] = prv
        QS[QS_FILED] -= 1
    top = QS[QS_TOP]
    later = top == i and (t > QT[i] or (t == QT[i] and key > QK[i]))
    QT[i] = t
    QK[i] = key
    if t < INF:
        a = t / QW[0]
        b = int(a) if a < FAR else FAR
        s = b & mask
        QL[i, Q_BUCKET] = b
        QL[i, Q_PREV] = -1
        QL[i, Q_NEXT] = QH[s]
        if QH[s] >= 0:
            QL[QH[s], Q_PREV] = i
        QH[s] = i
        QS[QS_FILED] += 1
        if b < QS[QS_AT]:
            QS[QS_AT] = b
    else:
        QL[i, Q_BUCKET] = -1
    if top == i:
        if later:
            QS[QS_TOP] = -1
    elif top >= 0 and _before(QT, QK, i, top):
        QS[QS_TOP] = i


@njit(cache=True)
def find_top(Q):
    """The object of the first horizon (by time, then key), -1 if none has one; kept known in
    QS. Walks the buckets from the current one to the first holding a horizon of its own (not
    one of a later pass of the ring); after a whole ring without, looks at every object."""
    QT, QK, QL, QH, QS, QW = Q
    if QS[QS_FILED] == 0:
        QS[QS_TOP] = -1
        return -1
    mask = QH.shape[0] - 1
    at = QS[QS_AT]
    best = -1
    for _ in range(QH.shape[0]):
        j = QH[at & mask]
        while j >= 0:
            if QL[j, Q_BUCKET] == at and (best < 0 or _before(QT, QK, j, best)):
                best = j
            j = QL[j, Q_NEXT]
        if best >= 0:
            break
        at += 1
    if best < 0:  # a whole ring of slots without one: look at every object
        for j in range(QT.shape[0]):
            if QL[j, Q_BUCKET] >= 0 and (best < 0 or _before(QT, QK, j, best)):
                best = j
        at = QL[best, Q_BUCKET]
    QS[QS_AT] = at
    QS[QS_TOP] = best
    return best


@njit(cache=True)
def first_horizon(Q, bound):
    """The object of the horizon to take next: of those no later than `bound` (the first
    horizon's, at least; it is known), the one with the smallest key."""
    QT, QK, QL, QH, QS, QW = Q
    mask = QH.shape[0] - 1
    best = QS[QS_TOP]
    a = bound / QW[0]
    last = int(a) if a < FAR else FAR
    last = min(last, QS[QS_AT] + mask)  # a whole ring sees every slot
    for b in range(QS[QS_AT], last + 1):
        j = QH[b & mask]
        while j >= 0:
            if QT[j] <= bound and QK[j] < QK[best]:
                best = j
            j = QL[j, Q_NEXT]
    return best
