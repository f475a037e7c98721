"""A scene that splits runs split or on one thread, whichever the clock says is faster, timing the
other way now and then; the ticks run are those asked for, in order, and a model gives the same
bytes whichever way each stretch of ticks went."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.engine import splitchoice
from collide2d.engine.models import make
from collide2d.engine.splitchoice import SplitChoice
from collide2d.engine.world import Bodies, WorldSpec


class Machine:
    """A fake clock: a tick costs `cost[chunks]` seconds; `go` records what ran."""

    def __init__(self, cost):
        self.cost = dict(cost)
        self.now = 0.0
        self.calls = []

    def clock(self):
        return self.now

    def go(self, ticks, chunks):
        self.calls.append((ticks, chunks))
        self.now += ticks * self.cost[chunks]
        return len(self.calls)


def ticks_by_way(calls):
    out = {}
    for ticks, chunks in calls:
        out[chunks] = out.get(chunks, 0) + ticks
    return out


def test_the_ticks_asked_for_run_once_each_in_calls_in_order():
    machine = Machine({1: 1e-3, 2: 6e-4})
    choice = SplitChoice(2, machine.clock)
    results = choice.run(5_000, machine.go)
    assert sum(t for t, _ in machine.calls) == 5_000
    assert results == list(range(1, len(machine.calls) + 1))
    assert machine.calls[0] == (1, 2)  # the first call, which loads the kernels, is one tick
    assert all(t >= 1 for t, _ in machine.calls)


def test_when_the_split_is_faster_it_runs_nearly_every_tick():
    machine = Machine({1: 1e-3, 2: 6e-4})
    choice = SplitChoice(2, machine.clock)
    choice.run(50_000, machine.go)
    ran = ticks_by_way(machine.calls)
    assert choice.way == 2
    assert choice.per_tick == pytest.approx({1: 1e-3, 2: 6e-4})
    assert ran[1] < 0.02 * 50_000  # one thread only in the phases that time it
    # those phases come less often as one thread keeps losing: at most PROBE_MAX phases apart
    probes = [i for i, (_, c) in enumerate(machine.calls) if c == 1]
    assert len(probes) < 20


def test_when_one_thread_is_faster_the_split_is_only_timed_now_and_then():
    machine = Machine({1: 1e-3, 2: 5e-3})  # the split waits on a busy core
    choice = SplitChoice(2, machine.clock)
    choice.run(50_000, machine.go)
    ran = ticks_by_way(machine.calls)
    assert choice.way == 1
    assert ran[2] < 0.02 * 50_000
    split_seconds = ran[2] * 5e-3
    assert split_seconds < 0.1 * machine.now  # the probes cost a bounded share of the run


def test_the_choice_follows_a_machine_that_gets_busy_and_free_again():
    machine = Machine({1: 1e-3, 2: 6e-4})
    choice = SplitChoice(2, machine.clock)
    choice.run(2_000, machine.go)
    assert choice.way == 2
    machine.cost[2] = 4e-3  # another process takes the second core
    choice.run(20_000, machine.go)
    assert choice.way == 1
    machine.cost[2] = 6e-4  # and leaves it
    choice.run(60_000, machine.go)
    assert choice.way == 2


def test_many_short_calls_add_up_to_phases():
    # one tick per call (a frame drawn every tick): the phases span calls and still choose
    machine = Machine({1: 1e-3, 2: 5e-3})
    choice = SplitChoice(2, machine.clock)
    for _ in range(3_000):
        choice.run(1, machine.go)
    assert choice.way == 1 and len(machine.calls) == 3_000
    assert ticks_by_way(machine.calls)[2] < 300


def test_a_scene_that_does_not_split_runs_in_one_call():
    machine = Machine({1: 1e-3, 2: 1e-3})
    choice = SplitChoice(1, machine.clock)
    assert choice.run(12_345, machine.go) == [1]
    assert machine.calls == [(12_345, 1)]
    assert SplitChoice(2, machine.clock).run(0, machine.go) == [2]  # no ticks: one call


def gas(n, seed):
    rng = np.random.default_rng(seed)
    world = WorldSpec(240, 180, 30)
    cells = rng.choice(26 * 20, n, replace=False)
    pos = np.stack([cells % 26 * 9.0, cells // 26 * 9.0], 1)
    vel = rng.uniform(-300, 300, (n, 2))
    if n:
        vel[0] = 0.0
    return world, Bodies.boxes(pos, [6, 5], vel, mass=rng.uniform(0.5, 3, n))


@pytest.mark.parametrize("model", ["stepped", "paper"])
def test_a_run_whose_stretches_alternate_ways_gives_the_bytes_of_one_thread(model, monkeypatch):
    # every phase one tick, the other way timed after each: the run goes split, one thread,
    # split ... and still gives the bytes of a run on one thread in one call
    from collide2d.engine.models.paper import model as paper_model
    from collide2d.engine.models.stepped import model as stepped_model

    world, bodies = gas(300, 5)
    if model == "paper":
        bodies = Bodies.boxes(np.round(bodies.pos), [6, 5], np.round(bodies.vel / 30) * 30)

    def run(chunks, alternate):
        monkeypatch.setattr(stepped_model, "chunks_for", lambda n: chunks)
        monkeypatch.setattr(paper_model, "chunks_for", lambda n: chunks)
        m = make(model, world, bodies)
        ways = []
        go = m._advance if model == "stepped" else m._ticks
        if model == "stepped":
            m._advance = lambda k, log, c: (ways.append(c), go(k, log, c))[1]
        else:
            m._ticks = lambda k, log, c: (ways.append(c), go(k, log, c))[1]
        if alternate:
            monkeypatch.setattr(splitchoice, "PHASE_S", 0.0)
            monkeypatch.setattr(splitchoice, "PROBE_S", 0.0)
            monkeypatch.setattr(splitchoice, "PHASE_MIN_TICKS", 1)
            monkeypatch.setattr(splitchoice, "PROBE_EVERY", 1)
            monkeypatch.setattr(splitchoice, "PROBE_MAX", 1)
        events = m.advance(60)
        monkeypatch.undo()
        return (events.tobytes(), m.positions().tobytes(), m.velocities().tobytes()), ways

    one, ways_one = run(1, False)
    mixed, ways = run(3, True)
    assert set(ways_one) == {1} and len(ways_one) == 1
    assert ways.count(3) >= 5 and ways.count(1) >= 5, ways  # both ways ran, many times
    assert len(one[0]) > 1000  # walls and pairs were logged
    assert mixed == one
