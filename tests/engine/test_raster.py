"""Tests for engine.picture.raster: exact DDA, midpoint circles, fills, clipping, id order, dirty
redraw."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.picture import pixels, raster
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, Bodies, Looks, WorldSpec

FAST = settings(max_examples=30, deadline=None)


# ------------------------------------------------------------------ helpers


def make_bodies(kind, pos, size, color, fill, polys=None) -> Bodies:
    """Bodies from lists; polys maps an object index to its vertex list (relative)."""
    n = len(kind)
    polys = polys or {}
    starts = [0]
    verts = []
    for i in range(n):
        verts.extend(polys.get(i, []))
        starts.append(len(verts))
    return Bodies(
        kind=np.asarray(kind, np.int8),
        pos=np.asarray(pos, np.float64).reshape(n, 2),
        size=np.asarray(size, np.float64).reshape(n, 2),
        vel=np.zeros((n, 2)),
        mass=np.ones(n),
        static=np.zeros(n, bool),
        looks=Looks(color=np.asarray(color, np.uint8), fill=np.asarray(fill, bool)),
        vert_start=np.asarray(starts, np.int64),
        verts=np.asarray(verts, np.int64).reshape(-1, 2),
    )


def random_scene(rng: np.random.Generator, n: int) -> Bodies:
    """n random objects of every kind and size 1..12, random colours 1..5 and fill flags."""
    kind, size, polys = [], [], {}
    for i in range(n):
        k = int(rng.integers(3))
        kind.append(k)
        if k == KIND_BOX:
            size.append([int(rng.integers(1, 13)), int(rng.integers(1, 13))])
        elif k == KIND_CIRCLE:
            d = int(rng.integers(1, 13))
            size.append([d, d])
        else:
            v = rng.integers(0, 12, size=(int(rng.integers(1, 7)), 2))
            v -= v.min(axis=0)
            polys[i] = v.tolist()
            size.append((v.max(axis=0) + 1).tolist())
    return make_bodies(
        kind,
        np.zeros((n, 2)),
        size,
        rng.integers(1, 6, size=n),
        rng.random(n) < 0.4,
        polys,
    )


def pixel_set(frame: np.ndarray, value=None) -> set[tuple[int, int]]:
    ys, xs = np.nonzero(frame if value is None else frame == value)
    return set(zip(xs.tolist(), ys.tolist(), strict=True))


def draw_line(w, h, x0, y0, x1, y1, clip=None):
    buf = np.zeros((h, w), np.uint8)
    cx0, cy0, cx1, cy1 = clip or (0, 0, w - 1, h - 1)
    pixels._line(buf, x0, y0, x1, y1, np.uint8(1), cx0, cy0, cx1, cy1)
    return buf


def ref_dda(x0, y0, x1, y1):
    """The paper's DDA with exact rationals: n steps of dx/n, each point rounded half up."""
    dx, dy = x1 - x0, y1 - y0
    n = max(abs(dx), abs(dy))
    if n == 0:
        return [(x0, y0)]
    half = Fraction(1, 2)
    return [
        (
            x0 + math.floor(Fraction(k * dx, n) + half),
            y0 + math.floor(Fraction(k * dy, n) + half),
        )
        for k in range(n + 1)
    ]


def ref_classic_circle(r):
    """Textbook integer midpoint circle of radius r centred on (0, 0) (decision variable form)."""
    pts = set()
    x, y, p = r, 0, 1 - r
    while x >= y:
        for a, b in ((x, y), (y, x)):
            pts.update({(a, b), (-a, b), (a, -b), (-a, -b)})
        y += 1
        if p < 0:
            p += 2 * y + 1
        else:
            x -= 1
            p += 2 * (y - x) + 1
    return pts


# ------------------------------------------------------------------ rounding


def test_positions_round_half_up():
    pos = np.array([[2.5, 2.4999], [-0.5, -0.51], [0.49, 1e-12], [9.5, -1.5]])
    expect = [[3, 2], [0, -1], [0, 0], [10, -1]]
    assert raster.round_positions(pos).tolist() == expect


