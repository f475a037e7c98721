"""The bounds on what a scenario may ask for (docs/limits.md), each one a command-line option.

`Limits` is read by the safe YAML reader (`runner.scenario.parse`: file size, YAML values, aliases),
by the scenario readers (objects, ticks, world sides, frames) and by the run
(`runner.output.budget`: output bytes, frame memory; `runner.run`: the event log's share of the
output bytes). It depends on nothing, so any module may import it. Each bound is a whole number of
at least 1, as its `--max-*` option takes (a numpy integer is kept as the int it is): a bound of
another type is a TypeError, one below 1 a ValueError, naming it (docs/reference/api.md).
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, fields


@dataclass(frozen=True)
class Limits:
    """Bounds on what a scenario may ask for; each is a command-line option."""

    max_objects: int = 1_000_000
    max_ticks: int = 10**9
    max_side: int = 16384  # px per world side
    max_alias_nodes: int = 10_000  # YAML nodes reached a second time or more through aliases
    max_output_bytes: int = 4 * 2**30  # bytes of frame files (PNG, GIF) and event log on disk
    max_frame_bytes: int = 2**30  # bytes of one frame in memory: width x height x scale^2 x 3
    max_frames: int = 1_000_000  # frames one `frames` entry may ask for, and a run may write
    max_file_bytes: int = 64 * 2**20  # bytes of a scenario file (it is read whole)
    max_yaml_nodes: int = 2_000_000  # YAML values in a file: each costs memory when composed

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            try:  # an int or a numpy integer; not a bool, not a float
                number = operator.index(value) if not isinstance(value, bool) else None
            except TypeError:
                number = None
            if number is None:
                said = repr(value)[:60]
                raise TypeError(
                    f"{f.name}={said}: expected a whole number, not {type(value).__name__}"
                )
            try:
                str(number)  # a message that names the bound writes it out
            except ValueError:
                raise ValueError(f"{f.name}: a whole number too long to write out") from None
            if number < 1:
                raise ValueError(f"{f.name}={number}: must be at least 1")
            object.__setattr__(self, f.name, number)
