"""The gravity part of `collide2d bench` (runner/bench/peers.py): the pile it times, and the
stepped model held to the closed forms it reports."""

from __future__ import annotations

import numpy as np

from collide2d.runner.bench import peers


def test_the_pile_is_n_boxes_inside_a_world_with_gravity_e_and_mu():
    world, bodies = peers.pile(1000)
    assert bodies.n == 1000 and world.has_gravity
    corner = bodies.pos + bodies.size
    assert (bodies.pos >= 0).all() and (corner <= [world.width, world.height]).all()
    assert (bodies.restitution == peers.E).all() and (bodies.friction == peers.MU).all()


def test_the_closed_forms_hold_for_the_stepped_model():
    rows = {(r["scene"], r["model"]): r["value"] for r in peers.closed_forms(lambda *a: None)}
    assert rows[("bounce", "stepped")] < 1e-9  # exact between contacts: the bounce instants
    assert rows[("slide", "stepped")] < 0.02
    if ("bounce", "pymunk") in rows:  # pymunk (the bench extra) has a semi-implicit step's error
        assert np.isfinite(rows[("bounce", "pymunk")])
