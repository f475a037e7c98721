"""Frames from positions: DDA outlines, midpoint circles, fills, and redrawing only what moved.

This is the picture stage (SPEC section 4). Input: the world (`WorldSpec`), the objects' drawing
data (`Bodies`: kind, size, colour index, fill flag, polygon vertices) and, per frame, the float
top-left corners `pos (n, 2)` in pixels. Output: a palette-index frame `(H, W) uint8`, index 0 the
background and `Bodies.color[i]` the colour of object i; the RGB picture is `palette[frame]`
(`to_rgb`).

Rules, all in exact integer arithmetic once positions are rounded as `floor(x + 0.5)`:
- outlines are the paper's DDA lines (section II.B) with exact rounding (`_dda_start`);
- a box w x h at (x, y) is the DDA outline through its corners (x, y), (x+w-1, y), (x+w-1, y+h-1),
  (x, y+h-1); a polygon is the closed DDA outline through `(x, y) + verts`;
- a circle of diameter d fits the d x d box at (x, y) with the midpoint circle algorithm, worked in
  doubled coordinates so that even diameters are centred too (`_circle`);
- `fill` paints whole boxes, circle rows between the outline's extremes, and polygon pixels whose
  centres are inside (even-odd rule);
- objects are drawn in id order (later ids on top); pixels outside the world are dropped.

`Renderer.draw` keeps the previous frame and repaints only the rectangles where something moved
(paper section III.B); `Renderer.draw_full` clears and repaints everything. Both give the same
pixels. The pixel loops are numba kernels over arrays; with `NUMBA_DISABLE_JIT=1` the same source
runs as plain Python.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, Bodies, WorldSpec

# Rounded positions are clamped to +-POSITION_LIMIT_PX (px) so that pixel arithmetic on an object
# far off screen (or at a non-finite position) stays inside int64; such an object draws nothing.
POSITION_LIMIT_PX = 2**40

# Renderer.draw repaints everything instead of the dirty rectangles when most objects moved, when
# the moved objects' dirty area exceeds FULL_REDRAW_AREA_FRACTION of the frame (dimensionless), or
# when more than MAX_DIRTY_RECTS objects moved (each dirty rectangle is tested against every object,
# so their number is kept bounded). Clearing a whole frame is one memset, cheaper than many small
# rectangles and object-rectangle tests.
FULL_REDRAW_AREA_FRACTION = 0.5
MAX_DIRTY_RECTS = 64


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
        x += sx
        rx += ix
        if rx >= two_n:
            rx -= two_n
            x += 1
        y += sy
        ry += iy
        if ry >= two_n:
            ry -= two_n
            y += 1


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
        x += sx
        rx += ix
        if rx >= two_n:
            rx -= two_n
            x += 1
        y += sy
        ry += iy
        if ry >= two_n:
            ry -= two_n
            y += 1


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


@njit(cache=True)
def _round_into(pos, out):
    """out = floor(pos + 0.5) as int64, clamped to +-POSITION_LIMIT_PX (NaN to the low end).

    floor(x + 0.5) is taken exactly: the float sum x + 0.5 can round up (0.49999999999999994
    + 0.5 is 1.0 in float64), so the half is compared with the fraction x - floor(x) instead,
    which is exact for |x| < 2**52.
    """
    lim = POSITION_LIMIT_PX
    for i in range(pos.shape[0]):
        for a in range(2):
            x = pos[i, a]
            v = np.floor(x)
            if x - v >= 0.5:
                v += 1.0
            if not v >= -lim:
                out[i, a] = -lim
            elif v > lim:
                out[i, a] = lim
            else:
                out[i, a] = np.int64(v)


@njit(cache=True)
def _redraw_all(buf, ipos, kind, wh, color, fill, vert_start, verts, ext, scratch):
    """Clear the frame and draw every object in id order."""
    h, w = buf.shape
    buf[:, :] = 0
    for i in range(kind.shape[0]):
        x = ipos[i, 0]
        y = ipos[i, 1]
        cx0 = max(x + ext[i, 0], 0)
        cy0 = max(y + ext[i, 1], 0)
        cx1 = min(x + ext[i, 2], w - 1)
        cy1 = min(y + ext[i, 3], h - 1)
        if cx0 <= cx1 and cy0 <= cy1:
            _draw_one(
                buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1
            )


@njit(cache=True)
def _redraw_dirty(
    buf, old, new, kind, wh, color, fill, vert_start, verts, ext, scratch, rects, max_area
):
    """Repaint only where something moved; False (frame untouched) when a full redraw is cheaper:
    most objects moved, or too many rectangles (`rects` is their storage), or more than max_area
    pixels to clear.

    Why this equals a full redraw: every object's pixels lie inside its extent box. A pixel outside
    all dirty rectangles is covered, before and after, only by objects that did not move (a mover's
    old and new boxes are inside its rectangle), so it keeps its colour. Inside the rectangles the
    frame is cleared and every object meeting one is drawn, clipped to it, in id order, so each of
    those pixels ends up with the colour of the last object covering it, as in a full redraw.
    """
    h, w = buf.shape
    n = kind.shape[0]
    count = 0
    area = 0
    # bounding box of all dirty rectangles, for a quick reject of far objects
    ux0 = w
    uy0 = h
    ux1 = -1
    uy1 = -1
    for i in range(n):
        if old[i, 0] == new[i, 0] and old[i, 1] == new[i, 1]:
            continue
        if ext[i, 0] > ext[i, 2] or ext[i, 1] > ext[i, 3]:
            continue
        rx0 = max(min(old[i, 0], new[i, 0]) + ext[i, 0], 0)
        ry0 = max(min(old[i, 1], new[i, 1]) + ext[i, 1], 0)
        rx1 = min(max(old[i, 0], new[i, 0]) + ext[i, 2], w - 1)
        ry1 = min(max(old[i, 1], new[i, 1]) + ext[i, 3], h - 1)
        if rx0 > rx1 or ry0 > ry1:
            continue
        if count == rects.shape[0]:
            return False
        area += (rx1 - rx0 + 1) * (ry1 - ry0 + 1)
        if area > max_area:
            return False
        rects[count, 0] = rx0
        rects[count, 1] = ry0
        rects[count, 2] = rx1
        rects[count, 3] = ry1
        count += 1
        ux0 = min(ux0, rx0)
        uy0 = min(uy0, ry0)
        ux1 = max(ux1, rx1)
        uy1 = max(uy1, ry1)
    if 2 * count > n:
        return False
    for r in range(count):
        _fill_rect(buf, rects[r, 0], rects[r, 1], rects[r, 2], rects[r, 3], 0, 0, 0, w - 1, h - 1)
    for i in range(n):
        x = new[i, 0]
        y = new[i, 1]
        ox0 = x + ext[i, 0]
        oy0 = y + ext[i, 1]
        ox1 = x + ext[i, 2]
        oy1 = y + ext[i, 3]
        if ox0 > ux1 or ox1 < ux0 or oy0 > uy1 or oy1 < uy0:
            continue
        for r in range(count):
            cx0 = max(ox0, rects[r, 0])
            cy0 = max(oy0, rects[r, 1])
            cx1 = min(ox1, rects[r, 2])
            cy1 = min(oy1, rects[r, 3])
            if cx0 <= cx1 and cy0 <= cy1:
                _draw_one(
                    buf,
                    i,
                    x,
                    y,
                    kind,
                    wh,
                    color,
                    fill,
                    vert_start,
                    verts,
                    scratch,
                    cx0,
                    cy0,
                    cx1,
                    cy1,
                )
    return True


# --------------------------------------------------------------------------------------------
# Public API


def round_positions(pos: np.ndarray) -> np.ndarray:
    """(n, 2) int64 pixel positions floor(pos + 0.5) of float positions pos (n, 2), px."""
    pos = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 2)
    out = np.empty(pos.shape, np.int64)
    _round_into(pos, out)
    return out


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


def to_rgb(frame: np.ndarray, palette: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8 RGB picture palette[frame] of a (H, W) uint8 index frame, palette (k, 3)."""
    palette = np.asarray(palette, dtype=np.uint8)
    if int(frame.max(initial=0)) >= palette.shape[0]:
        raise ValueError(
            f"frame uses colour index {int(frame.max())} but the palette has {palette.shape[0]}"
        )
    return palette[frame]


