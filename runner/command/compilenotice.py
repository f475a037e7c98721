"""The compile notice on a terminal: what compiles, about how long it takes, and a bar of it done.

A command that runs kernels (`COMPILING_COMMANDS`) installs a `CompileNotice` as the watcher of
numba's compilations (runner.compiling) when stderr is a terminal and it is not `--quiet`. The
first time kernels of a kind compile (those loading a scenario, a model's, those drawing frames)
it says so once, above any bar drawn, with about how long that takes on this machine:

    compiling the stepped model's kernels, first run only: about 45 s (numba caches them for
    later runs) …

The estimate is runner.compilecost's measured table of each kernel's compile seconds, scaled to
how fast a core of this machine runs Python now: for a run whose lane switched to compiled
kernels (runner.lanes, `--jit auto`), the kernels it called; else every kernel of that kind (the
model's and the shared ones), those the wheel ships left out. Then, while the burst lasts, a bar
counts the table's seconds of the kernels compiled so far against that estimate, redrawn every
second while one kernel compiles for long, and erased when the burst ends. A burst a cluster's
worker begins (a sweep's) is only said: its kernels compile in another process.
"""

from __future__ import annotations

from collide2d.runner import compilecost, compiling
from collide2d.runner.output import progress

# Seconds of compiling expected below which a burst shows no bar (a kernel or two).
BAR_FROM_S = 2.0
# The bar: seconds of compiling done of those expected, and the time it has taken so far.
BAR = "{desc}: {percentage:3.0f}%|{bar}| {n}/{total} s [{elapsed}]"


class CompileNotice:
    """runner.compiling's watcher for a terminal (see the module docstring)."""

    def __init__(self) -> None:
        self.said: set[str] = set()  # what the notice said compiles
        self.bar: progress.Progress | None = None
        self.expected = 0.0  # table seconds of the kernels the burst is expected to compile
        self.done = 0.0  # table seconds of the kernels compiled in the burst so far
        self.factor = 1.0  # runner.compilecost.speed_factor() when the burst began

    def begin(self, kernel: str) -> None:
        what, cold = compilecost.burst(kernel)
        known = compiling.expected(kernel)  # a run's lane knows the kernels it called
        cold = cold if known is None or not kernel else known
        if what not in self.said:
            self.said.add(what)
            progress.say(line(what, cold * compilecost.speed_factor() if cold else 0.0))
        if kernel and cold * compilecost.speed_factor() >= BAR_FROM_S:
            self.factor = compilecost.speed_factor()
            self.expected, self.done = cold, 0.0
            self.bar = progress.Progress(
                round(cold * self.factor), f"compiling {what}", waiting=True, bar_format=BAR
            )

    def compiled(self, kernel: str) -> None:
        if self.bar is None:
            return
        self.done += compilecost.table()["kernels"].get(kernel, compilecost.UNKNOWN_KERNEL_S)
        done = round(min(self.done, self.expected) * self.factor)
        self.bar.update(min(done, self.bar.bar.total - 1))  # full only once the burst is over

    def end(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def line(what: str, seconds: float) -> str:
    """The notice's one line: `what` compiles, in about `seconds` (0: not known)."""
    about = f": about {seconds:.0f} s" if seconds >= 1 else ""
    return f"compiling {what}, first run only{about} (numba caches them for later runs) …"
