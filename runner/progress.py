"""Progress on long runs: a one-line bar on a terminal's stderr, nothing when piped or quiet.

`Progress.for_terminal(total, label)` returns a Progress only when stderr is a terminal (else None,
and callers skip it). The bar redraws at most every REDRAW_S seconds so it costs nothing measurable.
"""

from __future__ import annotations

import sys
import time

# Seconds between redraws; runs shorter than SHOW_AFTER_S never show a bar.
REDRAW_S = 0.2
SHOW_AFTER_S = 0.5
BAR_WIDTH = 30


class Progress:
    """A bar for `total` steps written to `stream`."""

    def __init__(self, total: int, label: str, stream=None):
        self.total = max(int(total), 1)
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.started = time.monotonic()
        self.last = 0.0
        self.shown = False

    @classmethod
    def for_terminal(cls, total: int, label: str) -> Progress | None:
        stream = sys.stderr
        return cls(total, label, stream) if stream.isatty() else None

    def update(self, done: int) -> None:
        now = time.monotonic()
        if now - self.started < SHOW_AFTER_S or now - self.last < REDRAW_S:
            return
        self.last = now
        self.shown = True
        self.stream.write("\r" + self.line(done, now - self.started))
        self.stream.flush()

    def line(self, done: int, elapsed: float) -> str:
        frac = min(max(done / self.total, 0.0), 1.0)
        filled = int(frac * BAR_WIDTH)
        bar = "#" * filled + "-" * (BAR_WIDTH - filled)
        rate = done / elapsed if elapsed > 0 else 0.0
        eta = (self.total - done) / rate if rate > 0 else 0.0
        return f"{self.label} [{bar}] {frac:6.1%} {done}/{self.total} ticks, {eta:5.1f}s left"

    def close(self) -> None:
        if self.shown:
            self.stream.write("\r" + " " * (len(self.line(self.total, 1.0)) + 2) + "\r")
            self.stream.flush()
