"""Contact on a curved relative path (engine/models/exact/arccontact.py): the first instant two
shapes touch when one falls and the other stands, against dense sampling of the overlap along the
parabola, and the cases the rules name (touching and leaving comes back; pressed with no speed is a
contact now); the quartic's first entry against numpy's roots."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.engine.contact import penetration
from collide2d.engine.events import AXIS_Y
from collide2d.engine.models.exact.arccontact import Arc, Core, arc_contact, quartic_entry
from collide2d.engine.shapes import build_cores
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, Bodies, Looks

KINDS = (KIND_BOX, KIND_CIRCLE, KIND_POLYGON)


def shape(kind, w, h):
    """(kind, radius, vertices, normals, w, h) of one object's exact shape."""
    verts, start = np.zeros((0, 2), np.int64), np.zeros(2, np.int64)
    if kind == KIND_POLYGON:
        verts = np.array([[0, 0], [w, 2], [w - 3, h], [1, h - 2]], np.int64)
        start = np.array([0, 4])
    bodies = Bodies(
        kind=np.array([kind], np.int8),
        pos=np.zeros((1, 2)),
        size=np.array([[w, h]], float),
        vel=np.zeros((1, 2)),
        mass=np.ones(1),
        static=np.zeros(1, bool),
        vert_start=start,
        verts=verts,
        looks=Looks(color=np.ones(1, np.uint8), fill=np.zeros(1, bool)),
    )
    c = build_cores(bodies, "exact")
    rows = slice(c.start[0], c.start[1])
    return int(c.shape[0]), float(c.radius[0]), c.verts[rows], c.normals[rows], w, h


def depth(A, B, q):
    return penetration(q[0], q[1], A[0], A[4], A[5], A[1], A[2], A[3],
                       B[0], B[4], B[5], B[1], B[2], B[3])[0]  # fmt: skip


def contact(A, B, q, u, a, now=0.0):
    path = Arc(q[0], q[1], u[0], u[1], a[0], a[1])
    return arc_contact(path, Core(*A[:4]), Core(*B[:4]), now)


def test_the_first_contact_is_where_sampling_first_sees_an_overlap():
    rng = np.random.default_rng(7)
    step = 2e-4
    ts = np.arange(0.0, 2.0, step)
    met = 0
    for _ in range(200):
        ka, kb = rng.choice(KINDS, 2)
        wa, wb = (float(x) for x in rng.integers(4, 20, 2))
        A = shape(ka, wa, wa if ka == KIND_CIRCLE else float(rng.integers(4, 20)))
        B = shape(kb, wb, wb if kb == KIND_CIRCLE else float(rng.integers(4, 20)))
        q = rng.uniform(-40, 40, 2)
        u = -q * rng.uniform(0.2, 1.5) + rng.uniform(-30, 30, 2)  # mostly closing in
        a = rng.uniform(-300, 300, 2)
        if depth(A, B, q) > -1e-6:
            continue
        t, _, nx, ny = contact(A, B, q, u, a)
        path = q + u * ts[:, None] + 0.5 * a * ts[:, None] ** 2
        inside = np.flatnonzero([depth(A, B, p) > 1e-9 for p in path])
        if inside.size:
            first = ts[inside[0]]
            assert first - step - 1e-9 <= t <= first + 1e-12
        else:
            assert not t < 2.0 - step
        if t < 2.0:
            met += 1
            p = q + u * t + 0.5 * a * t * t
            assert abs(depth(A, B, p)) <= 1e-7  # touching, not inside
            v = u + a * t
            assert v[0] * nx + v[1] * ny <= 1e-9  # coming in along the normal
    assert met >= 40  # the cases met a contact, not only misses


@pytest.mark.parametrize("kind", KINDS)
def test_touching_and_leaving_comes_back_on_the_parabola(kind):
    # B just bounced off A's top (B above A, y down) at 100 px/s, pulled back at 980 px/s²:
    # it meets A again after 2 v / g, not at once
    A = shape(KIND_BOX, 40.0, 20.0)
    B = shape(kind, 10.0, 10.0)
    bottom = B[2][:, 1].max() + B[1]  # B's lowest point below its corner (a pixel hull's too)
    q = np.array([10.0, -bottom])
    t, code, nx, ny = contact(A, B, q, np.array([0.0, -100.0]), np.array([0.0, 980.0]))
    assert t == pytest.approx(200.0 / 980.0, rel=1e-13)
    assert (code, nx, ny) == (AXIS_Y, 0.0, -1.0)


def test_touching_with_no_speed_while_pressed_together_is_a_contact_now():
    A, B = shape(KIND_BOX, 40.0, 20.0), shape(KIND_BOX, 10.0, 10.0)
    q = np.array([10.0, -10.0])
    t, code, _, ny = contact(A, B, q, np.array([5.0, 0.0]), np.array([0.0, 980.0]))
    assert t == 0.0 and code == AXIS_Y and ny == -1.0
    # pulled apart instead: no contact
    t, *_ = contact(A, B, q, np.array([5.0, 0.0]), np.array([0.0, -980.0]))
    assert t == np.inf


def test_the_quartics_first_entry_is_numpys_first_root_going_down():
    rng = np.random.default_rng(3)
    for _ in range(3000):
        c = rng.normal(size=5) * 10.0 ** rng.uniform(-3, 3, 5)
        c[0] = abs(c[0]) + 1e-3
        got = quartic_entry(*c)
        roots = np.sort([r.real for r in np.roots(c) if abs(r.imag) <= 1e-9 * max(1, abs(r))])
        want = np.inf
        slope = np.polyder(c)
        for r in roots[roots >= 0]:
            if np.polyval(slope, r) < 0 and (r > 0 or np.polyval(c, 0.0) > 0):
                want = r
                break
        if np.isinf(want):
            assert np.isinf(got) or abs(np.polyval(c, got)) <= 1e-6 * np.abs(c).max()
        else:
            assert got == pytest.approx(want, rel=1e-7, abs=1e-9)
