"""How `collide2d bench` times things: the run lengths, repeats, and the timers every part uses.

A timed run aims at about TARGET_S seconds of stepping; an in-process probe of PROBE_S seconds
estimates a model's rate first. `cli_seconds` times `collide2d run` in a subprocess (what a user
runs), `drive_seconds` times `runner.run.drive` in this process; the median of REPEATS runs is
kept. `Echo` writes progress lines.

`measure` is how figures that are compared are timed, so that they can be trusted: a short
calibration first sets how many calls make one measure last at least MEASURE_S seconds (quick:
QUICK_MEASURE_S), then MEASURE_REPEATS measures of every function are taken in interleaved
rounds, A B ... then ... B A (A/B/A), so that a drift of the machine shows in every function
alike instead of in one; each gets a `Timing`: the median, min and max seconds per call, the
spread (max - min) / median, and `noisy` when the spread passes NOISY_SPREAD.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from pathlib import Path
from typing import NamedTuple

# Each timed run aims at about this many seconds of stepping (the 1-tick run is subtracted).
TARGET_S = 2.0
QUICK_TARGET_S = 0.05
REPEATS = 5
# `measure`: every measure lasts at least this long (s), repeated this many times; a spread past
# NOISY_SPREAD ((max - min) / median) marks the figure noisy.
MEASURE_S = 0.5
QUICK_MEASURE_S = 0.02
MEASURE_REPEATS = 5
NOISY_SPREAD = 0.20
# The in-process probe that estimates a rate runs this long (s), and so do the logged run that
# counts events and the staged run that times each stage.
PROBE_S = 0.2
QUICK_PROBE_S = 0.02


def median(values) -> float:
    return float(statistics.median(values))


def cli_seconds(path: Path, ticks: int, out: Path) -> float:
    """Wall time of `collide2d run PATH --ticks T` with nothing written but final.csv and summary,
    in a subprocess (`python -m collide2d`, what the console script runs), its kernels compiled
    (`--jit on`: the bench measures the compiled kernels, and the 1-tick run that start-up is
    measured by must take the same lane as the long one)."""
    import subprocess

    cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--no-gif", "--no-png"]
    # compiled whatever the length (runner.lanes would interpret the 1-tick run), so that the
    # 1-tick run subtracted holds the same start-up as the timed one
    cmd += ["--no-events", "--quiet", "--ticks", str(ticks), "--out", str(out), "--jit", "on"]
    began = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - began


def drive_seconds(text: str, ticks: int) -> float:
    """Seconds `runner.run.drive` takes over `ticks` ticks of the scenario text (loading not
    counted; model set-up counted, as in a run)."""
    from collide2d.runner.run import drive
    from collide2d.runner.scenario.load import loads

    scenario = loads(text, overrides={"ticks": ticks})
    began = time.perf_counter()
    drive(scenario)
    return time.perf_counter() - began


def probe_rate(model, seconds: float) -> float:
    """Ticks per second of `model.advance` (log off), from runs doubling until `seconds` long
    (after one untimed tick that loads the kernels)."""
    model.advance(1, log=False)
    ticks = 1
    while True:
        began = time.perf_counter()
        model.advance(ticks, log=False)
        spent = time.perf_counter() - began
        if spent >= seconds or ticks >= 1 << 20:
            return ticks / max(spent, 1e-9)
        ticks *= 2


def timed(fn) -> float:
    began = time.perf_counter()
    fn()
    return time.perf_counter() - began


def best_of(fn, repeats: int) -> float:
    """The shortest of `repeats` timings of fn() (s): skips compare like with like."""
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        fn()
        times.append(time.perf_counter() - began)
    return min(times)


class Echo:
    """Progress lines on stderr (nothing when quiet); on a terminal, below them, a bar of the
    `parts` done, drawn from the start (compiling the first part's kernels takes a while)."""

    def __init__(self, quiet: bool, parts: tuple[str, ...] = ()):
        from collide2d.runner.output.progress import Progress

        self.quiet = quiet
        self.parts = parts
        self.started = 0
        shown = parts and not quiet and sys.stderr.isatty()
        self.bar = Progress(len(parts), "bench", unit=" parts", waiting=True) if shown else None

    def __call__(self, text: str) -> None:
        if not self.quiet:
            from collide2d.runner.output.progress import say

            say(text)

    def part(self, name: str) -> None:
        """The part `name` starts: the parts before it are done."""
        if self.bar is not None:
            self.bar.label(f"bench: {name}")
            self.bar.update(self.started)
        self.started += 1

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


class Timing(NamedTuple):
    """Seconds per call of one function, from `measure`."""

    median: float
    low: float
    high: float
    calls: int  # calls per measure
    repeats: int  # measures

    @property
    def spread(self) -> float:
        """(max - min) / median."""
        return (self.high - self.low) / max(self.median, 1e-300)

    @property
    def noisy(self) -> bool:
        return self.spread > NOISY_SPREAD

    def row(self, prefix: str = "run_time") -> dict:
        """The bench.csv columns of this timing."""
        return {
            f"{prefix}_s": self.median,
            f"{prefix}_min_s": self.low,
            f"{prefix}_max_s": self.high,
            "repeats": self.repeats,
            "calls": self.calls,
            "spread": self.spread,
            "noisy": "yes" if self.noisy else "no",
        }


def measure(fns, quick: bool = False, repeats: int = MEASURE_REPEATS) -> list[Timing]:
    """Time each of `fns` (callables with no arguments) as the module docstring says; one Timing
    each, in order. Each function is called once first (a warm-up that also calibrates)."""
    least = QUICK_MEASURE_S if quick else MEASURE_S
    calls = []
    for fn in fns:
        began = time.perf_counter()
        fn()
        once = time.perf_counter() - began
        calls.append(max(1, math.ceil(least / max(once, 1e-9))))
    samples: list[list[float]] = [[] for _ in fns]
    for r in range(repeats):
        order = range(len(fns)) if r % 2 == 0 else range(len(fns) - 1, -1, -1)
        for i in order:
            began = time.perf_counter()
            for _ in range(calls[i]):
                fns[i]()
            samples[i].append((time.perf_counter() - began) / calls[i])
    return [
        Timing(median(s), min(s), max(s), c, repeats) for s, c in zip(samples, calls, strict=True)
    ]
