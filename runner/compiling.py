"""Seconds spent compiling numba kernels, kept apart from run time, and the first-run notice.

numba compiles a kernel the first time it runs with new argument types and keeps it in its cache
(next to the sources) for later processes; loading from that cache is quick and is not a
compilation. `install(notice)` registers a listener for numba's `numba:compile` event, which
numba raises only around a real compilation: from then on `seconds()` is the total time this
process spent compiling (nested compilations, a kernel compiling the kernels it calls, count
once), and `notice()`, when given, is called once, at the start of the first compilation (the CLI
prints "compiling kernels, first run only ..." on a terminal). With NUMBA_DISABLE_JIT=1 nothing
compiles and `seconds()` stays 0.

Kernels a cluster's worker process compiles (a sweep's, a check's with `--workers`) are not this
process's: `relay(tell)`, in the worker, calls `tell()` at the start of its first compilation (it
sends an event back, runner.sweep.cluster), and `told()`, here, gives the notice then, once for
the command whichever process compiles first.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from collide2d.engine import jit

_state = {"seconds": 0.0, "depth": 0, "started": 0.0, "installed": False, "notice": None}


def install(notice: Callable[[], None] | None = None) -> None:
    """Start counting compile time (once per process; from when numba loads, engine.jit: a run
    whose kernels are interpreted never loads it); `notice` replaces the one given before."""
    _state["notice"] = notice
    if _state["installed"]:
        return
    _state["installed"] = True
    jit.when_loaded(_listen)


def _listen() -> None:
    from numba.core import event

    class _Timer(event.Listener):
        def on_start(self, ev) -> None:
            if _state["depth"] == 0:
                _state["started"] = time.perf_counter()
                told, _state["notice"] = _state["notice"], None
                if told is not None:
                    told()
            _state["depth"] += 1

        def on_end(self, ev) -> None:
            _state["depth"] -= 1
            if _state["depth"] == 0:
                _state["seconds"] += time.perf_counter() - _state["started"]

    event.register("numba:compile", _Timer())


def seconds() -> float:
    """Seconds this process has spent compiling kernels since `install` (0 before it)."""
    return _state["seconds"]


def told() -> None:
    """Another process (a cluster's worker) started compiling: the notice, if not given yet."""
    notice, _state["notice"] = _state["notice"], None
    if notice is not None:
        notice()


def relay(tell: Callable[[], None]) -> None:
    """In a cluster's worker: `tell()` when this process starts compiling its first kernel. A
    worker in the command's own process (an in-process cluster) leaves this process's notice as it
    is: its compilations are counted and told here already."""
    if not _state["installed"]:
        install(tell)
