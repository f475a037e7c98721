"""The paper part of `collide2d bench`: the paper model on the section IV demo, three ways.

The demo (`scenarios/paper_fifty_boxes.yaml`) runs PAPER_TICKS ticks headless with the event log
off (the issue's target: at least 1,000,000 ticks/s), headless with it on, and through
`runner.run.drive` with no frames asked for (what `collide2d run --no-gif --no-events` does after
loading); the median of PAPER_REPEATS runs of each, after a warm-up call. Not a default part
(`--part paper`).
"""

from __future__ import annotations

from pathlib import Path

from collide2d.engine import models
from collide2d.runner.bench.scenes import DEMO_SCENARIO, PROJECT_SCENARIOS
from collide2d.runner.bench.timing import median, timed

PAPER_TICKS = 1_000_000
QUICK_PAPER_TICKS = 20_000
PAPER_REPEATS = 5


def demo_row(part: str, demo, ticks: int, rate: float, note: str) -> dict:
    """A bench row of the section IV demo run `ticks` ticks at `rate` ticks/s."""
    return {
        "part": part,
        "scene": DEMO_SCENARIO,
        "model": "paper",
        "n": demo.bodies.n,
        "ticks": ticks,
        "steps_per_s": rate,
        "value": rate,
        "note": note,
    }


def paper(quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """One row per way of running the demo: ticks/s (the demo is read from `folder`)."""
    from collide2d.runner.run import drive
    from collide2d.runner.scenario.load import load

    ticks = QUICK_PAPER_TICKS if quick else PAPER_TICKS
    repeats = 1 if quick else PAPER_REPEATS
    demo = load(folder / f"{DEMO_SCENARIO}.yaml", overrides={"ticks": ticks})
    models.make("paper", demo.world, demo.bodies).advance(2, log=False)  # load the kernels

    def headless(log: bool):
        return lambda: models.make("paper", demo.world, demo.bodies).advance(ticks, log)

    ways = [
        ("headless, no log, ticks/s (target >= 1,000,000)", headless(False)),
        ("headless, event log on, ticks/s", headless(True)),
        ("through runner.run.drive, no frames, ticks/s", lambda: drive(demo)),
    ]
    rows = []
    for what, run in ways:
        rate = ticks / median(timed(run) for _ in range(repeats))
        rows.append(demo_row("paper", demo, ticks, rate, what))
        echo(f"paper    {what:50s} {rate:14,.0f}")
    return rows
