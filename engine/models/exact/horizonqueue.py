"""The exact model's horizon queue: each moving object's one horizon, filed by time in buckets.

An object's horizon (its next wall contact or cell crossing, prediction.py) is replaced every
time the object is predicted again, so at most one is ever valid, and a new one is never before
the present. Here they are filed as in a calendar queue: bucket b holds the horizons of times in
[b·w, (b+1)·w) (w the bucket width, `bucket_width`), bucket b in ring slot b mod the number of
slots, an unsorted doubly linked list. Replacing a horizon (a crossing, a wall) is then a constant
number of steps, where a heap of 10,000 objects took five levels of sifting (the gas of
`collide2d bench --part exact`: 17 % fewer instructions per event). The first horizon
(by time, then key) is kept known; when it is replaced by a later one, the next is found by
walking the buckets on from the current one (`find_top`), each seen once per pass of time: about
one bucket per horizon taken when w matches how often they come, and after a whole ring of slots
without one (or at once, with FEW objects), a look at every object. `first_horizon` takes, of
the horizons within an instant of the first, the one with the smallest key, as the event queue
does for its contacts. The order is that of (time, key) exactly, whatever w is: w only sets how
much walking finding the next takes.

The queue is one record Q (state.Horizons), small, as the event loop's memory traffic is most
of its time, read by field (the kernels name the fields QT, QC, QL, QH, QS): each object's horizon
time QT = Q.time (n,) float64 (inf: none, or a static object; the bucket of a finite one is
QT·Q.rate, rounded down) and what it is, QC = Q.code (n,) int8 (rank × 8 + side, direction or
STOP: its event queue key, heap.py, is `horizon_key`, so ties go crossings first, then walls and
stops, by id); its
links QL = Q.links (n, 2) int32 (next and previous object in its bucket's list, -1 for none); the
first object of each ring slot QH = Q.heads (slots,) int32 (-1: empty; slots a power of two); the
scalar state QS = Q.state (the bucket the walk is at, every filed horizon's bucket being at least
it; the object of the first horizon, -1 when not known; how many horizons are filed) and Q.rate,
one over the bucket width (1/s).
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit
from collide2d.engine.models.exact.heap import ID_BITS, RANK_WALL, make_key
from collide2d.engine.models.exact.state import INF, Horizons, hot
from collide2d.engine.sort import median

# Columns of QL: the next and previous object in the same bucket's list.
Q_NEXT, Q_PREV = range(2)
# QS: the bucket the walk is at, the object of the first horizon (-1: not known), horizons filed.
QS_AT, QS_TOP, QS_FILED = range(3)
# A horizon this many bucket widths away or more is filed in the bucket FAR (no int64 overflow).
FAR = 1 << 62
# With at most this many objects, finding the first horizon looks at each (no walk).
FEW = 8
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
        w = median(span / speed) / speed.size
    return w if np.isfinite(w) and w > 0.0 else 1.0


def new_horizons(static: np.ndarray, width: float) -> Horizons:
    """The queue Q of `static`'s objects: none has a horizon yet; buckets `width` s wide."""
    static = np.asarray(static, bool)
    n = static.size
    slots = MIN_SLOTS
    while slots < SLOTS_PER_OBJECT * int((~static).sum()):
        slots *= 2
    QT = np.full(n, INF)
    QC = np.full(n, RANK_WALL * 8, np.int8)
    QL = np.full((n, 2), -1, np.int32)
    QH = np.full(slots, -1, np.int32)
    QS = np.zeros(3, np.int64)
    QS[QS_TOP] = -1
    return Horizons(QT, QC, QL, QH, QS, 1.0 / float(width))


@hot
def horizon_key(Q, i):
    """Object i's horizon as an event queue key (rank, i, side or direction)."""
    c = int(Q.code[i])
    return make_key(c >> 3, int(i), c & 7, c & 7)


@hot
def _bucket(t, rate):
    """The bucket of time t, at `rate` buckets per second."""
    a = t * rate
    return int(a) if a < FAR else FAR


@hot
def _order(QC, i):
    """Where object i's horizon key goes among other objects': by (rank, id)."""
    return ((int(QC[i]) >> 3) << ID_BITS) | int(i)


