"""Energy in summary.json (docs/outputs.md#summary): kinetic, potential relative to the world's
origin (U = -sum m (g . c), c the centre of each box; static objects left out) and their sum, at
the start and at the end of a run, one definition shared with the engine
(`engine.invariants.energies`)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from collide2d.engine.invariants import energies, potential_energy
from collide2d.engine.world import Bodies
from collide2d.runner.output.options import RunOptions
from collide2d.runner.run import run_to_dir, simulate
from collide2d.runner.scenario.load import loads

SCENE = """version: 1
world: {width: 200, height: 100, fps: 10, gravity: GRAVITY}
model: stepped
ticks: 3
objects:
  - {shape: box, size: [10, 4], position: [20, 30], velocity: [3, 4], mass: 2}
  - {shape: circle, diameter: 6, position: [100, 60], velocity: [-1, 0]}
  - {shape: box, size: [200, 5], position: [0, 95], static: true}
"""


def test_the_potential_energy_is_by_the_centre_of_each_box_statics_left_out():
    s = loads(SCENE.replace("GRAVITY", "[5, 100]"))
    summary = simulate(s, log_events=False).summary
    # by hand: centres (25, 32) of mass 2 and (103, 63) of mass 1; the static floor counts not
    expected = -(2 * (5 * 25 + 100 * 32) + 1 * (5 * 103 + 100 * 63))
    assert summary["potential_energy"]["start"] == expected
    kinetic = 0.5 * 2 * (3**2 + 4**2) + 0.5 * 1 * 1**2
    assert summary["kinetic_energy"]["start"] == kinetic
    assert summary["total_energy"]["start"] == kinetic + expected


def test_the_end_figures_are_those_of_the_final_state():
    s = loads(SCENE.replace("GRAVITY", "980"))
    result = simulate(s, log_events=False)
    k, u, total = energies(s.bodies, result.final_pos, result.final_vel, s.world.gravity)
    summary = result.summary
    assert (summary["kinetic_energy"]["end"], summary["potential_energy"]["end"]) == (k, u)
    assert summary["total_energy"]["end"] == total == k + u


@pytest.mark.parametrize("model", ["paper", "exact"])
def test_without_gravity_the_potential_is_zero_and_the_total_is_the_kinetic(tmp_path, model):
    text = SCENE.replace(", gravity: GRAVITY", "").replace("stepped", model)
    folder, _ = run_to_dir(loads(text), tmp_path, RunOptions(png=False, gif=False, events=False))
    summary = json.loads((folder / "summary.json").read_text())
    for when in ("start", "end"):
        assert summary["potential_energy"][when] == 0.0
        assert summary["total_energy"][when] == summary["kinetic_energy"][when]


def test_potential_energy_falls_as_a_body_falls_and_is_zero_without_gravity():
    b = Bodies.boxes([[0.0, 0.0], [0.0, 10.0]], [4.0, 2.0], [0.0, 0.0], mass=[1.0, 3.0])
    high = potential_energy(b.mass, b.static, b.pos, b.size, (0.0, 980.0))
    low = potential_energy(b.mass, b.static, b.pos + [0.0, 1.0], b.size, (0.0, 980.0))
    assert low - high == pytest.approx(-980.0 * 4)  # both 1 px down: m g h of 4 mass units
    assert potential_energy(b.mass, b.static, b.pos + 1e9, b.size, (0.0, 0.0)) == 0.0
    assert str(potential_energy(b.mass, b.static, np.zeros((2, 2)), b.size, (0.0, 0.0))) == "0.0"
