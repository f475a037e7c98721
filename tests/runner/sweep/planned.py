"""The sweep tests' view of a small plan: every run checked, with its scenario loaded (as a worker
has it), which a sweep itself never holds all at once."""

from __future__ import annotations

from collide2d.runner.sweep import plan, seedcheck


class Loaded:
    """One run of a checked plan and its scenario."""

    def __init__(self, checked, run):
        self.run = run
        self.index = run.index
        self.params = run.params
        self.scenario = checked.scenario(run)


def expand(paths, axes, seeds, limits=None) -> list[Loaded]:
    """Every run of the matrix, in order, each checked as a sweep checks it before sending it
    (its seed's drawing), with its scenario."""
    checked = plan.check(paths, axes, seeds, limits)
    for run in checked.runs():
        seedcheck.check_run(checked, run)
    return [Loaded(checked, run) for run in checked.runs()]


# three 10 px boxes in a 20 px world: only some seeds place them all (4 does, 5 and 154 do not)
CRAMPED = """version: 1
world: {width: 20, height: 20}
model: paper
ticks: 1
generate:
  - {count: 3, shape: box, size: 10, speed: 10, seed: 0}
"""