def test_far_and_nonfinite_positions_draw_nothing():
    bodies = Bodies.boxes([[0, 0], [0, 0], [0, 0]], 5, 0, fill=[True] * 3)
    pos = np.array([[1e30, 3.0], [np.nan, 2.0], [-np.inf, -1e18]])
    frame = raster.render(WorldSpec(20, 10, 10), bodies, pos)
    assert not frame.any()


# ------------------------------------------------------------------ DDA

coord = st.integers(-40, 40)


@FAST
@given(coord, coord, coord, coord)
def test_dda_matches_exact_rational_reference(x0, y0, x1, y1):
    got = pixels.dda_line(x0, y0, x1, y1).tolist()
    assert [tuple(p) for p in got] == ref_dda(x0, y0, x1, y1)


@FAST
@given(st.integers(-(10**9), 10**9), st.integers(-(10**9), 10**9), coord, coord)
def test_dda_far_from_origin_matches_reference(x0, y0, dx, dy):
    got = pixels.dda_line(x0, y0, x0 + dx, y0 + dy).tolist()
    assert [tuple(p) for p in got] == ref_dda(x0, y0, x0 + dx, y0 + dy)


@FAST
@given(coord, coord, coord, coord)
def test_dda_endpoints_and_steps(x0, y0, x1, y1):
    pts = pixels.dda_line(x0, y0, x1, y1)
    n = max(abs(x1 - x0), abs(y1 - y0))
    assert pts.shape == (n + 1, 2)
    assert pts[0].tolist() == [x0, y0]
    assert pts[-1].tolist() == [x1, y1]
    if n:
        step = np.diff(pts, axis=0)
        # each step moves one pixel along the major axis and at most one across
        assert np.all(np.abs(step).max(axis=1) == 1)
        major = 0 if abs(x1 - x0) >= abs(y1 - y0) else 1
        assert np.all(np.abs(step[:, major]) == 1)


@FAST
@given(
    st.integers(-10, 40),
    st.integers(-10, 30),
    st.integers(-10, 40),
    st.integers(-10, 30),
    st.tuples(st.integers(0, 29), st.integers(0, 19), st.integers(0, 29), st.integers(0, 19)),
)
def test_drawn_line_is_the_dda_points_clipped(x0, y0, x1, y1, clip):
    cx0, cy0, cx1, cy1 = clip
    buf = draw_line(30, 20, x0, y0, x1, y1, clip)
    expect = {(x, y) for x, y in ref_dda(x0, y0, x1, y1) if cx0 <= x <= cx1 and cy0 <= y <= cy1}
    assert pixel_set(buf) == expect


def test_drawn_lines_all_directions_match_reference():
    """Every line of up to 12 px each way from one pixel, including all rounding ties."""
    for dx in range(-12, 13):
        for dy in range(-12, 13):
            buf = draw_line(27, 27, 13, 13, 13 + dx, 13 + dy)
            assert pixel_set(buf) == set(ref_dda(13, 13, 13 + dx, 13 + dy)), (dx, dy)


# ------------------------------------------------------------------ boxes


@pytest.mark.parametrize("w,h", [(1, 1), (1, 6), (7, 1), (2, 2), (10, 10), (13, 4)])
def test_box_outline_is_dda_through_corners(w, h):
    x, y = 3, 2
    bodies = Bodies.boxes([[x, y]], [w, h], 0)
    frame = raster.render(WorldSpec(24, 16, 10), bodies, bodies.pos)
    corners = [(x, y), (x + w - 1, y), (x + w - 1, y + h - 1), (x, y + h - 1)]
    expect = set()
    for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
        expect.update(ref_dda(*a, *b))
    assert pixel_set(frame) == expect
    assert corners[0] in expect and corners[2] in expect
    perimeter = w * h if min(w, h) <= 2 else 2 * (w + h) - 4
    assert len(expect) == perimeter


