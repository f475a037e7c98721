"""The stepped model under extreme gravity (docs/models.md#stepped-gravity-restitution-and-friction,
docs/limits.md#runaways): a body that a step carries far into a static object is put back where it
met it, so that none is left inside one, asleep or awake, whatever the gravity (up to the 1e12
px/s² the format allows), the fps, the substeps, the geometry and the static object's shape (a box
on the floor, a polygon, a shelf one pixel thin); and a body that falls asleep inside a static
object all the same (here: under a stack of much heavier ones) stops the run, naming it."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from collide2d import api
from collide2d.engine.contact import penetration
from collide2d.engine.errors import Runaway
from collide2d.engine.shapes import build_cores
from collide2d.runner.command.main import main
from collide2d.runner.run import make_model

# Overlap past this (px) is a body inside another object, not one resting on it.
INSIDE_PX = 1.0


def box(x, y, w=10, h=10, **more):
    return {"shape": "box", "size": [w, h], "position": [x, y], **more}


def circle(x, y, d=10, **more):
    return {"shape": "circle", "diameter": d, "position": [x, y], **more}


def static_box(x, y, w, h):
    return {"shape": "box", "size": [w, h], "position": [x, y], "static": True}


def triangle(x, y):
    """A static triangle 61 x 21 px, its apex up."""
    return {"shape": "polygon", "points": [[0, 20], [30, 0], [60, 20]], "position": [x, y],
            "static": True}  # fmt: skip


def scene(objects, gravity, fps=60, substeps=1, geometry="box", seconds=2, **world):
    return {
        "version": 1,
        "name": "landing",
        "world": {"width": 320, "height": 240, "fps": fps, "gravity": gravity, **world},
        "model": {"kind": "stepped", "substeps": substeps, "geometry": geometry},
        "ticks": fps * seconds,
        "objects": list(objects),
    }


def ran(spec):
    """The stepped model after the scene's ticks, and the scenario."""
    scenario = api.load(spec)
    model = make_model(scenario)
    model.advance(scenario.ticks, log=False)
    return model, scenario


def deepest(model, scenario):
    """(depth, moving id, other id) of the deepest overlap of a moving object with another, by
    the scenario's geometry, px (depth <= 0: none overlap)."""
    bodies = scenario.bodies
    cores = build_cores(bodies, scenario.geometry or "box")
    p = model.positions()
    worst = (0.0, -1, -1)
    for a, b in itertools.combinations(range(bodies.n), 2):
        if bodies.static[a] and bodies.static[b]:
            continue
        q = p[b] - p[a]
        sa = slice(cores.start[a], cores.start[a + 1])
        sb = slice(cores.start[b], cores.start[b + 1])
        depth, *_ = penetration(
            q[0], q[1], cores.shape[a], *bodies.size[a], cores.radius[a], cores.verts[sa],
            cores.normals[sa], cores.shape[b], *bodies.size[b], cores.radius[b], cores.verts[sb],
            cores.normals[sb],
        )  # fmt: skip
        if depth > worst[0]:
            worst = (float(depth), b if bodies.static[a] else a, a if bodies.static[a] else b)
    return worst


# A box and a circle dropped onto each kind of static object: a slab lying on the floor (the
# floor stops a fall the slab's top should have), a triangle on the floor, a shelf one pixel
# thin in mid-air, and a slab in mid-air thinner than the bodies.
GROUNDS = {
    "slab on the floor": [static_box(50, 225, 220, 15)],
    "triangle on the floor": [triangle(90, 219)],
    "thin shelf": [static_box(50, 150, 220, 1)],
    "mid-air slab": [static_box(50, 150, 220, 6)],
}


@pytest.mark.parametrize("ground", list(GROUNDS))
@pytest.mark.parametrize("geometry", ["box", "exact"])
@pytest.mark.parametrize(
    "gravity, fps, substeps", [(1e12, 60, 1), (1e12, 10, 8), (1e9, 1000, 1), (1e6, 10, 1)]
)
def test_no_body_is_left_inside_a_static_object_at_any_gravity(
    ground, geometry, gravity, fps, substeps
):
    objects = [box(100, 100, restitution=0.3), circle(130, 90, restitution=0.3)]
    spec = scene(objects + GROUNDS[ground], gravity, fps, substeps, geometry)
    model, scenario = ran(spec)
    depth, i, s = deepest(model, scenario)
    assert depth <= INSIDE_PX, f"object {i} is {depth:.3g} px inside object {s}"


@pytest.mark.parametrize("gravity", [1e12, 1e9, 1e6])
def test_a_body_dropped_onto_a_slab_on_the_floor_sleeps_on_its_top(gravity):
    # the fall of a step reaches the floor, 15 px below the slab's top: the body is put back on
    # the slab's top, where it came to it, and rests there
    spec = scene([box(100, 100, restitution=0.0), static_box(50, 225, 220, 15)], gravity, 60)
    model, _ = ran(spec)
    assert model._settle.asleep()[0]
    assert model.positions()[0, 1] == pytest.approx(215.0, abs=INSIDE_PX)


