"""Kernels compile only what a scene needs: the paper model's pair stage only the pair finder the
scene chose (broadphase.find over a method marker), the rasteriser only the drawing code of the
kinds the scene has (draw.draw_shape over a shapes marker), with the same results as the code that
holds every branch."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from numba import njit

from collide2d.engine import broadphase
from collide2d.engine.picture.pixels import shapes_marker
from collide2d.engine.picture.raster import Renderer
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON
from collide2d.runner.scenario.load import loads


@njit
def _via_marker(marker, lo, hi, movable, cell, order, out, ws):
    return broadphase.find(marker, lo, hi, movable, cell, order, out, ws)


@pytest.mark.parametrize(
    "method", [broadphase.METHOD_SWEEP, broadphase.METHOD_GRID, broadphase.METHOD_CELLS]
)
def test_the_marker_finds_the_pairs_its_method_finds(method):
    rng = np.random.default_rng(method)
    n = 300
    lo = rng.uniform(0, 400, (n, 2))
    hi = lo + rng.uniform(2, 14, (n, 2))
    movable = rng.random(n) < 0.8
    expected = broadphase.sweep_pairs(lo, hi, ~movable)  # the reference answer
    ws = broadphase.workspace(n, lo.dtype)
    order = np.argsort(lo[:, 0], kind="stable").astype(np.int64)
    out = np.empty(4 * n, np.int64)
    k = _via_marker(broadphase.marker(method), lo, hi, movable, 20.0, order, out, ws)
    assert len(expected) > 10
    np.testing.assert_array_equal(broadphase.keys_to_pairs(out[:k]), expected)
    if os.environ.get("NUMBA_DISABLE_JIT") != "1":  # compiled: one specialisation per marker
        marker_type = _via_marker.signatures[-1][0]
        assert str(marker_type.dtype) == str(np.dtype(broadphase.marker(method).dtype))


@pytest.mark.parametrize(
    "kinds, dtype",
    [
        ([KIND_BOX], np.uint8),
        ([KIND_BOX, KIND_BOX], np.uint8),
        ([KIND_BOX, KIND_CIRCLE], np.uint64),
        ([KIND_POLYGON], np.uint64),
        ([KIND_CIRCLE, KIND_POLYGON, KIND_BOX], np.uint64),
    ],
)
def test_the_shapes_marker_names_the_kinds_present(kinds, dtype):
    marker = shapes_marker(np.array(kinds, np.int8))
    assert marker.dtype == dtype and marker.size == 0


SHOWCASE = """version: 1
world: {width: 90, height: 60}
ticks: 3
objects:
  - {shape: box, size: [12, 8], position: [2, 2], color: red}
  - {shape: circle, diameter: 11, position: [30, 5], color: lime, fill: true}
  - {shape: circle, diameter: 8, position: [50, 30], color: blue}
  - {shape: polygon, points: [[0, 9], [5, 0], [10, 9]], position: [70, 40], color: white}
"""


def test_a_scene_of_boxes_draws_as_the_code_with_every_kind():
    keep = "box"
    full = loads(SHOWCASE)
    lines = SHOWCASE.splitlines()
    kept = [
        line
        for line in lines
        if "shape:" not in line or line.split("shape: ")[1].split(",")[0] in keep.split("|")
    ]
    sc = loads("\n".join(kept) + "\n")
    assert sc.bodies.n < full.bodies.n
    pos = sc.bodies.pos + np.array([1.0, 2.0])
    some = Renderer(sc.world, sc.bodies)
    every = Renderer(sc.world, sc.bodies)
    every._art = every._art[:-1] + (np.zeros(0, np.uint64),)  # the code with every kind
    assert some._art[-1].dtype == np.uint8
    first = some.draw_full(pos).copy()
    np.testing.assert_array_equal(first, every.draw_full(pos))
    assert first.any()
    moved = pos + np.array([3.0, 1.0])
    np.testing.assert_array_equal(some.draw(moved), every.draw(moved))  # the dirty redraw too


SIGNATURES = """
import numpy as np
from numba import types
from collide2d.engine import sort
from collide2d.engine.models.paper import model as paper