def test_box_fill_covers_its_box():
    bodies = Bodies.boxes([[3, 2]], [6, 4], 0, color=[3], fill=[True])
    frame = raster.render(WorldSpec(16, 10, 10), bodies, bodies.pos)
    assert pixel_set(frame) == {(x, y) for x in range(3, 9) for y in range(2, 6)}
    assert set(np.unique(frame).tolist()) == {0, 3}


# ------------------------------------------------------------------ circles


@pytest.mark.parametrize("r", list(range(0, 50)))
def test_odd_circle_is_the_classic_midpoint_circle(r):
    d = 2 * r + 1
    got = {(x - r, y - r) for x, y in pixels.midpoint_circle(d).tolist()}
    assert got == ref_classic_circle(r)


def ref_doubled_circle(d):
    """Circle in doubled units from the closed form of the midpoint rule, not the stepping.

    For each V (parity of R = d-1) the outer candidate U is kept while the midpoint U-1 is inside:
    U(V) = the largest U of R's parity with (U-1)^2 + V^2 <= R^2; the first point is (R, R mod 2),
    the rightmost pixel of the box's middle row(s).
    """
    r = d - 1
    pts = set()
    v = r % 2
    while True:
        u = r
        while v > r % 2 and u >= v and (u - 1) ** 2 + v * v > r * r:
            u -= 2
        if u < v:
            break
        for a, b in ((u, v), (v, u)):
            for sa in (-1, 1):
                for sb in (-1, 1):
                    pts.add(((r + sa * a) // 2, (r + sb * b) // 2))
        v += 2
    return pts


@pytest.mark.parametrize("d", list(range(1, 60)))
def test_circle_matches_closed_form_for_every_diameter(d):
    got = {tuple(p) for p in pixels.midpoint_circle(d).tolist()}
    assert got == ref_doubled_circle(d)


@pytest.mark.parametrize("d", list(range(1, 70)))
def test_circle_fits_its_box_touches_all_sides_and_is_symmetric(d):
    pts = pixels.midpoint_circle(d)
    assert pts.min() == 0 and pts.max() == d - 1
    assert set(pts[:, 0].tolist()) >= {0, d - 1} and set(pts[:, 1].tolist()) >= {0, d - 1}
    s = {tuple(p) for p in pts.tolist()}
    assert {(d - 1 - x, y) for x, y in s} == s
    assert {(x, d - 1 - y) for x, y in s} == s
    assert {(y, x) for x, y in s} == s
    # every row and column of the box has a pixel, and the ring is 8-connected
    assert set(pts[:, 1].tolist()) == set(range(d))
    start = next(iter(s))
    seen, todo = {start}, [start]
    while todo:
        x, y = todo.pop()
        for ex in (-1, 0, 1):
            for ey in (-1, 0, 1):
                q = (x + ex, y + ey)
                if q in s and q not in seen:
                    seen.add(q)
                    todo.append(q)
    assert seen == s


def test_small_circles():
    assert pixels.midpoint_circle(1).tolist() == [[0, 0]]
    assert {tuple(p) for p in pixels.midpoint_circle(2).tolist()} == {
        (0, 0),
        (1, 0),
        (0, 1),
        (1, 1),
    }


@pytest.mark.parametrize("d", list(range(1, 40)))
def test_circle_fill_spans_rows_between_outline_extremes(d):
    outline = pixels.midpoint_circle(d)
    filled = {tuple(p) for p in pixels.midpoint_circle(d, fill=True).tolist()}
    expect = set()
    for y in range(d):
        xs = outline[outline[:, 1] == y, 0]
        expect.update((x, y) for x in range(xs.min(), xs.max() + 1))
    assert filled == expect
    assert {tuple(p) for p in outline.tolist()} <= filled


def test_circle_drawn_in_a_frame_sits_in_its_box():
    bodies = make_bodies([KIND_CIRCLE], [[4, 3]], [[7, 7]], [2], [False])
    frame = raster.render(WorldSpec(20, 15, 10), bodies, bodies.pos)
    expect = {(x + 4, y + 3) for x, y in pixels.midpoint_circle(7).tolist()}
    assert pixel_set(frame, 2) == expect


# ------------------------------------------------------------------ polygons


def strictly_inside(px, py, verts) -> bool | None:
    """Even-odd test of the point (px, py) with exact rationals; None when it is on an edge."""
    inside = False
    m = len(verts)
    for j in range(m):
        (ax, ay), (bx, by) = verts[j], verts[(j + 1) % m]
        cross = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
        if cross == 0 and min(ax, bx) <= px <= max(ax, bx) and min(ay, by) <= py <= max(ay, by):
            return None
        if (ay > py) != (by > py):
            xc = ax + Fraction((py - ay) * (bx - ax), by - ay)
            if px < xc:
                inside = not inside
    return inside


polygon_verts = st.lists(st.tuples(st.integers(0, 14), st.integers(0, 14)), min_size=1, max_size=7)


@FAST
@given(polygon_verts, st.booleans())
def test_polygon_outline_and_even_odd_fill(verts, fill):
    vx = np.array(verts)
    vx -= vx.min(axis=0)
    verts = [tuple(v) for v in vx.tolist()]
    x, y = 3, 2
    size = (vx.max(axis=0) + 1).tolist()
    bodies = make_bodies([KIND_POLYGON], [[x, y]], [size], [4], [fill], {0: verts})
    frame = raster.render(WorldSpec(24, 22, 10), bodies, bodies.pos)
    outline = set()
    m = len(verts)
    for j in range(m):
        a, b = verts[j], verts[(j + 1) % m]
        outline.update(ref_dda(a[0] + x, a[1] + y, b[0] + x, b[1] + y))
    got = pixel_set(frame, 4)
    assert outline <= got
    for py in range(frame.shape[0]):
        for px in range(frame.shape[1]):
            if (px, py) in outline:
                continue
            inside = strictly_inside(px - x, py - y, verts) if fill and m >= 3 else False
            assert inside is not None  # boundary points with whole coordinates are on the outline
            assert ((px, py) in got) == inside, (px, py)


# ------------------------------------------------------------------ frames


def test_clipping_equals_crop_of_a_larger_world():
    rng = np.random.default_rng(5)
    bodies = random_scene(rng, 40)
    w, h, m = 30, 20, 16
    pos = rng.uniform(-14, 32, size=(40, 2))
    small = raster.render(WorldSpec(w, h, 10), bodies, pos)
    big = raster.render(WorldSpec(w + 2 * m, h + 2 * m, 10), bodies, pos + m)
    assert np.array_equal(small, big[m : m + h, m : m + w])
    assert small.any()


def test_later_ids_are_drawn_on_top():
    world = WorldSpec(12, 8, 10)
    pos = [[1, 1], [3, 2]]
    bodies = Bodies.boxes(pos, 4, 0, color=[1, 2], fill=[True, True])
    frame = raster.render(world, bodies, bodies.pos)
    assert frame[2, 3] == 2 and frame[1, 1] == 1 and frame[5, 6] == 2
    swapped = Bodies.boxes(pos, 4, 0, color=[2, 1], fill=[True, True])
    assert raster.render(world, swapped, swapped.pos)[2, 3] == 1
    # an outline drawn after a filled box shows its outline only
    mixed = Bodies.boxes(pos, 4, 0, color=[1, 2], fill=[True, False])
    f = raster.render(world, mixed, mixed.pos)
    assert f[3, 4] == 1 and f[2, 4] == 2


def test_to_rgb_uses_the_palette():
    palette = np.array([[0, 0, 0], [255, 0, 0], [1, 2, 3]], np.uint8)
    frame = np.array([[0, 1], [2, 1]], np.uint8)
    assert raster.to_rgb(frame, palette).tolist() == [
        [[0, 0, 0], [255, 0, 0]],
        [[1, 2, 3], [255, 0, 0]],
    ]
    with pytest.raises(ValueError):
        raster.to_rgb(np.array([[3]], np.uint8), palette)


def test_renderer_rejects_wrong_shape():
    r = raster.Renderer(WorldSpec(10, 10, 10), Bodies.boxes([[0, 0], [5, 5]], 2, 0))
    with pytest.raises(ValueError):
        r.draw(np.zeros((3, 2)))


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_dirty_redraw_equals_full_redraw_every_tick(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 25))
    bodies = random_scene(rng, n)
    world = WorldSpec(int(rng.integers(20, 50)), int(rng.integers(15, 40)), 10)
    dirty = raster.Renderer(world, bodies)
    full = raster.Renderer(world, bodies)
    pos = rng.uniform(-8, [world.width, world.height], size=(n, 2))
    partial = 0
    for _ in range(80):
        movers = rng.random(n) < rng.choice([0.05, 0.2, 0.4, 1.0])
        step = rng.normal(0, 1.5, size=(n, 2))
        pos = np.where(movers[:, None], pos + step, pos)
        if rng.random() < 0.05:  # a jump anywhere, partly off screen
            pos[rng.integers(n)] = rng.uniform(-12, world.width + 4, size=2)
        got = dirty.draw(pos)
        partial += not dirty.last_was_full
        assert np.array_equal(got, full.draw_full(pos))
    assert partial > 0


def test_degenerate_objects_draw_nothing_and_do_not_break_redraw():
    world = WorldSpec(10, 8, 10)
    empty = raster.Renderer(world, Bodies.boxes(np.zeros((0, 2)), 1, 0))
    assert not empty.draw(np.zeros((0, 2))).any() and not empty.draw(np.zeros((0, 2))).any()
    bodies = make_bodies(
        [KIND_BOX, KIND_CIRCLE, KIND_POLYGON, KIND_BOX],
        np.zeros((4, 2)),
        [[0, 3], [0, 0], [1, 1], [2, 2]],
        [1, 2, 3, 4],
        [True, True, True, False],
    )
    r = raster.Renderer(world, bodies)
    pos = np.array([[1.0, 1], [2, 2], [3, 3], [5, 5]])
    assert pixel_set(r.draw(pos)) == {(5, 5), (6, 5), (5, 6), (6, 6)}
    pos[:3] += 1
    assert pixel_set(r.draw(pos)) == {(5, 5), (6, 5), (5, 6), (6, 6)}


def test_draw_with_nothing_moving_keeps_the_frame():
    bodies = Bodies.boxes([[1, 1], [6, 2]], 3, 0)
    r = raster.Renderer(WorldSpec(12, 8, 10), bodies)
    first = r.draw(bodies.pos).copy()
    assert np.array_equal(r.draw(bodies.pos + 0.3), first)
    assert not r.last_was_full


def test_same_pixels_without_jit():
    """The kernels are one source: run as plain Python they give the same frames."""
    code = """
import numpy as np, sys
sys.path.insert(0, TESTS_DIR)
from test_raster import random_scene
from collide2d.engine.picture import raster
from collide2d.engine.world import WorldSpec
rng = np.random.default_rng(11)
bodies = random_scene(rng, 12)
r = raster.Renderer(WorldSpec(30, 24, 10), bodies)
pos = rng.uniform(-5, 25, size=(12, 2))
out = []
for _ in range(6):
    out.append(r.draw(pos).copy())
    pos[:3] += rng.normal(0, 2, size=(3, 2))
sys.stdout.buffer.write(np.stack(out).tobytes())
""".replace("TESTS_DIR", repr(os.path.dirname(os.path.abspath(__file__))))
    results = []
    for flag in ("1", "0"):
        env = dict(os.environ, NUMBA_DISABLE_JIT=flag)
        proc = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, check=True, timeout=120
        )
        results.append(proc.stdout)
    assert len(results[0]) == 6 * 24 * 30
    assert results[0] == results[1]