@pytest.mark.parametrize("speed", [1e9, 1e5])
def test_a_body_thrown_sideways_into_a_static_column_at_speed_stays_out_of_it(speed):
    # many times its size a step, under 1e9 px/s² of gravity, into a static column standing in
    # the floor's right corner: the right wall stops the move inside the column
    objects = [box(20, 200, velocity=[speed, 0], restitution=0.0),
               static_box(280, 150, 40, 90)]  # fmt: skip
    for geometry in ("box", "exact"):
        model, scenario = ran(scene(objects, 1e9, 60, geometry=geometry))
        depth, i, s = deepest(model, scenario)
        assert depth <= INSIDE_PX, f"{geometry}: object {i} is {depth:.3g} px inside object {s}"


def test_an_elastic_ball_bouncing_on_a_slab_never_ends_a_tick_inside_it():
    # e = 1: the contacts give up no energy to push it out with; it comes to the slab 1.5 times
    # its size a step and went 13 px into it, bouncing from there
    spec = scene([box(100, 100), static_box(50, 225, 220, 15)], 1e6, 1000, seconds=1)
    scenario = api.load(spec)
    model = make_model(scenario)
    for _ in range(scenario.ticks):
        model.advance(1, log=False)
        depth, _, _ = deepest(model, scenario)
        assert depth <= INSIDE_PX, f"tick {model.tick}: {depth:.3g} px inside the slab"


def test_energy_does_not_rise_when_a_body_is_put_back():
    spec = scene([box(100, 100, restitution=0.5), static_box(50, 225, 220, 15)], 1e9, 60)
    scenario = api.load(spec)
    model = make_model(scenario)
    g = 1e9

    def total():
        p, v = model.positions()[0], model.velocities()[0]
        return 0.5 * float(v @ v) - g * float(p[1])

    e0 = total()
    for _ in range(scenario.ticks):
        model.advance(1, log=False)
        assert total() <= e0 + 1e-9 * abs(e0)
    assert np.isfinite(model.positions()).all()


# --- a body left asleep inside a static object stops the run, by name ----------------------------


def crushing_stack(ratio=100.0, **more):
    """Six boxes stacked on a static floor, each heavier than the one under it, ratio times from
    the bottom one to the top: at 60 fps the passes push the bottom boxes into the floor, where
    they would sleep."""
    floor = {**static_box(0, 220, 320, 20), "name": "floor"}
    stack = [box(100, 210 - 10 * k, 20, 10, mass=ratio ** (k / 5), restitution=0.3,
                 name=f"box{k}") for k in range(6)]  # fmt: skip
    return scene([floor, *stack], 980, 60, seconds=5, **more)


def test_a_body_falling_asleep_inside_a_static_object_stops_the_run_naming_both():
    scenario = api.load(crushing_stack())
    model = make_model(scenario)
    with pytest.raises(Runaway) as stop:
        model.advance(scenario.ticks, log=False)
    message = str(stop.value)
    i, s = stop.value.objects
    assert s == 0 and not scenario.bodies.static[i]
    assert f"object {i} fell asleep" in message and "inside static object 0" in message
    assert "in tick " in message and "substeps" in message


@pytest.mark.parametrize("ratio, substeps", [(100.0, 1), (1e3, 1), (1e6, 4), (10.0, 1), (100.0, 4)])
def test_no_run_leaves_a_body_asleep_inside_a_static_object_without_a_word(ratio, substeps):
    # either the run stops, naming the body, or no sleeping body is inside a static object
    spec = crushing_stack(ratio)
    spec["model"]["substeps"] = substeps
    scenario = api.load(spec)
    model = make_model(scenario)
    try:
        model.advance(scenario.ticks, log=False)
    except Runaway as stop:
        assert scenario.bodies.static[stop.objects[1]]
        return
    asleep = model._settle.asleep()
    p = model.positions()
    bodies = scenario.bodies
    for i in np.flatnonzero(asleep):
        q = p[0] - p[i]  # the floor, object 0, from body i
        depth = min(bodies.size[i, 0] - q[0], q[0] + 320, bodies.size[i, 1] - q[1], q[1] + 20)
        assert depth <= 0.1 + INSIDE_PX, f"object {i} asleep {depth:.3g} px inside the floor"


def test_the_run_line_names_the_body_asleep_inside_a_static_object(tmp_path, capsys):
    path = tmp_path / "crush.yaml"
    path.write_text(json.dumps({**crushing_stack(), "name": "crush"}))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{path}: error: the stepped model stopped the run in tick")
    assert "fell asleep" in err and "inside static object 0" in err and "object 0 is floor" in err
    summary = json.loads((out / "crush" / "summary.json").read_text())
    assert "fell asleep" in summary["stopped"] and summary["stopped_at_tick"] >= 0
