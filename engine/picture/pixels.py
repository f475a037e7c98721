"""Pixels of one object: DDA lines, boxes, midpoint circles, polygons, fills
(docs/drawing.md#shapes).

The drawing primitives `engine.picture.raster` paints frames with, each a numba kernel writing
palette indices into a `(H, W) uint8` buffer within an inclusive clip rectangle (cx0, cy0, cx1, cy1)
that the caller has already intersected with the frame. All in exact integer arithmetic on rounded
positions:
- outlines are the paper's DDA lines (section II.B) with exact rounding (`_dda_start`): from
  (x0, y0) to (x1, y1), n = max(|dx|, |dy|), points k = 0..n at x0 + floor((2 k dx + n) / (2 n));
- a box w x h at (x, y) is the DDA outline through its corners (x, y), (x+w-1, y), (x+w-1, y+h-1),
  (x, y+h-1); a polygon is the closed DDA outline through `(x, y) + verts`;
- a circle of diameter d fits the d x d box at (x, y) with the midpoint circle algorithm, worked in
  doubled coordinates so that even diameters are centred too (`_circle`);
- `fill` paints whole boxes, circle rows between the outline's extremes, and polygon pixels whose
  centres are inside (even-odd rule).
`dda_line` and `midpoint_circle` give the pixels of a line and a circle as arrays, for tests and
people.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit, overload
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON

# --------------------------------------------------------------------------------------------
# Pixel kernels. Every kernel takes an inclusive clip rectangle (cx0, cy0, cx1, cy1) that the caller
# has already intersected with the frame, and never writes outside it.


@njit(cache=True, inline="always")
def _plot(buf, x, y, c, cx0, cy0, cx1, cy1):
    if cx0 <= x and x <= cx1 and cy0 <= y and y <= cy1:
        buf[y, x] = c


@njit(cache=True, inline="always")
def _fill_rect(buf, x0, y0, x1, y1, c, cx0, cy0, cx1, cy1):
    """Paint the inclusive rectangle [x0, x1] x [y0, y1], clipped."""
    xa = max(x0, cx0)
    xb = min(x1, cx1)
    ya = max(y0, cy0)
    yb = min(y1, cy1)
    for y in range(ya, yb + 1):
        for x in range(xa, xb + 1):
            buf[y, x] = c


@njit(cache=True)
def _dda_start(da, n):
    """Exact DDA stepping along one axis of a line of n >= 1 steps with total change da.

    The paper's DDA (section II.B) takes n = max(|dx|, |dy|) steps of x_inc = dx/n and plots
    round(x0 + k*x_inc), k = 0..n. Rounding as floor(v + 1/2) and clearing the fraction gives
        x_k = x0 + floor(k*dx/n + 1/2) = x0 + floor((2*k*dx + n) / (2*n)),
    an exact integer formula. At k = 0 it is x0, at k = n it is x0 + dx + floor(1/2) = x1, so both
    endpoints are drawn exactly. To avoid a division per pixel, the numerator N_k = 2*k*dx + n is
    kept as a quotient q and remainder r of 2n (N_0 = n: q = 0, r = n); each step adds 2*dx =
    step*2n + inc, so q += step, r += inc, and one carry when r reaches 2n. Returns (step, inc).
    """
    step = (2 * da) // (2 * n)
    return step, 2 * da - step * 2 * n


@njit(cache=True)
def _line(buf, x0, y0, x1, y1, c, cx0, cy0, cx1, cy1):
    """DDA line from (x0, y0) to (x1, y1), both endpoints included, clipped (see `_dda_start`)."""
    if max(x0, x1) < cx0 or min(x0, x1) > cx1 or max(y0, y1) < cy0 or min(y0, y1) > cy1:
        return
    n = max(abs(x1 - x0), abs(y1 - y0))
    if n == 0:
        _plot(buf, x0, y0, c, cx0, cy0, cx1, cy1)
        return
    two_n = 2 * n
    sx, ix = _dda_start(x1 - x0, n)
    sy, iy = _dda_start(y1 - y0, n)
    x = x0
    y = y0
    rx = n
    ry = n
    for _ in range(n + 1):
        _plot(buf, x, y, c, cx0, cy0, cx1, cy1)
        x, rx = _dda_next(x, rx, sx, ix, two_n)
        y, ry = _dda_next(y, ry, sy, iy, two_n)


@njit(cache=True, inline="always")
def _dda_next(v, r, step, extra, two_n):
    """One DDA step on one axis: the coordinate and remainder after it (whole step `step`, and one
    more pixel each time the remainder, growing by `extra`, reaches `two_n`)."""
    v += step
    r += extra
    if r >= two_n:
        return v + 1, r - two_n
    return v, r


@njit(cache=True)
def _line_points(x0, y0, x1, y1, out):
    """The pixels `_line` plots, in order, into out (n+1, 2); the same stepping as `_line`."""
    n = out.shape[0] - 1
    if n == 0:
        out[0, 0] = x0
        out[0, 1] = y0
        return
    two_n = 2 * n
    sx, ix = _dda_start(x1 - x0, n)
    sy, iy = _dda_start(y1 - y0, n)
    x = x0
    y = y0
    rx = n
    ry = n
    for k in range(n + 1):
        out[k, 0] = x
        out[k, 1] = y
        x, rx = _dda_next(x, rx, sx, ix, two_n)
        y, ry = _dda_next(y, ry, sy, iy, two_n)


@njit(cache=True, inline="always")
def _box(buf, x, y, w, h, c, fill, cx0, cy0, cx1, cy1):
    """A w x h box at (x, y): its whole box when filled, else DDA lines through its four corners.

    Between two corners on one row (or column) the DDA takes one pixel step per point along it and
    none across, so each side is the run of pixels between its corners, painted as a 1-pixel-wide
    rectangle.
    """
    if w <= 0 or h <= 0:
        return
    xr = x + w - 1
    yb = y + h - 1
    if fill:
        _fill_rect(buf, x, y, xr, yb, c, cx0, cy0, cx1, cy1)
        return
    _fill_rect(buf, x, y, xr, y, c, cx0, cy0, cx1, cy1)
    _fill_rect(buf, x, yb, xr, yb, c, cx0, cy0, cx1, cy1)
    _fill_rect(buf, x, y, x, yb, c, cx0, cy0, cx1, cy1)
    _fill_rect(buf, xr, y, xr, yb, c, cx0, cy0, cx1, cy1)


@njit(cache=True)
def _circle(buf, x, y, d, c, fill, half, cx0, cy0, cx1, cy1):
    """Midpoint circle of diameter d in the d x d box at (x, y); `half` is scratch of length >= d.

    Doubled coordinates make the centre and radius whole for every d: the box's pixel centres run
    over 2x .. 2x + 2(d-1), so the centre is cx2 = 2x + d - 1 (likewise cy2) and the radius, from
    the centre to the first and last pixel centre, is R = d - 1. Offsets (U, V) keep the parity of R
    so that (cx2 +- U)/2 is a whole pixel. Starting at (U, V) = (R, R mod 2), V grows by one pixel
    (2 doubled units) per step, and U drops by one pixel when the midpoint (U - 1, V) between the
    two candidate pixels lies outside the circle: (U-1)^2 + V^2 > R^2; the eight mirror images of
    each (U, V) with U >= V make the whole circle. For odd d = 2r + 1 every value is even and this
    is the classic integer midpoint algorithm of radius r; for even d the pixel centres sit half a
    pixel off the centre, which the doubled units represent exactly.

    Filled, each row is painted between the outline's extremes on that row: half[row] holds the
    largest |offset| (doubled) plotted on that row.
    """
    if d <= 0:
        return
    cx2 = 2 * x + d - 1
    cy2 = 2 * y + d - 1
    r = d - 1
    u = r
    v = r % 2
    if fill:
        for i in range(d):
            half[i] = -1
    while u >= v:
        if fill:
            # rows (cy2 +- v)/2 reach +-u; rows (cy2 +- u)/2 reach +-v (row index relative to y)
            lo = (r - v) // 2
            hi = (r + v) // 2
            if u > half[lo]:
                half[lo] = u
            if u > half[hi]:
                half[hi] = u
            lo = (r - u) // 2
            hi = (r + u) // 2
            if v > half[lo]:
                half[lo] = v
            if v > half[hi]:
                half[hi] = v
        else:
            xl = (cx2 - u) // 2
            xr = (cx2 + u) // 2
            yt = (cy2 - v) // 2
            yb = (cy2 + v) // 2
            _plot(buf, xl, yt, c, cx0, cy0, cx1, cy1)
            _plot(buf, xr, yt, c, cx0, cy0, cx1, cy1)
            _plot(buf, xl, yb, c, cx0, cy0, cx1, cy1)
            _plot(buf, xr, yb, c, cx0, cy0, cx1, cy1)
            xl = (cx2 - v) // 2
            xr = (cx2 + v) // 2
            yt = (cy2 - u) // 2
            yb = (cy2 + u) // 2
            _plot(buf, xl, yt, c, cx0, cy0, cx1, cy1)
            _plot(buf, xr, yt, c, cx0, cy0, cx1, cy1)
            _plot(buf, xl, yb, c, cx0, cy0, cx1, cy1)
            _plot(buf, xr, yb, c, cx0, cy0, cx1, cy1)
        v += 2
        if (u - 1) * (u - 1) + v * v > r * r:
            u -= 2
    if fill:
        for i in range(d):
            if half[i] >= 0:
                _fill_rect(
                    buf,
                    (cx2 - half[i]) // 2,
                    y + i,
                    (cx2 + half[i]) // 2,
                    y + i,
                    c,
                    cx0,
                    cy0,
                    cx1,
                    cy1,
                )


@njit(cache=True)
def _ceil_div(a, b):
    """ceil(a / b) for b > 0, exact."""
    return -((-a) // b)


@njit(cache=True)
def _polygon(buf, x, y, verts, s, e, c, fill, xs, cx0, cy0, cx1, cy1):
    """Closed DDA outline through (x, y) + verts[s:e]; filled, plus the pixels inside it.

    Inside (even-odd rule, one scanline per pixel row): a vertex (vx, vy) is the pixel (vx, vy), so
    pixel centres are the whole points. On row py an edge counts when py is in [min(y), max(y))
    of its ends (horizontal edges never count), which gives every row an even number of crossings;
    the crossing is at the rational x = ax + (py - ay) * (bx - ax) / (by - ay). Sorted, crossings
    pair up into spans xa <= px < xb, that is ceil(xa) <= px < ceil(xb); since ceil is monotone, the
    ceilings can be sorted instead of the rationals. Pixels exactly on the boundary follow this
    half-open rule; the outline drawn afterwards covers the boundary anyway. `xs` is scratch of
    length >= e - s.
    """
    m = e - s
    if m <= 0:
        return
    if fill and m >= 3:
        ymin = verts[s, 1]
        ymax = verts[s, 1]
        for j in range(s, e):
            ymin = min(ymin, verts[j, 1])
            ymax = max(ymax, verts[j, 1])
        for py in range(max(y + ymin, cy0), min(y + ymax, cy1) + 1):
            ly = py - y
            cnt = 0
            for j in range(m):
                ax = verts[s + j, 0]
                ay = verts[s + j, 1]
                jb = s + j + 1 if j + 1 < m else s
                bx = verts[jb, 0]
                by = verts[jb, 1]
                if (ay <= ly and ly < by) or (by <= ly and ly < ay):
                    num = (ly - ay) * (bx - ax)
                    den = by - ay
                    if den < 0:
                        num = -num
                        den = -den
                    xc = x + ax + _ceil_div(num, den)
                    # insertion into the sorted prefix xs[:cnt]
                    p = cnt
                    while p > 0 and xs[p - 1] > xc:
                        xs[p] = xs[p - 1]
                        p -= 1
                    xs[p] = xc
                    cnt += 1
            for k in range(0, cnt - 1, 2):
                _fill_rect(buf, xs[k], py, xs[k + 1] - 1, py, c, cx0, cy0, cx1, cy1)
    for j in range(m):
        jb = s + j + 1 if j + 1 < m else s
        _line(
            buf,
            x + verts[s + j, 0],
            y + verts[s + j, 1],
            x + verts[jb, 0],
            y + verts[jb, 1],
            c,
            cx0,
            cy0,
            cx1,
            cy1,
        )


@njit(cache=True, inline="always")
def _draw_one(buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1):
    """Draw object i at integer top-left (x, y), clipped to the inclusive rectangle."""
    k = kind[i]
    if k == KIND_BOX:
        _box(buf, x, y, wh[i, 0], wh[i, 1], color[i], fill[i], cx0, cy0, cx1, cy1)
    elif k == KIND_CIRCLE:
        _circle(buf, x, y, wh[i, 0], color[i], fill[i], scratch, cx0, cy0, cx1, cy1)
    elif k == KIND_POLYGON:
        _polygon(
            buf,
            x,
            y,
            verts,
            vert_start[i],
            vert_start[i + 1],
            color[i],
            fill[i],
            scratch,
            cx0,
            cy0,
            cx1,
            cy1,
        )


# A renderer's *shapes marker*: a zero-length array whose dtype says whether the scene has only
# boxes (uint8) or other kinds too (uint64). Kernels call `draw_shape(marker, ...)`, which numba
# compiles to the box code alone or to every kind's (the dtype is part of the kernel's signature,
# so each is its own cached specialisation): a scene of boxes never compiles the circle and polygon
# rasterisers. Two variants, not one per set of kinds, so that a corpus of mixed scenes compiles
# the rasteriser at most twice.
_BOXES_ONLY, _EVERY_KIND = np.uint8, np.uint64


def shapes_marker(kind: np.ndarray) -> np.ndarray:
    """The marker of the kinds in `kind` (n,) for `draw_shape`."""
    boxes_only = bool((np.asarray(kind) == KIND_BOX).all())
    return np.zeros(0, _BOXES_ONLY if boxes_only else _EVERY_KIND)


def draw_shape(
    shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1
):
    """`_draw_one` for a scene whose kinds `shapes` names (this body runs only without the JIT)."""
    _draw_one(buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1)


@overload(draw_shape)
def _draw_shape(
    shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1
):
    if shapes.dtype.bitwidth == 8:

        def boxes(
            shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0,
            cx1, cy1,
        ):  # fmt: skip
            _box(buf, x, y, wh[i, 0], wh[i, 1], color[i], fill[i], cx0, cy0, cx1, cy1)

        return boxes

    def every(
        shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1,
        cy1,
    ):  # fmt: skip
        _draw_one(
            buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1
        )

    return every


def dda_line(x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    """(n+1, 2) int64 pixels of the DDA line from (x0, y0) to (x1, y1), in drawing order.

    n = max(|x1-x0|, |y1-y0|); the first point is (x0, y0) and the last (x1, y1).
    """
    x0, y0, x1, y1 = (int(v) for v in (x0, y0, x1, y1))
    n = max(abs(x1 - x0), abs(y1 - y0))
    out = np.empty((n + 1, 2), np.int64)
    _line_points(x0, y0, x1, y1, out)
    return out


def midpoint_circle(d: int, fill: bool = False) -> np.ndarray:
    """(k, 2) int64 pixels (x, y) of a circle of diameter d drawn in the d x d box at (0, 0).

    Sorted by y then x, each pixel once; d = 1 is the single pixel (0, 0), d <= 0 is empty.
    """
    d = int(d)
    if d <= 0:
        return np.zeros((0, 2), np.int64)
    buf = np.zeros((d, d), np.uint8)
    _circle(buf, 0, 0, d, np.uint8(1), bool(fill), np.empty(d, np.int64), 0, 0, d - 1, d - 1)
    ys, xs = np.nonzero(buf)
    return np.stack([xs, ys], axis=1).astype(np.int64)
