"""How many threads the kernels may use, and from what size a stage splits its work among them.

The stages that split their work (the stepped model's move, narrow phase and relist, the
rasteriser's full redraw) cut it into a fixed number of contiguous chunks, run the chunks on
numba's threads (`prange`), and join the chunks' results in chunk order: every chunk does exactly
the arithmetic one thread would do on its share, so results are the same bytes with one thread or
many. A stage splits only for scenes of at least PARALLEL_MIN_OBJECTS objects (below that,
starting the threads costs more than they save) and only when more than one thread is allowed.

`shares_total` and `join_shares` join a split stage's results: each chunk writes into its own
share of one buffer, and the shares are moved together in chunk order.

`set_threads(n)` is the one switch: it sets numba's thread count for the kernels and the number
of chunks the models and the renderer made after it use. The command line's `--threads N` (and
`[tool.collide2d] threads`) go through `request(n)`, which waits until numba is loaded: a run whose
kernels are interpreted (engine.jit) never loads it. Interpreted, prange is range and the chunks
run one after another, with the same results.
"""

from __future__ import annotations

import os

from collide2d.engine.jit import njit, numba_module, when_loaded

# Threads waiting at the end of a split stage spin a short while (GNU OpenMP's GOMP_SPINCOUNT
# turns of a pause loop, up to a few hundred microseconds), then sleep. Woken from sleep, a thread
# took about 60 us per split stage on a 2-core virtual machine (a 100,000-object move of 90 us
# went to 100 us on two threads, and to 48 us spinning); spinning without end (OpenMP's ACTIVE)
# took a split stage ten times as long as one thread when the machine was busy (load 9). Even the
# short spin loses to one thread on a busy machine, so the models time both ways as they run and
# keep the faster (engine.splitchoice). Set before numba starts its threads; values the user set
# are kept.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
os.environ.setdefault("GOMP_SPINCOUNT", "10000")

# Objects from which a stage splits its work among threads (tuned on the standard scene of
# `collide2d bench`: on 2 cores a split step of 10,000 boxes took 12.5 ns per box against 13.6 on
# one thread, both models; at 5,000 the two were even).
PARALLEL_MIN_OBJECTS = 8_000

_threads: int | None = None  # None: every core numba may use


def available() -> int:
    """The most threads numba may run here (its NUMBA_NUM_THREADS, every core by default)."""
    from numba import config  # imported only here: an interpreted run never asks

    return max(1, int(config.NUMBA_NUM_THREADS))


def set_threads(n: int | None) -> int:
    """Let the kernels use n threads (None: all cores); returns the number in force (n clipped to
    what numba may run). ValueError for n < 1."""
    global _threads
    if n is not None and (int(n) != n or n < 1):
        raise ValueError(f"threads must be a whole number >= 1, got {n!r}")
    count = available() if n is None else min(int(n), available())
    _threads = count
    if not _jit_disabled():
        numba_module().set_num_threads(count)
    return count


def request(n: int | None) -> None:
    """`set_threads(n)` when numba loads (now if it is loaded): an interpreted run never loads it.
    ValueError for n < 1."""
    if n is not None and (int(n) != n or n < 1):
        raise ValueError(f"threads must be a whole number >= 1, got {n!r}")
    when_loaded(lambda: set_threads(n))


def threads() -> int:
    """Threads the kernels may use now."""
    return available() if _threads is None else _threads


def chunks_for(n_objects: int) -> int:
    """How many chunks a stage over n_objects objects splits into: the thread count for a scene of
    PARALLEL_MIN_OBJECTS objects or more, else 1 (no split)."""
    if n_objects < PARALLEL_MIN_OBJECTS:
        return 1
    t = threads()
    return t if t > 1 else 1


def _jit_disabled() -> bool:
    return os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0")


@njit(cache=True)
def shares_total(found, share, room):
    """The results of a split stage whose chunk c wrote found[c] items into its own share of
    `share` slots: how many in all, or more than `room` (the caller grows its buffer and asks
    again) when a chunk found more than its share held."""
    total = 0
    fits = True
    for c in range(found.shape[0]):
        total += found[c]
        fits = fits and found[c] <= share
    return total if fits else max(total, room + 1)


@njit(cache=True)
def join_shares(found, share, out):
    """Move the chunks' shares of `out` together in chunk order (chunk c's found[c] items from
    c * share); returns how many."""
    k = 0
    for c in range(found.shape[0]):
        for r in range(found[c]):
            out[k + r] = out[c * share + r]
        k += found[c]
    return k