class Renderer:
    """Draws the frames of one world and one set of objects, reusing one frame buffer.

    `draw(pos)` repaints only what moved since the previous frame; `draw_full(pos)` repaints
    everything. Both return the internal (H, W) uint8 buffer, which the next call overwrites.
    """

    def __init__(self, world: WorldSpec, bodies: Bodies):
        n = bodies.n
        self.width = int(world.width)
        self.height = int(world.height)
        self._kind = np.ascontiguousarray(bodies.kind, dtype=np.int8)
        self._wh = round_positions(bodies.size)
        self._color = np.ascontiguousarray(bodies.color, dtype=np.uint8)
        self._fill = np.ascontiguousarray(bodies.fill, dtype=np.bool_)
        self._vert_start = np.ascontiguousarray(bodies.vert_start, dtype=np.int64)
        self._verts = np.ascontiguousarray(bodies.verts, dtype=np.int64).reshape(-1, 2)
        self._ext = _extents(self._kind, self._wh, self._vert_start, self._verts)
        counts = np.diff(self._vert_start) if n else np.zeros(0, np.int64)
        diam = self._wh[self._kind == KIND_CIRCLE, 0]
        self._scratch = np.empty(
            max(1, int(counts.max(initial=0)), int(diam.max(initial=0))), np.int64
        )
        self._buf = np.zeros((self.height, self.width), np.uint8)
        self._old = np.zeros((n, 2), np.int64)
        self._new = np.zeros((n, 2), np.int64)
        self._rects = np.empty((min(n, MAX_DIRTY_RECTS), 4), np.int64)
        self._max_area = int(FULL_REDRAW_AREA_FRACTION * self.width * self.height)
        self._drawn = False
        self.last_was_full = True  # whether the latest draw repainted the whole frame
        self.n = n

    def _positions(self, pos) -> None:
        pos = np.asarray(pos, dtype=np.float64)
        if pos.shape != (self.n, 2):
            raise ValueError(f"positions must have shape ({self.n}, 2), got {pos.shape}")
        _round_into(np.ascontiguousarray(pos), self._new)

    def _full(self) -> np.ndarray:
        _redraw_all(
            self._buf,
            self._new,
            self._kind,
            self._wh,
            self._color,
            self._fill,
            self._vert_start,
            self._verts,
            self._ext,
            self._scratch,
        )
        self._old, self._new = self._new, self._old
        self._drawn = True
        self.last_was_full = True
        return self._buf

    def draw_full(self, pos: np.ndarray) -> np.ndarray:
        """(H, W) uint8 frame for top-left corners pos (n, 2) px, cleared and drawn from scratch."""
        self._positions(pos)
        return self._full()

    def draw(self, pos: np.ndarray) -> np.ndarray:
        """(H, W) uint8 frame for top-left corners pos (n, 2) px, repainting only what moved."""
        self._positions(pos)
        if not self._drawn:
            return self._full()
        done = _redraw_dirty(
            self._buf,
            self._old,
            self._new,
            self._kind,
            self._wh,
            self._color,
            self._fill,
            self._vert_start,
            self._verts,
            self._ext,
            self._scratch,
            self._rects,
            self._max_area,
        )
        if not done:
            return self._full()
        self._old, self._new = self._new, self._old
        self.last_was_full = False
        return self._buf


