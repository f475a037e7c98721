"""Frames from positions: every object drawn in id order, and redrawing only what moved.

This is the picture stage (docs/drawing.md). Input: the world (`WorldSpec`), the objects' drawing
data (`Bodies`: kind, size, colour index, fill flag, polygon vertices) and, per frame, the float
top-left corners `pos (n, 2)` in pixels. Output: a palette-index frame `(H, W) uint8`, index 0 the
background and `Bodies.looks.color[i]` the colour of object i; the RGB picture is `palette[frame]`
(`to_rgb`). Positions are rounded as `floor(x + 0.5)`; each object is drawn by the primitives of
`engine.picture.pixels` (DDA outlines, midpoint circles, fills), later ids on top, pixels outside
the world dropped.

A full redraw of a scene of engine.threads.PARALLEL_MIN_OBJECTS objects or more is split among
threads by bands of rows (each band cleared and drawn clipped to itself, every object in id
order): the same bytes as one thread.

`Renderer.draw` keeps the previous frame and repaints only the rectangles where something moved
(paper section III.B); `Renderer.draw_full` clears and repaints everything. Both give the same
pixels. The pixel loops are numba kernels over arrays; with `NUMBA_DISABLE_JIT=1` the same source
runs as plain Python.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit, prange
from collide2d.engine.picture.pixels import _fill_rect, draw_shape, shapes_marker
from collide2d.engine.threads import chunks_for
from collide2d.engine.world import KIND_CIRCLE, KIND_POLYGON, Bodies, WorldSpec

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
def _redraw_all(buf, ipos, art, scratch):
    """Clear the frame and draw every object in id order (`art`: see `Renderer`)."""
    kind, wh, color, fill, vert_start, verts, ext, shapes = art
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
            draw_shape(
                shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch,
                cx0, cy0, cx1, cy1,
            )  # fmt: skip


@njit(cache=True)
def _draw_band(buf, y0, y1, ipos, kind, wh, color, fill, vert_start, verts, ext, shapes, scratch):
    """Clear rows y0 ... y1-1 of the frame and draw every object in id order, clipped to them."""
    h, w = buf.shape
    for y in range(y0, y1):
        for x in range(w):
            buf[y, x] = 0
    for i in range(kind.shape[0]):
        x = ipos[i, 0]
        y = ipos[i, 1]
        cx0 = max(x + ext[i, 0], 0)
        cy0 = max(y + ext[i, 1], y0)
        cx1 = min(x + ext[i, 2], w - 1)
        cy1 = min(y + ext[i, 3], y1 - 1)
        if cx0 <= cx1 and cy0 <= cy1:
            draw_shape(
                shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch,
                cx0, cy0, cx1, cy1,
            )  # fmt: skip


@njit(cache=True, parallel=True)
def _draw_bands(buf, ipos, kind, wh, color, fill, vert_start, verts, ext, shapes, scratch, bands):
    """The frame cut into `bands` bands of rows, one per thread; each band cleared and every
    object drawn clipped to it, in id order. Clipping keeps each pixel's colour (the dirty-region
    redraw relies on the same), so the frame equals `_redraw_all`'s, to the byte."""
    h = buf.shape[0]
    for b in prange(bands):
        _draw_band(
            buf, b * h // bands, (b + 1) * h // bands, ipos, kind, wh, color, fill, vert_start,
            verts, ext, shapes, scratch[b],
        )


@njit(cache=True)
def _redraw_split(buf, ipos, art, scratch, bands):
    """`_redraw_all` split among threads by bands of rows (`_draw_bands`); scratch (bands, k)."""
    kind, wh, color, fill, vert_start, verts, ext, shapes = art
    _draw_bands(buf, ipos, kind, wh, color, fill, vert_start, verts, ext, shapes, scratch, bands)


@njit(cache=True)
def _redraw_dirty(buf, old, new, art, scratch, rects, max_area):
    """Repaint only where something moved; False (frame untouched) when a full redraw is cheaper:
    most objects moved, or too many rectangles (`rects` is their storage), or more than max_area
    pixels to clear.

    Why this equals a full redraw: every object's pixels lie inside its extent box. A pixel outside
    all dirty rectangles is covered, before and after, only by objects that did not move (a mover's
    old and new boxes are inside its rectangle), so it keeps its colour. Inside the rectangles the
    frame is cleared and every object meeting one is drawn, clipped to it, in id order, so each of
    those pixels ends up with the colour of the last object covering it, as in a full redraw.
    """
    kind, wh, color, fill, vert_start, verts, ext, shapes = art
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
                draw_shape(
                    shapes,
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
        self._color = np.ascontiguousarray(bodies.looks.color, dtype=np.uint8)
        self._fill = np.ascontiguousarray(bodies.looks.fill, dtype=np.bool_)
        self._vert_start = np.ascontiguousarray(bodies.vert_start, dtype=np.int64)
        self._verts = np.ascontiguousarray(bodies.verts, dtype=np.int64).reshape(-1, 2)
        self._ext = _extents(self._kind, self._wh, self._vert_start, self._verts)
        # the drawing data the kernels read, in one tuple: kind, size, colour, fill, vertices
        # (start, points) and each object's extent around its position
        self._art = (
            self._kind,
            self._wh,
            self._color,
            self._fill,
            self._vert_start,
            self._verts,
            self._ext,
            shapes_marker(self._kind),  # which drawing code the kernels compile
        )
        counts = np.diff(self._vert_start) if n else np.zeros(0, np.int64)
        diam = self._wh[self._kind == KIND_CIRCLE, 0]
        self._scratch = np.empty(
            max(1, int(counts.max(initial=0)), int(diam.max(initial=0))), np.int64
        )
        # a full redraw of a large scene is split among threads by bands of rows
        self._bands = min(chunks_for(n), max(1, self.height))
        self._band_scratch = np.empty((self._bands, self._scratch.shape[0]), np.int64)
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
        if self._bands > 1:
            _redraw_split(self._buf, self._new, self._art, self._band_scratch, self._bands)
        else:
            _redraw_all(self._buf, self._new, self._art, self._scratch)
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
            self._buf, self._old, self._new, self._art, self._scratch, self._rects, self._max_area
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
