"""The stress suite: its check kernels against plain references, its verdicts on models that break
each invariant on purpose, its scenes, and `collide2d stress --quick` end to end."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.events import EV_WALL, EVENT_DTYPE
from collide2d.engine.models import MODEL_NAMES, ModelUnavailable
from collide2d.engine.raster import round_positions
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner import stress
from collide2d.runner.cli import main
from collide2d.runner.generate import first_overlap

ROOT = Path(__file__).resolve().parents[2]


# ----------------------------------------------------------------------------- kernels


def brute_penetration(pos, size) -> float:
    """The deepest overlap min(width, height) over all pairs, plainly."""
    lo = pos[:, None, :]
    hi = (pos + size)[:, None, :]
    over = np.minimum(hi, (pos + size)[None, :, :]) - np.maximum(lo, pos[None, :, :])
    depth = np.minimum(over[..., 0], over[..., 1])
    np.fill_diagonal(depth, 0.0)
    return float(max(depth.max(), 0.0))


boxes = st.integers(1, 12).flatmap(
    lambda n: st.tuples(
        st.lists(st.tuples(st.integers(0, 40), st.integers(0, 40)), min_size=n, max_size=n),
        st.lists(st.tuples(st.integers(1, 15), st.integers(1, 15)), min_size=n, max_size=n),
        st.sampled_from([1.0, 0.5, 0.25]),
    )
)


@settings(max_examples=60, deadline=None)
@given(boxes)
def test_max_penetration_is_the_deepest_overlap_of_any_pair(case):
    corners, sides, unit = case
    pos = np.array(corners, np.float64) * unit
    size = np.array(sides, np.float64)
    depth, a, b = stress.max_penetration(pos, size)
    assert depth == brute_penetration(pos, size)
    if depth > 0:
        assert a < b
        one = brute_penetration(pos[[a, b]], size[[a, b]])
        assert one == depth
    else:
        assert (a, b) == (-1, -1)


def test_touching_boxes_have_no_penetration():
    pos = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
    assert stress.max_penetration(pos, np.full((3, 2), 10.0))[0] == 0.0


def figures(pos, vel, size, mass, static, pos0, speed0, world=(100.0, 80.0), room=None):
    out = np.zeros(8)
    room = np.array(room if room else (0.0, 0.0, -1.0, -1.0))
    stress.tick_figures(pos, vel, size, mass, static, pos0, speed0, *world, room, out)
    return out


def test_tick_figures_against_numpy():
    rng = np.random.default_rng(3)
    n = 9
    pos = rng.uniform(-5, 95, (n, 2))
    vel = rng.uniform(-50, 50, (n, 2))
    size = rng.uniform(1, 10, (n, 2))
    static = np.arange(n) % 4 == 0
    mass = np.where(static, np.inf, rng.uniform(0.1, 5, n))
    pos0 = pos + rng.uniform(-1, 1, (n, 2))
    speed0 = np.abs(vel) + rng.uniform(0, 1, (n, 2))
    room = (10.0, 10.0, 70.0, 60.0)
    out = figures(pos, vel, size, mass, static, pos0, speed0, room=room)
    m = ~static
    assert out[0] == 1.0
    outside = max(0.0, (-pos).max(), (pos + size - [100.0, 80.0]).max())
    assert out[1] == pytest.approx(outside, abs=1e-12)
    assert out[2] == pytest.approx(0.5 * np.sum(mass[m] * np.sum(vel[m] ** 2, axis=1)))
    assert out[3:5] == pytest.approx(np.sum(mass[m, None] * vel[m], axis=0))
    assert out[5] == pytest.approx(np.abs(np.abs(vel) - speed0).max())
    assert out[6] == pytest.approx(np.abs(pos - pos0)[static].max())
    esc = np.concatenate([10 - pos[m], (pos + size)[m] - [70.0, 60.0]], axis=1).max()
    assert out[7] == pytest.approx(max(esc, 0.0))


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_tick_figures_flag_a_non_finite_value(bad):
    pos = np.array([[1.0, 1.0], [5.0, 5.0]])
    vel = np.array([[1.0, 0.0], [0.0, 1.0]])
    vel[1, 0] = bad
    one = np.ones(2)
    out = figures(pos, vel, np.ones((2, 2)), one, np.zeros(2, bool), pos, np.abs(vel))
    assert out[0] == 0.0


@settings(max_examples=200, deadline=None)
@given(st.floats(-1e6, 1e6, allow_nan=False))
def test_exact_round_is_floor_of_x_plus_a_half_in_exact_arithmetic(x):
    expected = math.floor(Fraction(x) + Fraction(1, 2))
    assert stress.exact_round(np.array([[x, -x]]))[0].tolist() == [
        expected,
        math.floor(Fraction(-x) + Fraction(1, 2)),
    ]


def test_exact_round_at_the_float_half_trap():
    x = float(np.nextafter(0.5, 0.0))  # 0.49999999999999994: x + 0.5 rounds to 1.0 in floats
    assert x + 0.5 == 1.0
    assert stress.exact_round(np.array([[x, 2.5]])).tolist() == [[0, 3]]


def test_raster_rounds_the_float_just_below_a_half_down():
    x = float(np.nextafter(0.5, 0.0))
    assert round_positions(np.array([[x, 0.0]])).tolist() == [[0, 0]]


# ----------------------------------------------------------------------------- scenes


def test_scenes_are_valid_starts():
    names = []
    for quick in (True, False):
        for scene in stress.scenes(quick):
            names.append(scene.name)
            b = scene.bodies
            assert b.pos.shape == b.size.shape == b.vel.shape == (b.n, 2)
            assert np.all(b.pos >= 0)
            assert np.all(b.pos + b.size <= [scene.world.width, scene.world.height])
            assert first_overlap(b.pos, b.size) is None, scene.name
            assert set(scene.models) <= set(MODEL_NAMES)
            assert set(scene.expect_stop) <= set(scene.models)
            if "paper" in scene.models:
                assert np.array_equal(b.pos, np.round(b.pos)), scene.name
    assert len(set(names)) == len(names) // 2


def test_quick_scenes_are_shorter_and_the_long_run_is_a_million_ticks():
    quick = {s.name: s for s in stress.scenes(True)}
    full = {s.name: s for s in stress.scenes(False)}
    assert quick.keys() == full.keys()
    assert all(quick[k].ticks <= full[k].ticks for k in quick)
    assert full["long_run"].ticks == 10**6
    assert full["far_from_origin"].world.width == 10**6
    masses = full["mass_ratios"].bodies.mass
    assert masses.min() == pytest.approx(1e-12) and masses.max() == pytest.approx(1e12)


# ----------------------------------------------------------------------------- verdicts


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


def small_scene(models=("exact",), expect_stop=(), static=None, ticks=6) -> stress.Scene:
    bodies = Bodies.boxes([[10.0, 10.0], [40.0, 10.0]], 5, [[3.0, 0.0], [-3.0, 0.0]], static=static)
    return stress.Scene(
        "small", "two boxes", WorldSpec(100, 50, 10), bodies, ticks, models, expect_stop
    )


def run_fake(monkeypatch, breaks, model="exact", **scene_kw):
    def fake_make(name, world, bodies, **options):
        return FakeModel(world, bodies, breaks)

    monkeypatch.setattr(stress, "make_model", fake_make)
    return stress.run_case(small_scene(models=(model,), **scene_kw), model)


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
    assert stress.STEPPED_ENERGY_TOL > 2e-7 > stress.EXACT_ENERGY_TOL


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

    monkeypatch.setattr(stress, "make_model", fake_make)
    r = stress.run_case(small_scene(), "exact")
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


def test_an_unavailable_model_is_reported_not_failed(monkeypatch):
    def unavailable(name, world, bodies, **options):
        raise ModelUnavailable(f"model {name!r} is not available yet")

    monkeypatch.setattr(stress, "make_model", unavailable)
    r = stress.run_case(small_scene(), "exact")
    assert r.verdict == "unavailable" and "not available" in r.note


# ----------------------------------------------------------------------------- the command


def test_stress_exits_1_and_reports_a_broken_invariant(tmp_path, monkeypatch, capsys):
    def fake_make(name, world, bodies, **options):
        return FakeModel(world, bodies, set_nan if name == "stepped" else None, at=1)

    monkeypatch.setattr(stress, "make_model", fake_make)
    argv = ["stress", "--quick", "--scene", "runaway", "--scene", "half_pixel", "--out", tmp_path]
    assert main([str(a) for a in argv]) == 1
    err = capsys.readouterr().err
    assert "half_pixel / stepped: tick 1: a position or velocity is not finite" in err
    data = json.loads((tmp_path / "stress" / "report.json").read_text())
    verdicts = {(c["scene"], c["model"]): c["verdict"] for c in data["cases"]}
    assert verdicts[("half_pixel", "stepped")] == "fail"
    assert verdicts[("half_pixel", "exact")] == "pass"
    assert data["ok"] is False
    assert "**half_pixel / stepped**: tick 1" in (tmp_path / "stress" / "report.md").read_text()
    assert sorted(p.name for p in (tmp_path / "stress").iterdir()) == ["report.json", "report.md"]


def test_stress_refuses_an_unknown_scene_and_a_linked_report_folder(tmp_path, capsys):
    assert main(["stress", "--scene", "nope", "--out", str(tmp_path)]) == 2
    assert "unknown scene 'nope'" in capsys.readouterr().err
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "stress").symlink_to(elsewhere)
    assert main(["stress", "--quick", "--out", str(tmp_path / "out")]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert list(elsewhere.iterdir()) == []


def test_collide2d_stress_quick_passes_and_reports_every_case(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "collide2d", "stress", "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr
    data = json.loads((tmp_path / "stress" / "report.json").read_text())
    assert data["mode"] == "quick" and data["ok"] is True
    cases = {(c["scene"], c["model"]): c for c in data["cases"]}
    expected = {(s.name, m) for s in stress.scenes(True) for m in s.models}
    assert set(cases) == expected
    for (scene, model), c in cases.items():
        assert c["verdict"] in ("pass", "stopped", "unavailable"), (scene, model, c["problems"])
        if c["verdict"] == "pass":
            assert c["ticks_run"] == c["ticks"]
            assert c["events"] >= 0 and c["run_time_s"] >= 0
            assert c["energy_drift"] is not None and c["penetration_px"] is not None
    for model in ("stepped", "exact"):
        if cases[("runaway", model)]["verdict"] != "unavailable":
            assert cases[("runaway", model)]["verdict"] == "stopped"
    assert cases[("long_run", "paper")]["events"] > 0
    text = (tmp_path / "stress" / "report.md").read_text()
    assert "| scene | model | verdict | ticks run | events | energy drift |" in text
    assert f"Cases: {len(expected)}, failed: 0" in text
    assert "## Scenes" in text and "- `mass_ratios`: masses 1e-12 ... 1e12" in text
    assert data["scenes"].keys() == {s.name for s in stress.scenes(True)}
    assert "stress: " in proc.stdout and " 0 failed" in proc.stdout
