"""Which frames a run draws, as a rule rather than a list: none, all, every k-th, last, listed.

A run may have up to a billion ticks, so nothing here is sized by `ticks`: a `FrameRule` answers
how many frames it holds (`len`), whether it holds frame k (`in`), and the first frame it holds at
or after k (`next_from`), all by arithmetic; iterating it yields the frames one by one. Only a
`list` rule keeps its numbers, and those were written out in the scenario file (bounded by the
file's limits and by `--max-frames`).
"""

from __future__ import annotations

import bisect
import operator
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

KINDS = ("none", "all", "every", "last", "list")


@dataclass(frozen=True)
class FrameRule:
    """The frames 0..ticks a rule selects. Build one with the class methods below."""

    kind: str  # one of KINDS
    ticks: int  # the run's last frame number
    every: int = 1  # the step of an "every" rule (1 for "all")
    listed: tuple[int, ...] = ()  # a "list" rule's frames, sorted, unique, within 0..ticks

    @classmethod
    def none(cls, ticks: int) -> FrameRule:
        return cls("none", int(ticks))

    @classmethod
    def all(cls, ticks: int) -> FrameRule:
        return cls("all", int(ticks))

    @classmethod
    def every_k(cls, k: int, ticks: int) -> FrameRule:
        if k < 1:
            raise ValueError(f"every must be at least 1, got {k}")
        return cls("all", int(ticks)) if k == 1 else cls("every", int(ticks), every=int(k))

    @classmethod
    def last(cls, ticks: int) -> FrameRule:
        return cls("last", int(ticks))

    @classmethod
    def of(cls, frames: Iterable[int], ticks: int) -> FrameRule:
        """A list rule of the given frame numbers that lie in 0..ticks (duplicates dropped)."""
        listed = tuple(sorted({int(k) for k in frames if 0 <= int(k) <= ticks}))
        return cls("list", int(ticks), listed=listed)

    def next_from(self, k: int) -> int | None:
        """The first frame of the rule at or after frame k, or None when there is none."""
        k = max(int(k), 0)
        if k > self.ticks or self.kind == "none":
            return None
        if self.kind == "last":
            return self.ticks
        if self.kind == "list":
            i = bisect.bisect_left(self.listed, k)
            return self.listed[i] if i < len(self.listed) else None
        step = self.every if self.kind == "every" else 1
        f = -(-k // step) * step
        return f if f <= self.ticks else None

    def __len__(self) -> int:
        if self.kind == "none":
            return 0
        if self.kind == "last":
            return 1
        if self.kind == "list":
            return len(self.listed)
        return self.ticks // (self.every if self.kind == "every" else 1) + 1

    def __contains__(self, k: object) -> bool:
        try:
            k = operator.index(k)
        except TypeError:
            return False
        return self.next_from(k) == k

    def __iter__(self) -> Iterator[int]:
        k = self.next_from(0)
        while k is not None:
            yield k
            k = self.next_from(k + 1)

    def __bool__(self) -> bool:
        return len(self) > 0