def render(world: WorldSpec, bodies: Bodies, pos: np.ndarray) -> np.ndarray:
    """A new (H, W) uint8 frame of `bodies` at top-left corners pos (n, 2) px."""
    return Renderer(world, bodies).draw_full(pos).copy()


@njit(cache=True)
def _extents(kind, wh, vert_start, verts):
    """(n, 4) int64 inclusive pixel box [x0, y0, x1, y1] of each object relative to its position.

    Boxes and circles cover [0, w-1] x [0, h-1] (a circle's h is its diameter w); polygons the span
    of their vertices. An object that draws nothing (zero size, no vertices) gets the empty box
    [0, 0, -1, -1].
    """
    n = kind.shape[0]
    ext = np.zeros((n, 4), np.int64)
    for i in range(n):
        ext[i, 2] = wh[i, 0] - 1
        ext[i, 3] = wh[i, 0] - 1 if kind[i] == KIND_CIRCLE else wh[i, 1] - 1
        if kind[i] == KIND_POLYGON:
            s = vert_start[i]
            e = vert_start[i + 1]
            if e > s:
                ext[i, 0] = verts[s, 0]
                ext[i, 1] = verts[s, 1]
                ext[i, 2] = verts[s, 0]
                ext[i, 3] = verts[s, 1]
                for j in range(s + 1, e):
                    ext[i, 0] = min(ext[i, 0], verts[j, 0])
                    ext[i, 1] = min(ext[i, 1], verts[j, 1])
                    ext[i, 2] = max(ext[i, 2], verts[j, 0])
                    ext[i, 3] = max(ext[i, 3], verts[j, 1])
            else:
                ext[i, 2] = -1
                ext[i, 3] = -1
        if ext[i, 2] < ext[i, 0] or ext[i, 3] < ext[i, 1]:
            ext[i, 0] = 0
            ext[i, 1] = 0
            ext[i, 2] = -1
            ext[i, 3] = -1
    return ext
