"""Progress on long runs: a tqdm bar on a terminal's stderr, nothing when piped or quiet.

`Progress.for_terminal(total, label)` returns a Progress only when stderr is a terminal (else None,
and callers skip it). The bar is tqdm's: it fits the terminal's width (following a resize), redraws
in place at most every REDRAW_S seconds, appears only once a run has lasted SHOW_AFTER_S seconds
and is erased when the run ends.
"""

from __future__ import annotations

import sys

from collide2d.runner.output import escape

# Seconds between redraws; runs shorter than SHOW_AFTER_S never show a bar.
REDRAW_S = 0.2
SHOW_AFTER_S = 0.5


class Progress:
    """A bar for `total` ticks (or other `unit`s: a sweep counts runs) written to `stream`."""

    def __init__(self, total: int, label: str, stream=None, unit: str = " ticks"):
        from tqdm import tqdm

        self.bar = tqdm(
            total=max(int(total), 1),
            desc=escape.one_line(label),
            unit=unit,
            # the terminal itself: the bar redraws its line with carriage returns of its own
            file=escape.raw(stream if stream is not None else sys.stderr),
            dynamic_ncols=True,
            leave=False,
            mininterval=REDRAW_S,
            delay=SHOW_AFTER_S,
        )
        self.done = 0

    @classmethod
    def for_terminal(cls, total: int, label: str) -> Progress | None:
        stream = sys.stderr
        return cls(total, label, stream) if stream.isatty() else None

    def update(self, done: int) -> None:
        """`done` ticks of the total are run."""
        if done > self.done:
            self.bar.update(done - self.done)
            self.done = done

    def close(self) -> None:
        self.bar.close()
