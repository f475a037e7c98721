"""How `collide2d bench` times things: the run lengths, repeats, and the timers every part uses.

A timed run aims at about TARGET_S seconds of stepping; an in-process probe of PROBE_S seconds
estimates a model's rate first. `cli_seconds` times `collide2d run` in a subprocess (what a user
runs), `drive_seconds` times `runner.run.drive` in this process; the median of REPEATS runs is
kept (the shortest for the skips, which compare like with like). `Echo` writes progress lines.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

# Each timed run aims at about this many seconds of stepping (the 1-tick run is subtracted).
TARGET_S = 2.0
QUICK_TARGET_S = 0.05
REPEATS = 3
# The in-process probe that estimates a rate runs this long (s), and so do the logged run that
# counts events and the staged run that times each stage.
PROBE_S = 0.2
QUICK_PROBE_S = 0.02


def median(values) -> float:
    return float(statistics.median(values))


def cli_seconds(path: Path, ticks: int, out: Path) -> float:
    """Wall time of `collide2d run PATH --ticks T` with nothing written but final.csv and summary,
    in a subprocess (`python -m collide2d`, what the console script runs)."""
    import subprocess

    cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--no-gif", "--no-png"]
    cmd += ["--no-events", "--quiet", "--ticks", str(ticks), "--out", str(out)]
    began = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - began


def drive_seconds(text: str, ticks: int) -> float:
    """Seconds `runner.run.drive` takes over `ticks` ticks of the scenario text (loading not
    counted; model set-up counted, as in a run)."""
    from collide2d.runner.run import drive
    from collide2d.runner.scenario import loads

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
    """Progress lines on stderr (nothing when quiet)."""

    def __init__(self, quiet: bool):
        self.quiet = quiet

    def __call__(self, text: str) -> None:
        if not self.quiet:
            print(text, file=sys.stderr, flush=True)
