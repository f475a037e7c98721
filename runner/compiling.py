"""Seconds spent compiling numba kernels, kept apart from run time, and what watches them compile.

numba compiles a kernel the first time it runs with new argument types and keeps it in its cache
(next to the sources) for later processes; loading from that cache is quick and is not a
compilation. `install(watcher)` registers a listener for numba's `numba:compile` event, which
numba raises only around a real compilation: from then on `seconds()` is the total time this
process spent compiling (nested compilations, a kernel compiling the kernels it calls, count
once), and the `Watcher`, when given, hears each burst of compiling begin and end and each kernel
compiled in it (the CLI's notice, runner.command.compilenotice: a line saying what compiles and
about how long it takes, then a bar of that work done). With NUMBA_DISABLE_JIT=1 nothing compiles
and `seconds()` stays 0.

Kernels a cluster's worker process compiles (a sweep's, a check's with `--workers`) are not this
process's: `relay(tell)`, in the worker, calls `tell()` at the start of its first compilation (it
sends an event back, runner.sweep.cluster), and `told()`, here, begins a burst named "" for the
watcher then, once for the command whichever process compiles first.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Protocol

from collide2d.engine import jit

_state = {
    "seconds": 0.0,
    "depth": 0,
    "started": 0.0,
    "installed": False,
    "watcher": None,
    "expected": None,
}


class Watcher(Protocol):
    """What hears kernels compile, each named `module.qualname` ("" for another process's)."""

    def begin(self, kernel: str) -> None:
        """A burst of compiling begins, with `kernel` (the burst's outermost)."""

    def compiled(self, kernel: str) -> None:
        """`kernel` is compiled (the kernels it calls are told first)."""

    def end(self) -> None:
        """The burst is over: this process runs compiled kernels again."""


def install(watcher: Watcher | None = None) -> None:
    """Start counting compile time (once per process; from when numba loads, engine.jit: a run
    whose kernels are interpreted never loads it); `watcher` replaces the one given before."""
    _state["watcher"] = watcher
    if _state["installed"]:
        return
    _state["installed"] = True
    jit.when_loaded(_listen)


def _kernel(ev) -> str:
    """The module.qualname of the kernel a `numba:compile` event is about ("" when unknown)."""
    func = getattr((ev.data or {}).get("dispatcher"), "py_func", None)
    return f"{func.__module__}.{func.__qualname__}" if func is not None else ""


def _listen() -> None:
    from numba.core import event

    class _Timer(event.Listener):
        def on_start(self, ev) -> None:
            if _state["depth"] == 0:
                _state["started"] = time.perf_counter()
                if _state["watcher"] is not None:
                    _state["watcher"].begin(_kernel(ev))
            _state["depth"] += 1

        def on_end(self, ev) -> None:
            _state["depth"] -= 1
            watcher = _state["watcher"]
            if watcher is not None:
                watcher.compiled(_kernel(ev))
            if _state["depth"] == 0:
                _state["seconds"] += time.perf_counter() - _state["started"]
                if watcher is not None:
                    watcher.end()

    event.register("numba:compile", _Timer())


def seconds() -> float:
    """Seconds this process has spent compiling kernels since `install` (0 before it)."""
    return _state["seconds"]


def expect(cold: float, kernels: set[str]) -> None:
    """The next burst of compiling, when it begins with one of `kernels` (module.qualname), is
    expected to take `cold` of the measured table's seconds (runner.compilecost): a run's lane
    knows the kernels it has called when it switches."""
    _state["expected"] = (cold, kernels)


def expected(kernel: str) -> float | None:
    """What `expect` said of the burst beginning now with `kernel` (None: nothing, or of other
    kernels: a lane whose kernels were all cached compiled none); said once."""
    said, _state["expected"] = _state["expected"], None
    return said[0] if said is not None and kernel in said[1] else None


def told() -> None:
    """Another process (a cluster's worker) started compiling: a burst named "" for the watcher."""
    if _state["watcher"] is not None:
        _state["watcher"].begin("")


class _Relay:
    """A worker's watcher: `tell()` at the start of its first compilation, nothing after."""

    def __init__(self, tell: Callable[[], None]):
        self.tell: Callable[[], None] | None = tell

    def begin(self, kernel: str) -> None:
        tell, self.tell = self.tell, None
        if tell is not None:
            tell()

    def compiled(self, kernel: str) -> None:
        pass

    def end(self) -> None:
        pass


def relay(tell: Callable[[], None]) -> None:
    """In a cluster's worker: `tell()` when this process starts compiling its first kernel. A
    worker in the command's own process (an in-process cluster) leaves this process's watcher as
    it is: its compilations are counted and told here already."""
    if not _state["installed"]:
        install(_Relay(tell))
