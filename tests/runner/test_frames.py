"""Frame rules: every question answered by arithmetic agrees with the frames written out."""

from __future__ import annotations

import time
import tracemalloc

from hypothesis import given
from hypothesis import strategies as st

from collide2d.runner.scenario.frames import FrameRule


def rules(ticks: int):
    return st.one_of(
        st.just(FrameRule.none(ticks)),
        st.just(FrameRule.all(ticks)),
        st.just(FrameRule.last(ticks)),
        st.integers(1, ticks + 3).map(lambda k: FrameRule.every_k(k, ticks)),
        st.lists(st.integers(-3, ticks + 3), max_size=12).map(lambda f: FrameRule.of(f, ticks)),
    )


def written_out(rule: FrameRule) -> list[int]:
    """The frames of a rule by its definition, one frame at a time."""
    t = rule.ticks
    if rule.kind == "none":
        return []
    if rule.kind == "last":
        return [t]
    if rule.kind == "list":
        return list(rule.listed)
    return [k for k in range(t + 1) if k % rule.every == 0]


@given(st.integers(0, 60).flatmap(lambda t: rules(t)))
def test_a_rule_answers_as_its_frames_written_out(rule):
    frames = written_out(rule)
    assert list(rule) == frames
    assert len(rule) == len(frames) and bool(rule) == bool(frames)
    for k in range(-2, rule.ticks + 3):
        assert (k in rule) == (k in frames)
        after = [f for f in frames if f >= k]
        assert rule.next_from(k) == (after[0] if after else None)


def test_a_list_rule_keeps_frames_within_the_run_once_each():
    rule = FrameRule.of([12, 0, 6, 6, 13, -1], ticks=12)
    assert rule.listed == (0, 6, 12)


def test_a_billion_frames_are_counted_and_walked_without_a_list():
    tracemalloc.start()
    start = time.perf_counter()
    rule = FrameRule.every_k(7, 10**9)
    assert len(rule) == 10**9 // 7 + 1
    assert rule.next_from(10**9 - 10) == 999_999_994 and 999_999_994 in rule
    assert rule.next_from(999_999_995) is None
    assert len(FrameRule.all(10**9)) == 10**9 + 1 and FrameRule.all(10**9).next_from(5) == 5
    first = [k for k, _ in zip(FrameRule.all(10**9), range(3), strict=False)]
    seconds = time.perf_counter() - start
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert first == [0, 1, 2]
    assert seconds < 0.1 and peak < 100_000, (seconds, peak)