@hot
def _before(QT, QC, i, j):
    """Object i's horizon comes before object j's (another object's), by (time, key)."""
    if QT[i] != QT[j]:
        return QT[i] < QT[j]
    return _order(QC, i) < _order(QC, j)


@njit(cache=True)
def set_horizon(Q, i, t, rank, d):
    """Object i's horizon becomes (t, rank, side or direction d) (t >= the present; inf: none):
    it leaves its bucket for that of t, and the first horizon stays known unless it was i's and
    i's is now later."""
    QT, QC, QL, QH, QS = Q.time, Q.code, Q.links, Q.heads, Q.state
    mask = QH.shape[0] - 1
    if QT[i] < INF:  # unlink
        nxt, prv = int(QL[i, Q_NEXT]), int(QL[i, Q_PREV])
        if prv >= 0:
            QL[prv, Q_NEXT] = nxt
        else:
            QH[_bucket(QT[i], Q.rate) & mask] = nxt
        if nxt >= 0:
            QL[nxt, Q_PREV] = prv
        QS[QS_FILED] -= 1
    top = QS[QS_TOP]
    code = rank * 8 + d
    later = top == i and (t > QT[i] or (t == QT[i] and code > QC[i]))
    QT[i] = t
    QC[i] = code
    if t < INF:
        b = _bucket(t, Q.rate)
        s = b & mask
        QL[i, Q_PREV] = -1
        head = int(QH[s])
        QL[i, Q_NEXT] = head
        if head >= 0:
            QL[head, Q_PREV] = i
        QH[s] = i
        QS[QS_FILED] += 1
        if b < QS[QS_AT]:
            QS[QS_AT] = b
    if top == i:
        if later:
            QS[QS_TOP] = -1
    elif top >= 0 and _before(QT, QC, i, top):
        QS[QS_TOP] = i


@hot
def next_top(Q):
    """find_top, with a scene of FEW objects looked at in place (no call: the two-body chain
    finds its first horizon again after nearly every event)."""
    QT, QC, QS = Q.time, Q.code, Q.state
    if QT.shape[0] > FEW:
        return find_top(Q)
    best = -1
    for j in range(QT.shape[0]):
        if QT[j] < INF and (best < 0 or _before(QT, QC, j, best)):
            best = j
    if best >= 0:
        QS[QS_AT] = _bucket(QT[best], Q.rate)
    QS[QS_TOP] = best
    return best


@njit(cache=True)
def find_top(Q):
    """The object of the first horizon (by time, then key), -1 if none has one; kept known in
    QS. Walks the buckets from the current one to the first holding a horizon of its own (not
    one of a later pass of the ring); after a whole ring without, looks at every object."""
    QT, QC, QL, QH, QS = Q.time, Q.code, Q.links, Q.heads, Q.state
    if QS[QS_FILED] == 0:
        QS[QS_TOP] = -1
        return -1
    mask = QH.shape[0] - 1
    at = QS[QS_AT]
    best = -1
    for _ in range(QH.shape[0] if QT.shape[0] > FEW else 0):
        j = int(QH[at & mask])
        while j >= 0:
            if _bucket(QT[j], Q.rate) == at and (best < 0 or _before(QT, QC, j, best)):
                best = j
            j = int(QL[j, Q_NEXT])
        if best >= 0:
            break
        at += 1
    if best < 0:  # a whole ring of slots without one (or few objects): look at every object
        for j in range(QT.shape[0]):
            if QT[j] < INF and (best < 0 or _before(QT, QC, j, best)):
                best = j
        at = _bucket(QT[best], Q.rate)
    QS[QS_AT] = at
    QS[QS_TOP] = best
    return best


@hot
def first_horizon(Q, bound):
    """The object of the horizon to take next: of those no later than `bound` (the first
    horizon's, at least; it is known), the one with the smallest key."""
    QT, QC, QL, QH, QS = Q.time, Q.code, Q.links, Q.heads, Q.state
    mask = QH.shape[0] - 1
    best = int(QS[QS_TOP])
    last = min(_bucket(bound, Q.rate), QS[QS_AT] + mask)  # a whole ring sees every slot
    for b in range(QS[QS_AT], last + 1):
        j = int(QH[b & mask])
        while j >= 0:
            if QT[j] <= bound and _order(QC, j) < _order(QC, best):
                best = j
            j = int(QL[j, Q_NEXT])
    return best
