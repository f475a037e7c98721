"""Progress on long runs: a tqdm bar on a terminal's stderr, nothing when piped or quiet.

`Progress.for_terminal(total, label)` returns a Progress only when stderr is a terminal (else None,
and callers skip it). The bar is tqdm's: it fits the terminal's width (following a resize), redraws
in place at most every REDRAW_S seconds, appears only once a run has lasted SHOW_AFTER_S seconds
and is erased when the run ends. A bar made with `waiting=True` (a sweep's, a check's on a
cluster: many seconds may pass before the first run is done, compiling kernels) is drawn at once
and redrawn every TICK_S seconds while nothing finishes, so its clock runs from the start.
`say(line)` prints a line on stderr above the open bars (the compile notice), which are drawn
again below it.
"""

from __future__ import annotations

import sys
import threading

from collide2d.runner.output import escape

# Seconds between redraws; runs shorter than SHOW_AFTER_S never show a bar.
REDRAW_S = 0.2
SHOW_AFTER_S = 0.5
# Seconds between redraws of a waiting bar while nothing is done (its elapsed time).
TICK_S = 1.0

_open: list[Progress] = []  # the bars drawn now, for `say`
_lock = threading.Lock()


class Progress:
    """A bar for `total` ticks (or other `unit`s: a sweep counts runs) written to `stream`."""

    def __init__(
        self,
        total: int,
        label: str,
        stream=None,
        unit: str = " ticks",
        waiting: bool = False,
        bar_format: str | None = None,
    ):
        from tqdm import tqdm

        self.stream = stream if stream is not None else sys.stderr
        self.bar = tqdm(
            total=max(int(total), 1),
            desc=escape.one_line(label),
            unit=unit,
            # the terminal itself: the bar redraws its line with carriage returns of its own
            file=escape.raw(self.stream),
            dynamic_ncols=True,
            leave=False,
            mininterval=REDRAW_S,
            delay=0 if waiting else SHOW_AFTER_S,
            bar_format=bar_format,
        )
        self.done = 0
        self._stop = threading.Event()
        with _lock:
            _open.append(self)
        if waiting:
            threading.Thread(target=self._tick, name="collide2d-progress", daemon=True).start()

    @classmethod
    def for_terminal(cls, total: int, label: str) -> Progress | None:
        stream = sys.stderr
        return cls(total, label, stream) if stream.isatty() else None

    def _tick(self) -> None:
        while not self._stop.wait(TICK_S):
            with _lock:
                if not self._stop.is_set():
                    self.bar.refresh()

    def update(self, done: int) -> None:
        """`done` ticks of the total are run."""
        if done > self.done:
            with _lock:
                self.bar.update(done - self.done)
            self.done = done

    def label(self, text: str) -> None:
        """The bar's label is now `text` (a bench's part), drawn at once."""
        with _lock:
            self.bar.set_description(escape.one_line(text))

    def close(self) -> None:
        self._stop.set()
        with _lock:
            if self in _open:
                _open.remove(self)
            self.bar.close()


def say(line: str, stream=None) -> None:
    """Print `line` on `stream` (stderr) above the bars drawn now, which are drawn again after."""
    stream = stream if stream is not None else sys.stderr
    with _lock:
        for p in _open:
            p.bar.clear()
        print(line, file=stream, flush=True)
        for p in _open:
            p.bar.refresh()
