"""runner.stress.cases: the verdicts on models that break each invariant on purpose.

`FakeModel` (also used by test_cli) has the surface of engine.models and breaks one invariant at a
chosen tick."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collide2d.engine.events import EV_WALL, EVENT_DTYPE
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner.stress import cases, checks
from collide2d.runner.stress.scenes import Scene


class FakeModel:
    """A model surface (engine.models) whose boxes drift right at 1 px per tick, with a hook that
    breaks one invariant at a chosen tick."""

    def __init__(self, world, bodies, breaks=None, at=3):
        self.tick = 0
        self.pos = bodies.pos.copy()
        self.vel = bodies.vel.copy()
        self.breaks = breaks
        self.at = at

    def advance(self, ticks, log=True):
        events = []
        for _ in range(ticks):
            if self.breaks is not None and self.tick + 1 >= self.at:
                events += self.breaks(self) or []  # may raise, as a runaway does
            self.tick += 1
        out = np.zeros(len(events), EVENT_DTYPE)
        for i, (tick, kind, a) in enumerate(events):
            out[i]["tick"], out[i]["type"], out[i]["a"], out[i]["b"] = tick, kind, a, -1
        return out

    def positions(self):
        return self.pos.copy()

    def velocities(self):
        return self.vel.copy()


def small_scene(models=("exact",), expect_stop=(), static=None, ticks=6) -> Scene:
    bodies = Bodies.boxes([[10.0, 10.0], [40.0, 10.0]], 5, [[3.0, 0.0], [-3.0, 0.0]], static=static)
    return Scene("small", "two boxes", WorldSpec(100, 50, 10), bodies, ticks, models, expect_stop)


def run_fake(monkeypatch, breaks, model="exact", **scene_kw):
    def fake_make(name, world, bodies, **options):
        return FakeModel(world, bodies, breaks)

    monkeypatch.setattr(cases, "make_model", fake_make)
    return cases.run_case(small_scene(models=(model,), **scene_kw), model)


def test_a_model_that_keeps_every_invariant_passes(monkeypatch):
    r = run_fake(monkeypatch, None)
    assert (r.verdict, r.ticks_run, r.problems) == ("pass", 6, [])
    assert r.energy_drift == 0.0 and r.momentum_drift == 0.0 and r.penetration_px == 0.0


def set_nan(m):
    m.pos[1, 0] = math.nan


def leave_world(m):
    m.pos[0, 0] = -0.5


def heat_up(m):
    m.vel *= 1 + 1e-7


def turn_one(m):
    m.vel[0, 0] = -m.vel[0, 0]  # momentum changes, energy does not


def overlap(m):
    m.pos[1] = m.pos[0] + 1.0


def flip_and_grow(m):
    m.vel[0, 0] = -2 * m.vel[0, 0]


@pytest.mark.parametrize(
    ("breaks", "model", "fragment"),
    [
        (set_nan, "exact", "not finite"),
        (leave_world, "stepped", "sticks out of the world by 0.5 px"),
        (heat_up, "exact", "kinetic energy drifted"),
        (turn_one, "exact", "momentum drifted"),
        (overlap, "exact", "objects 0 and 1 overlap by 4 px"),
        (flip_and_grow, "paper", "changed size"),
    ],
)
def test_each_broken_invariant_fails_the_case_at_its_tick(monkeypatch, breaks, model, fragment):
    r = run_fake(monkeypatch, breaks, model=model)
    assert r.verdict == "fail"
    assert r.ticks_run == 3
    assert r.problems[0].startswith("tick 3: ")
    assert fragment in r.problems[0]


def test_stepped_energy_bound_is_looser_than_exact(monkeypatch):
    assert run_fake(monkeypatch, heat_up, model="stepped").verdict == "pass"
    assert checks.STEPPED_ENERGY_TOL > 2e-7 > checks.EXACT_ENERGY_TOL


def test_momentum_is_not_judged_in_ticks_with_wall_events(monkeypatch):
    def turn_at_wall(m):
        turn_one(m)
        return [(m.tick + 1, EV_WALL, 0)]

    r = run_fake(monkeypatch, turn_at_wall)
    assert r.verdict == "pass", r.problems


def test_a_static_object_that_moves_fails(monkeypatch):
    def move_static(m):
        m.pos[1, 1] += 2.0

    r = run_fake(monkeypatch, move_static, static=[False, True])
    assert "static object moved by 2 px" in r.problems[0]
    assert r.momentum_drift is None  # statics: momentum is not a conserved quantity


def test_a_run_that_differs_the_second_time_fails(monkeypatch):
    runs = iter(range(100))
    made = []

    def fake_make(name, world, bodies, **options):
        model = FakeModel(world, bodies)
        model.pos[0, 1] += 1e-3 * next(runs)  # the second build differs
        made.append(model)
        return model

    monkeypatch.setattr(cases, "make_model", fake_make)
    r = cases.run_case(small_scene(), "exact")
    assert len(made) == 2
    assert r.verdict == "fail"
    assert "second run differs in its positions" in r.problems[-1]


class Runaway(RuntimeError):
    pass


def stop_at_3(m):
    raise Runaway("tick 3 needed more than 10 events")


def test_an_unexpected_stop_fails_and_names_the_error(monkeypatch):
    r = run_fake(monkeypatch, stop_at_3)
    assert r.verdict == "fail"
    assert r.ticks_run == 2
    assert r.problems == ["tick 3: stopped: Runaway: tick 3 needed more than 10 events"]


def test_an_expected_stop_is_reported_as_stopped(monkeypatch):
    r = run_fake(monkeypatch, stop_at_3, expect_stop=("exact",))
    assert (r.verdict, r.ticks_run, r.problems) == ("stopped", 2, [])
    assert "Runaway" in r.note


def test_running_through_an_expected_runaway_fails(monkeypatch):
    r = run_fake(monkeypatch, None, expect_stop=("exact",))
    assert r.verdict == "fail"
    assert "should stop with a clear error" in r.problems[0]