rng = np.random.default_rng(1)
n = 100
keys = np.arange(n, dtype=np.int64)[::-1].copy()
pos = np.zeros((n, 2), np.int64)
size = np.full((n, 2), 5, np.int64)
near = np.empty(n, np.int64)
reach = np.empty((n, 4), np.int64)
assert paper._near(pos, size, np.zeros((n, 2), np.int64), keys, n, near, reach) == n
sort.sort_by_time(rng.random(n), keys.copy(), n)
sort.heap_argsort(rng.random(n))
for f in (sort.sort_keys, sort._sift_keys, sort._heap_sort_timed, sort._sift_order):
    literal = any(isinstance(a, types.Literal) for s in f.signatures for a in s)
    print(f.__name__, len(f.signatures), literal)
"""


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
def test_the_sorts_compile_once_not_again_for_a_literal_zero(tmp_path):
    """A literal 0 passed where a count or an index goes compiles a kernel a second time (numba
    types it as Literal[int](0)); the paper model's pair sort and the heap sorts pass typed ints."""
    env = dict(os.environ, COLLIDE2D_KERNEL_STORE="off", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    got = subprocess.run(
        [sys.executable, "-c", SIGNATURES], capture_output=True, text=True, env=env, check=True
    ).stdout.split()
    assert got == [
        *("sort_keys", "1", "False"),
        *("_sift_keys", "1", "False"),
        *("_heap_sort_timed", "1", "False"),
        *("_sift_order", "1", "False"),
    ]


# A script's prefix that collects, in `compiled`, the names of the kernels numba compiles.
LISTEN = """
from numba.core import event

compiled = set()


class Listen(event.Listener):
    def on_start(self, ev):
        compiled.add(ev.data["dispatcher"].py_func.__name__)

    def on_end(self, ev):
        pass


event.register("numba:compile", Listen())
"""

FINDERS = (
    LISTEN
    + """
import numpy as np
from numba import njit
from collide2d.engine import broadphase


@njit
def split_candidates(finder, lo, hi, movable, cell, order, keys, ws, found):
    return broadphase.find_split(finder, lo, hi, movable, cell, order, keys, ws, found)


lo = np.array([[0.0, 0.0], [5.0, 5.0], [50.0, 50.0]])
hi = lo + 10.0
movable = np.ones(3, bool)
assert broadphase.find_pairs(broadphase.METHOD_SWEEP, lo, hi, movable).tolist() == [[0, 1]]
keys = np.empty(16, np.int64)
order = np.arange(3, dtype=np.int64)
finder = broadphase.marker(broadphase.METHOD_SWEEP)
found = np.zeros(2, np.int64)
ws = broadphase.workspace(3)
assert split_candidates(finder, lo, hi, movable, 1.0, order, keys, ws, found) == 1
names = ("sweep_candidates", "grid_candidates", "cell_candidates", "cell_candidates_split_into")
print(*(name for name in names if name in compiled))
"""
)


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
def test_the_sweep_compiles_no_other_pair_finder(tmp_path):
    """broadphase.find_pairs (the start-up overlap check) and broadphase.find_split (the paper
    and stepped models' pair stages) compile the one finder their method names, not the grid's
    and the cells' too."""
    env = dict(os.environ, COLLIDE2D_KERNEL_STORE="off", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    got = subprocess.run(
        [sys.executable, "-c", FINDERS], capture_output=True, text=True, env=env, check=True
    ).stdout.split()
    assert got == ["sweep_candidates"]


SPRITES = (
    LISTEN
    + """
from collide2d.engine.picture.sprites import sprites
from collide2d.runner.scenario.load import loads
scene = loads(
    "version: 1\\nworld: {width: 40, height: 30}\\nticks: 1\\nobjects:\\n"
    "  - {shape: box, size: [3, 2], position: [2, 2]}\\n"
)
start, offsets = sprites(scene.bodies)
assert start.tolist() == [0, 6], start
print(*sorted(name for name in ("_circle", "_polygon") if name in compiled) or ["none"])
"""
)


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
def test_the_sprites_of_boxes_compile_no_circle_or_polygon_drawing(tmp_path):
    """The viewer's sprites (engine.picture.sprites) draw through the shapes marker, as the renderer
    does: a scene of boxes compiles no circle or polygon rasteriser for them."""
    env = dict(os.environ, COLLIDE2D_KERNEL_STORE="off", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    got = subprocess.run(
        [sys.executable, "-c", SPRITES], capture_output=True, text=True, env=env, check=True
    ).stdout.split()
    assert got == ["none"]
