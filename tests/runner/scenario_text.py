"""Scenario texts for the tests of the scenario readers, and where a refusal must point."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from collide2d.runner.scenario.load import ScenarioError, loads

DATA = Path(__file__).parent / "data"
BASE = "version: 1\nworld: {width: 100, height: 80, fps: 10}\n"


def at(text: str, needle: str, nth: int = 0) -> tuple[int, int]:
    """1-based (line, column) of the nth occurrence of needle in text."""
    index = -1
    for _ in range(nth + 1):
        index = text.index(needle, index + 1)
    line = text.count("\n", 0, index) + 1
    col = index - (text.rfind("\n", 0, index) + 1) + 1
    return line, col


def refused(text: str, **kw) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        loads(text, **kw)
    return info.value


def check_refused(text: str, needle: str, fragment: str, nth: int = 0, **kw) -> ScenarioError:
    """The text is refused at the nth occurrence of needle, with fragment in the message."""
    err = refused(text, **kw)
    assert (err.line, err.col) == at(text, needle, nth), str(err)
    assert fragment in err.message, str(err)
    assert str(err) == f"<string>:{err.line}:{err.col}: error: {err.message}"
    return err


def objects(*lines: str, head: str = BASE) -> str:
    return head + "objects:\n" + "".join(f"  - {line}\n" for line in lines)


def any_overlap(pos, size) -> bool:
    """Whether any two boxes overlap, by an all-pairs array comparison (n up to a few thousand)."""
    lo, hi = pos, pos + size
    over = (
        (lo[:, None, 0] < hi[None, :, 0])
        & (lo[None, :, 0] < hi[:, None, 0])
        & (lo[:, None, 1] < hi[None, :, 1])
        & (lo[None, :, 1] < hi[:, None, 1])
    )
    np.fill_diagonal(over, False)
    return bool(over.any())
