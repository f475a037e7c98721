"""The gravity part of `collide2d bench` (runner/bench/peers.py): the pile it times, and the
stepped model held to the closed forms it reports."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from collide2d.runner.bench import peers


def test_the_pile_is_n_boxes_inside_a_world_with_gravity_e_and_mu():
    world, bodies = peers.pile(1000)
    assert bodies.n == 1000 and world.has_gravity
    corner = bodies.pos + bodies.size
    assert (bodies.pos >= 0).all() and (corner <= [world.width, world.height]).all()
    assert (bodies.restitution == peers.E).all() and (bodies.friction == peers.MU).all()


def test_the_closed_forms_hold_for_the_stepped_model_at_every_rate():
    found = peers.closed_forms(lambda *a: None, rates=(60, 240))
    rows = {(r["scene"], r["model"], r["fps"]): r for r in found}
    for fps in (60, 240):
        # exact between contacts: the bounce instants
        assert rows[("bounce", "stepped", fps)]["value"] < 1e-9
        assert rows[("slide", "stepped", fps)]["value"] < 0.02
        assert all(rows[(scene, "stepped", fps)]["run_time_s"] > 0 for scene in ("bounce", "slide"))
    if ("bounce", "pymunk", 60) in rows:  # pymunk (the bench extra): a semi-implicit step's error,
        # smaller at the finer step
        coarse, fine = rows[("bounce", "pymunk", 60)], rows[("bounce", "pymunk", 240)]
        assert np.isfinite(coarse["value"]) and fine["value"] < coarse["value"]


def test_the_chart_of_the_closed_forms_is_written(tmp_path):
    pytest.importorskip("matplotlib")
    from collide2d.runner.bench import plots

    rows = peers.closed_forms(lambda *a: None, rates=(30, 60))
    assert "gravity_runtime_vs_error.png" in plots.plots(rows, tmp_path)
    with Image.open(tmp_path / "gravity_runtime_vs_error.png") as chart:
        assert chart.width > chart.height > 300
