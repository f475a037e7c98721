"""Contact geometry: times of impact and normals, against analytic cases and independent references.

The references here share no code with engine.contact: Minkowski differences are built as the
convex hull of all pairwise differences of the pixel-square corners, overlap is tested point by
point, and times of impact are found by scanning the line and bisecting.
"""

import math

import numpy as np
import pytest
from engine_refs import pixel_corners, ref_hull
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine import jit
from collide2d.engine.contact import (
    box_next_contact,
    box_penetration,
    box_reach,
    box_sweep,
    disc_roots,
    next_contact,
    penetration,
    polygon_sweep,
    rounded_sweep,
)
from collide2d.engine.events import AXIS_NORMAL, AXIS_X, AXIS_XY, AXIS_Y
from collide2d.engine.models.stepped.approach import box_clip, box_overlap_axis, box_step_contact
from collide2d.engine.shapes import edge_normals, pixel_hull
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON

INF = math.inf

# --- independent references ---------------------------------------------------------------------


def strictly_inside(poly, p):
    """Whether the point p (2,) (or each of the points (k, 2)) lies strictly inside the convex
    polygon."""
    single = np.ndim(p) == 1
    p = np.atleast_2d(p)
    a = poly[None, :, :]
    b = np.roll(poly, -1, axis=0)[None, :, :]
    cross = (b[..., 0] - a[..., 0]) * (p[:, None, 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (
        p[:, None, 0] - a[..., 0]
    )
    inside = (cross > 0).all(axis=1)
    return bool(inside[0]) if single else inside


def nearest_on_polygon(poly, p):
    """The points of the polygon's boundary nearest to the point(s) p (k, 2)."""
    p = np.atleast_2d(p)
    a = poly[None, :, :]
    e = (np.roll(poly, -1, axis=0) - poly)[None, :, :]
    lam = np.clip(((p[:, None, :] - a) * e).sum(-1) / (e * e).sum(-1), 0.0, 1.0)
    foot = a + lam[..., None] * e
    d = np.hypot(*(p[:, None, :] - foot).transpose(2, 0, 1))
    k = d.argmin(axis=1)
    return foot[np.arange(len(p)), k], d[np.arange(len(p)), k]


def first_contact(overlaps, t_max, samples=4000):
    """The first t in [0, t_max] at which overlaps(t) (vectorised over t), by a scan and 80
    bisections."""
    ts = np.linspace(0.0, t_max, samples + 1)
    hits = np.nonzero(overlaps(ts))[0]
    if len(hits) == 0:
        return None
    if hits[0] == 0:
        return 0.0
    lo, hi = ts[hits[0] - 1], ts[hits[0]]
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if overlaps(np.array([mid]))[0] else (mid, hi)
    return hi


def core(verts):
    hull = pixel_hull(np.asarray(verts, np.int64))
    return hull, edge_normals(hull)


# --- boxes ----------------------------------------------------------------------------------------


def test_head_on_boxes_meet_and_part_at_the_analytic_times():
    # A 10x10 at the origin; B 10x10 30 px to its right closing at 10 px/s.
    t_enter, t_exit, code, nx, ny = box_sweep(30.0, 0.0, -10.0, 0.0, 10.0, 10.0, 10.0, 10.0)
    assert (t_enter, t_exit, code, nx, ny) == (2.0, 4.0, AXIS_X, 1.0, 0.0)
    t_enter, t_exit, code, nx, ny = box_sweep(0.0, -25.0, 0.0, 5.0, 10.0, 10.0, 4.0, 5.0)
    assert (t_enter, code, nx, ny) == (4.0, AXIS_Y, 0.0, -1.0)  # B above, coming down


def test_the_contact_axis_is_the_one_that_started_overlapping_last():
    # B below-right of A: x overlap starts at t = 1, y overlap at t = 2 -> the y faces meet.
    t_enter, _, code, nx, ny = box_sweep(20.0, 30.0, -10.0, -10.0, 10.0, 10.0, 10.0, 10.0)
    assert (t_enter, code, nx, ny) == (2.0, AXIS_Y, 0.0, 1.0)
    # Exactly corner to corner: both at once, AXIS_XY with both signs.
    t_enter, _, code, nx, ny = box_sweep(20.0, 20.0, -10.0, -10.0, 10.0, 10.0, 10.0, 10.0)
    assert (t_enter, code, nx, ny) == (1.0, AXIS_XY, 1.0, 1.0)


def test_grazing_and_sliding_boxes_never_collide():
    # Corners pass exactly through each other: the overlap has zero length.
    t_enter, t_exit, *_ = box_sweep(20.0, 0.0, -10.0, -10.0, 10.0, 10.0, 10.0, 10.0)
    assert not t_enter < t_exit
    assert (t_enter, t_exit) == (1.0, 1.0)
    assert box_next_contact(20.0, 0.0, -10.0, -10.0, 10.0, 10.0, 10.0, 10.0)[0] == INF
    # B rests on A's bottom face and slides along it.
    assert box_next_contact(15.0, 10.0, -3.0, 0.0, 10.0, 10.0, 10.0, 10.0)[0] == INF


def test_robust_rules_for_boxes_already_in_contact():
    w = 10.0
    # Touching and approaching: now. Touching and separating: never.
    assert box_next_contact(w, 0.0, -1.0, 0.0, w, w, w, w)[:2] == (0.0, AXIS_X)
    assert box_next_contact(w, 0.0, 1.0, 0.0, w, w, w, w)[0] == INF
    # Overlapping by a rounding error: approaching collides now, separating makes no event.
    q = w - 1e-13
    t, code, nx, ny = box_next_contact(q, 0.0, -1.0, 0.0, w, w, w, w)
    assert (t, code, nx) == (0.0, AXIS_X, 1.0)
    assert box_next_contact(q, 0.0, 1.0, 0.0, w, w, w, w)[0] == INF
    # Never in the past: a pair that already passed each other has no contact.
    assert box_next_contact(-30.0, 0.0, -5.0, 0.0, w, w, w, w)[0] == INF


def test_box_penetration_is_the_smallest_push_apart():
    depth, code, nx, ny = box_penetration(8.0, 5.0, 10.0, 10.0, 10.0, 10.0)
    assert (depth, code, nx, ny) == (2.0, AXIS_X, 1.0, 0.0)
    depth, code, nx, ny = box_penetration(-3.0, -9.0, 10.0, 10.0, 10.0, 10.0)
    assert (depth, code, nx, ny) == (1.0, AXIS_Y, 0.0, -1.0)
    assert box_penetration(7.0, 7.0, 10.0, 10.0, 10.0, 10.0)[:2] == (3.0, AXIS_XY)
    assert box_penetration(10.0, 0.0, 10.0, 10.0, 10.0, 10.0)[0] == 0.0  # touching


def test_stepped_axis_follows_the_smaller_overlap_width_when_the_motion_cannot_tell():
    # B (2 x 20) sits inside A's x-range: overlap widths 2 (x) and 8 (y) -> axis x
    # (docs/models.md#stepped-contact-normal-and-push), and the push along x that parts them is the
    # distance to A's nearer side face.
    depth, depth_y, code, nx, ny = box_overlap_axis(40.0, 2.0, 100.0, 10.0, 2.0, 20.0)
    assert (code, nx, depth) == (AXIS_X, -1.0, 42.0)
    assert box_overlap_axis(10.0, 0.0, 10.0, 10.0, 10.0, 10.0)[0] == 0.0


@settings(max_examples=30, deadline=None)
@given(
    st.floats(-60, 60),
    st.floats(-60, 60),
    st.floats(-20, 20),
    st.floats(-20, 20),
    st.floats(0.5, 3.0),
)
def test_box_reach_never_rules_out_a_contact_in_time(qx, qy, ux, uy, dt):
    t, *_ = box_next_contact(qx, qy, ux, uy, 10.0, 8.0, 6.0, 12.0)
    if t <= dt:
        assert box_reach(qx, qy, ux, uy, 10.0, 8.0, 6.0, 12.0, dt)


def _reach_with_branches(qx, qy, ux, uy, wa, ha, wb, hb, dt):
    """box_reach as first written, axis by axis with branches: the reference the branchless
    form must equal."""
    for q, u, lo, hi in ((qx, ux, -wb, wa), (qy, uy, -hb, ha)):
        if q > hi:
            gap, closing = q - hi, -u
        elif q < lo:
            gap, closing = lo - q, u
        else:
            continue
        if not closing > 0.0 or gap > closing * dt:
            return False
    return True


_edge = st.sampled_from([0.0, -0.0, 10.0, -6.0, 8.0, -12.0, 1e300, -1e300, 5e-324])


@settings(max_examples=200, deadline=None)
@given(
    st.one_of(st.floats(-60, 60), _edge),
    st.one_of(st.floats(-60, 60), _edge),
    st.one_of(st.floats(-1e3, 1e3), _edge),
    st.one_of(st.floats(-1e3, 1e3), _edge),
    st.sampled_from([1 / 60, 1 / 600, 0.5, 0.0]),
    st.booleans(),
)
def test_box_reach_is_the_test_with_branches_in_both_lanes(qx, qy, ux, uy, dt, compiled):
    # the edges (q on a side of [lo, hi], u = +-0, huge and subnormal numbers) are where a
    # rewrite without branches could part from the plain test
    with jit.lane(compiled):
        got = box_reach(qx, qy, ux, uy, 10.0, 8.0, 6.0, 12.0, dt)
    assert got == _reach_with_branches(qx, qy, ux, uy, 10.0, 8.0, 6.0, 12.0, dt)


# --- circles --------------------------------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(st.floats(-1, 1), st.floats(0.2, 3.0), st.floats(2, 12), st.floats(2, 12))
def test_circle_circle_time_of_impact_matches_the_distance(offset, speed, ra, rb):
    # B's centre starts 50 px right of A's, offset sideways, and moves left.
    R = ra + rb
    py = offset * R * 0.9  # the line passes within R of A's centre: a real hit
    t1, t2 = disc_roots(0.0, 0.0, R, 50.0, py, -speed, 0.0)
    analytic = (50.0 - math.sqrt(R * R - py * py)) / speed
    assert abs(t1 - analytic) <= 1e-12 * max(1.0, analytic)
    assert abs(math.hypot(50.0 - speed * t1, py) - R) < 1e-9


def circle_cores(d):
    r = d / 2.0
    return np.array([[r, r]]), np.zeros((1, 2)), r


def test_oblique_circle_contact_has_the_centre_line_as_normal():
    va, na, ra = circle_cores(10.0)
    vb, nb, rb = circle_cores(10.0)
    # B's corner 30 px right and 6 px down of A's, moving left: centres meet at distance 10.
    t, code, nx, ny = next_contact(
        30.0,
        6.0,
        -10.0,
        0.0,
        KIND_CIRCLE,
        10.0,
        10.0,
        ra,
        va,
        na,
        KIND_CIRCLE,
        10.0,
        10.0,
        rb,
        vb,
        nb,
    )
    assert abs(t - (30.0 - 8.0) / 10.0) < 1e-12  # sqrt(10^2 - 6^2) = 8
    assert code == AXIS_NORMAL and abs(nx - 0.8) < 1e-12 and abs(ny - 0.6) < 1e-12


def test_a_circle_misses_a_box_corner_its_box_would_hit():
    va = np.array([[0.0, 0], [10, 0], [10, 10], [0, 10]])
    na = edge_normals(va)
    vb, nb, rb = circle_cores(10.0)
    # The disc's centre runs along (1, -1) 6 px beyond A's corner (10, 10): its box clips A's
    # corner, the disc (radius 5) stays clear.
    along = np.array([1.0, -1.0]) / math.sqrt(2.0)
    centre = np.array([10.0, 10.0]) + 6.0 * np.array([1.0, 1.0]) / math.sqrt(2.0) - 30.0 * along
    q, u = tuple(centre - 5.0), tuple(10.0 * along)
    assert box_next_contact(*q, *u, 10.0, 10.0, 10.0, 10.0)[0] < INF
    t, *_ = next_contact(
        *q, *u, KIND_BOX, 10.0, 10.0, 0.0, va, na, KIND_CIRCLE, 10.0, 10.0, rb, vb, nb
    )
    assert t == INF
    # Aimed at the corner along the diagonal it touches when the centre is r from the corner.
    s0 = 20.0
    t, code, nx, ny = next_contact(
        10.0 - 5.0 + s0,
        10.0 - 5.0 + s0,
        -1.0,
        -1.0,
        KIND_BOX,
        10.0,
        10.0,
        0.0,
        va,
        na,
        KIND_CIRCLE,
        10.0,
        10.0,
        rb,
        vb,
        nb,
    )
    assert abs(t - (s0 - 5.0 / math.sqrt(2.0))) < 1e-12
    assert code == AXIS_NORMAL and abs(nx - ny) < 1e-15 and abs(nx - 1 / math.sqrt(2)) < 1e-12


# --- random convex shapes against the references ------------------------------------------------

polygons = st.lists(
    st.tuples(st.integers(0, 12), st.integers(0, 12)), min_size=1, max_size=6, unique=True
)


@settings(max_examples=30, deadline=None)
@given(polygons, polygons, st.floats(0, 2 * math.pi), st.floats(2.0, 20.0))
def test_polygon_time_of_impact_and_normal_match_the_reference(pa, pb, angle, speed):
    va, na = core(pa)
    vb, nb = core(pb)
    # M = A ⊕ (-B) from all pairwise corner differences; aim through an interior point of it.
    diffs = (pixel_corners(pa)[:, None, :] - pixel_corners(pb)[None, :, :]).reshape(-1, 2)
    m = ref_hull(diffs)
    target = pixel_corners(pa).mean(axis=0) - pixel_corners(pb).mean(axis=0)
    direction = np.array([math.cos(angle), math.sin(angle)])
    q0 = target + 60.0 * direction
    u = -speed * direction
    t_enter, t_exit, code, nx, ny = polygon_sweep(va, na, vb, nb, *q0, *u)
    t_ref = first_contact(lambda t: strictly_inside(m, q0 + u * t[:, None]), 60.0 / speed)
    assert t_ref is not None and t_enter < t_exit
    assert abs(t_enter - t_ref) <= 1e-9 * max(1.0, t_ref)
    # The normal is M's outward normal where the line enters: q lies on that supporting line.
    if code != AXIS_XY:
        n = np.array([nx, ny])
        assert abs(np.hypot(nx, ny) - 1.0) < 1e-12
        q = q0 + u * t_enter
        assert abs(float(n @ q) - float((m @ n).max())) < 1e-9
        assert float(n @ u) < 0


@settings(max_examples=30, deadline=None)
@given(
    polygons,
    st.integers(2, 14),
    st.floats(0, 2 * math.pi),
    st.floats(2.0, 20.0),
    st.floats(-0.9, 0.9),
)
def test_circle_against_polygon_matches_the_reference(pa, d, angle, speed, aim):
    va, na = core(pa)
    poly = ref_hull(pixel_corners(pa))
    r = d / 2.0
    centre_offset = np.array([r, r])  # the circle's centre relative to its box corner
    direction = np.array([math.cos(angle), math.sin(angle)])
    side = np.array([-direction[1], direction[0]])
    target = poly.mean(axis=0) + aim * r * side  # passes within r of an interior point
    q0 = target - centre_offset + 60.0 * direction
    u = -speed * direction

    def overlaps(t):
        centres = q0 + u * t[:, None] + centre_offset
        inside = strictly_inside(poly, centres)
        return inside | (nearest_on_polygon(poly, centres)[1] < r)

    t_ref = first_contact(overlaps, 60.0 / speed)
    vb, nb = np.array([[r, r]]), np.zeros((1, 2))
    t_enter, t_exit, code, nx, ny = rounded_sweep(va, na, 1.0, -r, -r, r, *q0, *u)
    assert t_ref is not None and t_enter < t_exit
    assert abs(t_enter - t_ref) <= 1e-9 * max(1.0, t_ref)
    # The same through the dispatcher, and the normal runs from A's nearest point to the centre.
    t, code, nx, ny = next_contact(
        *q0, *u, KIND_POLYGON, 0.0, 0.0, 0.0, va, na, KIND_CIRCLE, float(d), float(d), r, vb, nb
    )
    assert t == t_enter
    centre = q0 + u * t + centre_offset
    foot, dist = nearest_on_polygon(poly, centre)
    assert abs(dist[0] - r) < 1e-9
    assert np.allclose([nx, ny], (centre - foot[0]) / dist[0], atol=1e-6)


@settings(max_examples=30, deadline=None)
@given(polygons, polygons, st.floats(-6, 14), st.floats(-6, 14))
def test_penetration_agrees_with_the_reference_overlap(pa, pb, qx, qy):
    va, na = core(pa)
    vb, nb = core(pb)
    m = ref_hull((pixel_corners(pa)[:, None, :] - pixel_corners(pb)[None, :, :]).reshape(-1, 2))
    depth, code, nx, ny = penetration(
        qx, qy, KIND_POLYGON, 0.0, 0.0, 0.0, va, na, KIND_POLYGON, 0.0, 0.0, 0.0, vb, nb
    )
    inside = strictly_inside(m, np.array([qx, qy]))
    if abs(depth) > 1e-9:
        assert (depth > 0) == inside
    if inside and code != AXIS_XY:
        # Pushing B out by depth along the normal brings q onto M's boundary.
        q_out = np.array([qx, qy]) + depth * np.array([nx, ny])
        assert not strictly_inside(m, q_out + 1e-9 * np.array([nx, ny]))


def test_a_static_point_pair_has_no_contact():
    va, na = core([[0, 0]])
    vb, nb = core([[0, 0]])
    assert polygon_sweep(va, na, vb, nb, 5.0, 0.0, 0.0, 0.0)[0] == INF


@pytest.mark.parametrize("u", [(-10.0, 0.0), (0.0, -10.0)])
def test_a_polygon_meeting_a_box_face_gets_that_axis(u):
    va = np.array([[0.0, 0], [10, 0], [10, 10], [0, 10]])
    vb, nb = core([[0, 0], [4, 0], [2, 3]])
    q = (30.0, 2.0) if u[0] else (2.0, 30.0)
    t, code, nx, ny = next_contact(
        *q, *u, KIND_BOX, 10.0, 10.0, 0.0, va, edge_normals(va), KIND_POLYGON, 5.0, 4.0, 0.0, vb, nb
    )
    assert t == 2.0 and code == (AXIS_X if u[0] else AXIS_Y)


def test_the_stepped_normal_is_the_axis_the_pair_came_in_by():
    # the glancing pass: 10x10 boxes offset by 5 px, B coming in from A's left at 26
    # px/s over a 1 s step; it went 6 px deep in x, deeper than the 5 px of y overlap, yet the
    # normal is x (the smaller overlap would say y), pointing back the way B came, and the push
    # is twice the 6 px: B ends where a bounce at the contact instant would put it.
    push, push_y, code, nx, ny = box_step_contact(-4.0, 5.0, 26.0, 0.0, 10, 10, 10, 10, 1.0)
    assert (push, push_y, code, nx, ny) == (12.0, 0.0, AXIS_X, -1.0, 0.0)
    assert box_overlap_axis(-4.0, 5.0, 10, 10, 10, 10)[2] == AXIS_Y  # the old rule
    # deeper than half way through along x: still the side it came in by
    push, _, code, nx, _ = box_step_contact(-1.0, 9.5, 9.5, 0.0, 10, 10, 10, 10, 1.0)
    assert (code, nx, push) == (AXIS_X, -1.0, 18.0)
    # coming down onto A's top face: y, pointing up
    _, _, code, nx, ny = box_step_contact(3.0, -7.0, 0.0, 5.0, 10, 10, 10, 10, 1.0)
    assert (code, nx, ny) == (AXIS_Y, 0.0, -1.0)
    # corner to corner within TIE_PX: both axes, each pushed twice its own depth
    assert box_step_contact(-8.0, -8.0, 4.0, 4.0, 10, 10, 10, 10, 1.0) == (
        4.0, 4.0, AXIS_XY, -1.0, -1.0,
    )  # fmt: skip
    # overlapping since before the previous step, or not moving: the smaller overlap decides
    assert box_step_contact(-4.0, 5.0, 1.0, 0.0, 10, 10, 10, 10, 1.0)[:3] == (5.0, 0.0, AXIS_Y)
    assert box_step_contact(-4.0, 5.0, 0.0, 0.0, 10, 10, 10, 10, 1.0)[:3] == (5.0, 0.0, AXIS_Y)
    # apart, and no corner cut within the step: no contact
    assert box_step_contact(-11.0, 0.0, 5.0, 0.0, 10, 10, 10, 10, 1.0)[0] == 0.0


def test_a_corner_cut_within_a_step_is_a_clip_and_a_pass_through_is_not():
    # B's corner cuts A's top-left corner between two step ends where the boxes are apart
    assert box_clip(-5.0, -10.5, 5.5, -5.5, 10, 10, 10, 10, 1.0)
    push, _, code, nx, ny = box_step_contact(-5.0, -10.5, 5.5, -5.5, 10, 10, 10, 10, 1.0)
    assert code in (AXIS_X, AXIS_Y, AXIS_XY) and push > 0.0
    # B passes wholly through A along x within one step: tunnelling, the stepped model's own
    assert not box_clip(15.0, 0.0, 40.0, 0.0, 10, 10, 10, 10, 1.0)
    assert box_step_contact(15.0, 0.0, 40.0, 0.0, 10, 10, 10, 10, 1.0)[0] == 0.0
    # a corner cut that is still overlapping at the step's end is an overlap, not a clip
    assert not box_clip(-9.0, -9.0, 2.0, 2.0, 10, 10, 10, 10, 1.0)
