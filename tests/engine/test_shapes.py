"""Exact shapes: pixel hulls of polygons, edge normals, and the cores every object gets."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.shapes import build_cores, edge_normals, pixel_hull
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, Bodies, Looks


def shoelace(v):
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def bodies_of(kinds, sizes, polys):
    """Bodies with the given kinds, sizes and polygon vertex lists (None for non-polygons)."""
    n = len(kinds)
    starts = [0]
    verts = []
    for p in polys:
        if p is not None:
            verts.extend(p)
        starts.append(len(verts))
    return Bodies(
        kind=np.array(kinds, np.int8),
        pos=np.zeros((n, 2)),
        size=np.array(sizes, float),
        vel=np.zeros((n, 2)),
        mass=np.ones(n),
        static=np.zeros(n, bool),
        looks=Looks(color=np.ones(n, np.uint8), fill=np.zeros(n, bool)),
        vert_start=np.array(starts, np.int64),
        verts=np.array(verts, np.int64).reshape(-1, 2),
    )


def test_one_pixel_is_the_unit_square():
    hull = pixel_hull(np.array([[3, 4]], np.int64))
    assert sorted(map(tuple, hull)) == [(3, 4), (3, 5), (4, 4), (4, 5)]
    assert shoelace(hull) == 1.0


def test_a_boxes_corner_pixels_give_exactly_the_box():
    w, h = 7, 3
    corners = np.array([[0, 0], [w - 1, 0], [w - 1, h - 1], [0, h - 1]], np.int64)
    hull = pixel_hull(corners)
    assert sorted(map(tuple, hull)) == [(0, 0), (0, h), (w, 0), (w, h)]
    assert shoelace(hull) == w * h


def test_collinear_pixels_leave_no_collinear_vertices():
    # A horizontal run of pixels is a 5x1 box: four corners, nothing in between.
    hull = pixel_hull(np.array([[0, 0], [1, 0], [2, 0], [3, 0], [4, 0]], np.int64))
    assert len(hull) == 4 and shoelace(hull) == 5.0


points = st.lists(
    st.tuples(st.integers(0, 20), st.integers(0, 20)), min_size=1, max_size=8, unique=True
)


@settings(max_examples=30, deadline=None)
@given(points)
def test_pixel_hull_is_the_convex_hull_of_the_pixel_squares(pts):
    p = np.array(pts, np.int64)
    hull = pixel_hull(p)
    h = len(hull)
    # Its bounding box is the box of the pixels: [min, max + 1] on each axis.
    assert hull[:, 0].min() == p[:, 0].min() and hull[:, 0].max() == p[:, 0].max() + 1
    assert hull[:, 1].min() == p[:, 1].min() and hull[:, 1].max() == p[:, 1].max() + 1
    # Strictly convex, positive order: every turn is a strict left turn.
    for k in range(h):
        a, b, c = hull[k], hull[(k + 1) % h], hull[(k + 2) % h]
        assert (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0
    # Every corner of every pixel square lies inside or on it ...
    corners = (p[:, None, :] + np.array([[0, 0], [1, 0], [0, 1], [1, 1]])[None]).reshape(-1, 2)
    for k in range(h):
        a, b = hull[k], hull[(k + 1) % h]
        cross = (b[0] - a[0]) * (corners[:, 1] - a[1]) - (b[1] - a[1]) * (corners[:, 0] - a[0])
        assert (cross >= 0).all()
    # ... and each of its vertices is such a corner.
    corner_set = set(map(tuple, corners.tolist()))
    assert all(tuple(v) in corner_set for v in hull.astype(int).tolist())


@settings(max_examples=30, deadline=None)
@given(points)
def test_edge_normals_are_outward_unit_and_perpendicular(pts):
    hull = pixel_hull(np.array(pts, np.int64))
    normals = edge_normals(hull)
    centroid = hull.mean(axis=0)
    for k in range(len(hull)):
        e = hull[(k + 1) % len(hull)] - hull[k]
        n = normals[k]
        assert abs(np.hypot(*n) - 1.0) < 1e-15
        assert abs(n @ e) < 1e-12
        assert n @ (centroid - hull[k]) < 0  # the inside lies behind the face
        if e[0] == 0 or e[1] == 0:
            assert set(np.abs(n)) == {0.0, 1.0}  # exact for axis-aligned edges


def test_cores_of_each_kind():
    triangle = [[0, 9], [5, 0], [10, 9]]
    cores = build_cores(
        bodies_of(
            [KIND_BOX, KIND_CIRCLE, KIND_POLYGON],
            [[4, 6], [9, 9], [11, 10]],
            [None, None, triangle],
        ),
        "exact",
    )
    assert cores.shape.tolist() == [KIND_BOX, KIND_CIRCLE, KIND_POLYGON]
    box = cores.verts[cores.start[0] : cores.start[1]]
    assert box.tolist() == [[0, 0], [4, 0], [4, 6], [0, 6]]
    assert cores.normals[cores.start[0] : cores.start[1]].tolist() == [
        [0, -1],
        [1, 0],
        [0, 1],
        [-1, 0],
    ]
    circle = cores.verts[cores.start[1] : cores.start[2]]
    assert circle.tolist() == [[4.5, 4.5]] and cores.radius.tolist() == [0, 4.5, 0]
    poly = cores.verts[cores.start[2] : cores.start[3]]
    assert poly.tolist() == pixel_hull(np.array(triangle, np.int64)).tolist()
    # The polygon's exact shape fills its pixel box, 11 x 10.
    assert poly.min(axis=0).tolist() == [0, 0] and poly.max(axis=0).tolist() == [11, 10]


def test_geometry_box_gives_every_object_its_box():
    cores = build_cores(
        bodies_of([KIND_CIRCLE, KIND_POLYGON], [[9, 9], [11, 10]], [None, [[0, 9], [5, 0]]]), "box"
    )
    assert cores.shape.tolist() == [KIND_BOX, KIND_BOX]
    assert cores.verts[4:].tolist() == [[0, 0], [11, 0], [11, 10], [0, 10]]
    assert cores.radius.tolist() == [0, 0]


def test_unknown_geometry_is_refused():
    with pytest.raises(ValueError, match="geometry"):
        build_cores(bodies_of([KIND_BOX], [[1, 1]], [None]), "round")
