"""Exact shapes: every object as a convex core polygon grown by a radius, built once per model.

The accurate models (`stepped`, `exact`) test pairs by their real shapes under `geometry: exact`.
Each object's exact shape is written here as `core ⊕ disc(radius)`, relative to its box's top-left
corner, so that one family of contact formulas (contact.py) serves every pair:

    box w×h     core = the rectangle (0,0) (w,0) (w,h) (0,h), radius 0 — exactly its box;
    circle d    core = the single point (d/2, d/2), radius d/2 — the disc in its d×d box;
    polygon     core = conv(vertices) ⊕ [0,1]², the hull of its vertices' pixel squares,
                radius 0 — whose bounding box is exactly the polygon's pixel box.

Under `geometry: box` every object is given its box as core. Input: the `Bodies` arrays. Output:
`Cores`, parallel arrays in id order (`shape`, `radius`, and the cores' vertices and outward unit
edge normals in one flat table indexed by `start`). Vertices run in positive (shoelace) order; with
x right and y down that is clockwise on screen, and the outward normal of the edge from v_k to
v_k+1 is (e_y, -e_x)/|e| with e = v_k+1 - v_k. No rotation: cores never change after they are built.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from collide2d.engine.jit import njit
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, Bodies

GEOMETRIES = ("box", "exact")

# The four corners of a pixel square, added to every polygon vertex before taking the hull.
_PIXEL_CORNERS = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], dtype=np.int64)


@dataclass(frozen=True)
class Cores:
    """Exact shapes of n objects; m core vertices in all.

    shape   (n,)   int8     KIND_BOX / KIND_CIRCLE / KIND_POLYGON as the contact tests see it
    radius  (n,)   float64  px; d/2 for circles, 0 otherwise
    start   (n+1,) int64    object i's core is verts[start[i]:start[i+1]]
    verts   (m, 2) float64  core vertices relative to the box's top-left corner, px
    normals (m, 2) float64  outward unit normal of the edge verts[k] -> verts[k+1] (cyclic);
                            (0, 0) for a one-point core
    """

    shape: np.ndarray
    radius: np.ndarray
    start: np.ndarray
    verts: np.ndarray
    normals: np.ndarray


@njit(cache=True)
def pixel_hull(verts):
    """Convex hull of the pixel squares of integer points: conv(verts) ⊕ [0,1]².

    verts: (k, 2) int64 pixel coordinates, k >= 1. Returns (h, 2) float64 hull vertices in positive
    (shoelace) order, starting at the lowest x (then lowest y), no repeated or collinear vertices.
    """
    k = verts.shape[0]
    pts = np.empty((4 * k, 2), np.int64)
    for i in range(k):
        for c in range(4):
            pts[4 * i + c, 0] = verts[i, 0] + _PIXEL_CORNERS[c, 0]
            pts[4 * i + c, 1] = verts[i, 1] + _PIXEL_CORNERS[c, 1]
    # Sort by x, then y (insertion sort: few points, and it compiles quickly).
    p = pts
    for i in range(1, p.shape[0]):
        x, y = p[i, 0], p[i, 1]
        j = i - 1
        while j >= 0 and (p[j, 0] > x or (p[j, 0] == x and p[j, 1] > y)):
            p[j + 1, 0], p[j + 1, 1] = p[j, 0], p[j, 1]
            j -= 1
        p[j + 1, 0], p[j + 1, 1] = x, y
    # Andrew's monotone chain; popping on cross <= 0 drops collinear and repeated points.
    hull = np.empty((2 * p.shape[0] + 1, 2), np.int64)
    h = 0
    for i in range(p.shape[0]):
        while h >= 2 and _cross(hull[h - 2], hull[h - 1], p[i]) <= 0:
            h -= 1
        hull[h, 0], hull[h, 1] = p[i, 0], p[i, 1]  # by element: no broadcast check to compile
        h += 1
    lower = h + 1
    for i in range(p.shape[0] - 2, -1, -1):
        while h >= lower and _cross(hull[h - 2], hull[h - 1], p[i]) <= 0:
            h -= 1
        hull[h, 0], hull[h, 1] = p[i, 0], p[i, 1]  # by element: no broadcast check to compile
        h += 1
    return hull[: h - 1].astype(np.float64)


@njit(cache=True)
def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


@njit(cache=True)
def edge_normals(v):
    """(h, 2) outward unit normals of a positive-order convex polygon's edges v[k] -> v[k+1].

    Axis-aligned edges get exact (±1, 0) / (0, ±1). A one-point polygon gets (0, 0).
    """
    h = v.shape[0]
    out = np.zeros((h, 2))
    if h < 2:
        return out
    for k in range(h):
        ex = v[(k + 1) % h, 0] - v[k, 0]
        ey = v[(k + 1) % h, 1] - v[k, 1]
        if ex == 0.0:
            out[k, 0] = 1.0 if ey > 0 else -1.0
        elif ey == 0.0:
            out[k, 1] = -1.0 if ex > 0 else 1.0
        else:
            length = np.sqrt(ex * ex + ey * ey)
            out[k, 0] = ey / length
            out[k, 1] = -ex / length
    return out


@njit(cache=True)
def _build(kind, size, vert_start, verts, exact):
    n = kind.shape[0]
    counts = np.empty(n, np.int64)
    total_bound = 0
    for i in range(n):
        total_bound += 4 * max(vert_start[i + 1] - vert_start[i], 1) + 4
    buf = np.empty((total_bound, 2))
    shape = np.empty(n, np.int8)
    radius = np.zeros(n)
    at = 0
    for i in range(n):
        k = kind[i] if exact else KIND_BOX
        if k == KIND_POLYGON and vert_start[i + 1] - vert_start[i] == 0:
            k = KIND_BOX  # a polygon without vertices collides as its box
        shape[i] = k
        if k == KIND_CIRCLE:
            radius[i] = 0.5 * size[i, 0]
            buf[at, 0] = radius[i]
            buf[at, 1] = radius[i]
            counts[i] = 1
        elif k == KIND_POLYGON:
            hull = pixel_hull(verts[vert_start[i] : vert_start[i + 1]])
            for r in range(hull.shape[0]):  # by element: no broadcast check to compile
                buf[at + r, 0], buf[at + r, 1] = hull[r, 0], hull[r, 1]
            counts[i] = hull.shape[0]
        else:
            w = size[i, 0]
            h = size[i, 1]
            buf[at, 0], buf[at, 1] = 0.0, 0.0
            buf[at + 1, 0], buf[at + 1, 1] = w, 0.0
            buf[at + 2, 0], buf[at + 2, 1] = w, h
            buf[at + 3, 0], buf[at + 3, 1] = 0.0, h
            counts[i] = 4
        at += counts[i]
    start = np.zeros(n + 1, np.int64)
    for i in range(n):
        start[i + 1] = start[i] + counts[i]
    core = buf[:at].copy()
    normals = np.zeros((at, 2))
    for i in range(n):
        edges = edge_normals(core[start[i] : start[i + 1]])
        for r in range(edges.shape[0]):  # by element: no broadcast check to compile
            normals[start[i] + r, 0], normals[start[i] + r, 1] = edges[r, 0], edges[r, 1]
    return shape, radius, start, core, normals


def build_cores(bodies: Bodies, geometry: str) -> Cores:
    """The exact shapes of `bodies` under `geometry` ("box": every object as its box; "exact")."""
    if geometry not in GEOMETRIES:
        raise ValueError(f"unknown geometry {geometry!r}; expected one of {', '.join(GEOMETRIES)}")
    shape, radius, start, verts, normals = _build(
        np.ascontiguousarray(bodies.kind, np.int8),
        np.ascontiguousarray(bodies.size, np.float64),
        np.ascontiguousarray(bodies.vert_start, np.int64),
        np.ascontiguousarray(bodies.verts, np.int64).reshape(-1, 2),
        geometry == "exact",
    )
    return Cores(shape=shape, radius=radius, start=start, verts=verts, normals=normals)
