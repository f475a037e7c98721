"""The gravity part of `collide2d bench` (runner/bench/gravity): the pile it times, and the
stepped model held to the closed forms it reports."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from collide2d.engine import events
from collide2d.runner.bench.gravity import closed, pile


def test_the_pile_is_n_boxes_inside_a_world_with_gravity_e_and_mu():
    world, bodies = pile.pile(1000)
    assert bodies.n == 1000 and world.has_gravity
    corner = bodies.pos + bodies.size
    assert (bodies.pos >= 0).all() and (corner <= [world.width, world.height]).all()
    assert (bodies.restitution == pile.E).all() and (bodies.friction == pile.MU).all()


def test_the_closed_forms_hold_for_the_stepped_model_at_every_rate():
    found = closed.closed_forms(lambda *a: None, rates=(60, 240))
    rows = {(r["scene"], r["model"], r["fps"]): r for r in found if r.get("substeps", 1) == 1}
    for fps in (60, 240):
        # exact between contacts: the bounce instants
        assert rows[("bounce", "stepped", fps)]["value"] < 1e-9
        assert rows[("slide", "stepped", fps)]["value"] < 0.02
        assert all(rows[(scene, "stepped", fps)]["run_time_s"] > 0 for scene in ("bounce", "slide"))
    # the ladder of substeps at 30 fps: bounces still to round-off, the slide's error down by a
    # thousand to the floor it has at 240 fps (30 x 8), where it stays
    ladder = [r for r in found if r.get("substeps", 1) > 1]
    assert sorted({r["substeps"] for r in ladder}) == list(closed.LADDER_SUBSTEPS)
    assert all(r["value"] < 1e-9 for r in ladder if r["scene"] == "bounce")
    slides = {r["substeps"]: r["value"] for r in ladder if r["scene"] == "slide"}
    assert slides[64] < slides[2] / 1000
    assert slides[64] == pytest.approx(rows[("slide", "stepped", 240)]["value"], rel=1e-3)
    if ("bounce", "pymunk", 60) in rows:  # pymunk (the bench extra): a semi-implicit step's error,
        # smaller at the finer step
        coarse, fine = rows[("bounce", "pymunk", 60)], rows[("bounce", "pymunk", 240)]
        assert np.isfinite(coarse["value"]) and fine["value"] < coarse["value"]


def test_the_chart_of_the_closed_forms_is_written(tmp_path):
    pytest.importorskip("matplotlib")
    from collide2d.runner.bench import plots

    rows = closed.closed_forms(lambda *a: None, rates=(30, 60))
    assert "gravity_runtime_vs_error.png" in plots.plots(rows, tmp_path)
    with Image.open(tmp_path / "gravity_runtime_vs_error.png") as chart:
        assert chart.width > chart.height > 300


def test_the_exact_model_meets_the_closed_forms_to_round_off_at_every_rate():
    found = closed.closed_forms(lambda *a: None, rates=(30, 240))
    rows = {(r["scene"], r["model"], r["fps"]): r for r in found if r.get("substeps", 1) == 1}
    for fps in (30, 240):
        # every bounce at its closed-form instant, the slide's stop where v0²/(2 mu g) puts it
        assert rows[("bounce", "exact", fps)]["value"] < 1e-12
        assert rows[("slide", "exact", fps)]["value"] < 1e-12
    # the stepped model's slide error shrinks with its step; the exact model's does not need to
    assert rows[("slide", "stepped", 240)]["value"] < rows[("slide", "stepped", 30)]["value"]


def test_the_exact_model_s_events_per_second_under_gravity_are_reported(monkeypatch):
    from collide2d.runner.bench.gravity import exact

    monkeypatch.setitem(exact.GAS, True, (300, 60))
    monkeypatch.setitem(exact.BALLS, True, (200, 120))
    said = []
    found = {(r["scene"], r["note"].split(",")[0]): r for r in exact.gravity(True, said.append)}
    flat = found[("gas-300", "exact: events/s without gravity")]["value"]
    falling = found[("gas-300", "exact: events/s under gravity 400 px/s²")]["value"]
    ratio = found[("gas-300", "exact: under gravity / without (target >= 0.5)")]["value"]
    assert flat > 0 and falling > 0 and ratio == falling / flat
    assert found[("balls-200", "exact: events/s")]["value"] > 0  # they reach the floor
    assert len(said) == 2 and "balls e 0.9" in said[1]


def test_the_falling_balls_bounce_on_the_floor_and_each_other_and_stay_inside():
    from collide2d.engine.models import make
    from collide2d.engine.world import WorldSpec
    from collide2d.runner.bench.gravity import exact

    bodies = exact.balls(200)
    world = WorldSpec(exact.SIDE, exact.SIDE, 60, gravity=(0.0, exact.BALLS_G))
    model = make("exact", world, bodies)
    found = model.advance(240)
    floor = found[found["type"] == events.EV_WALL]
    assert (floor["code"] == events.SIDE_BOTTOM).sum() > 200  # each ball's first bounces
    assert (found["type"] == events.EV_PAIR).sum() > 0
    assert (model.positions() <= exact.SIDE - exact.SIZE).all() and (model.positions() >= 0).all()
