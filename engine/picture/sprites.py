"""Each object's pixels relative to its position: what `engine.picture.raster` draws, as sprites.

A frame is every object drawn in id order at its rounded position, and what an object draws does not
depend on where it is (its pixels move with it; the frame's edge only clips them). So the pixels of
object i drawn once at its own origin, by the same `engine.picture.pixels` kernels the renderer
uses, give any frame: for each object in id order, its sprite's pixels at the rounded position plus
their offsets, inside the world, in its colour, over the background. The run viewer
(`runner.output.viewerdata`) draws its canvas this way, so it shows exactly the PNG frames' pixels.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit
from collide2d.engine.picture.pixels import draw_shape, shapes_marker
from collide2d.engine.picture.raster import _extents, round_positions
from collide2d.engine.world import KIND_CIRCLE, Bodies


def sprites(bodies: Bodies) -> tuple[np.ndarray, np.ndarray]:
    """(start, offsets): object i's pixels are offsets[start[i]:start[i+1]], (k, 2) int32 (dx, dy)
    from its rounded top-left position, in row order. start is (n+1,) int64."""
    kind = np.ascontiguousarray(bodies.kind, dtype=np.int8)
    wh = round_positions(bodies.size)
    fill = np.ascontiguousarray(bodies.looks.fill, dtype=np.bool_)
    vert_start = np.ascontiguousarray(bodies.vert_start, dtype=np.int64)
    verts = np.ascontiguousarray(bodies.verts, dtype=np.int64).reshape(-1, 2)
    ext = _extents(kind, wh, vert_start, verts)
    ones = np.ones(kind.shape[0], np.uint8)
    counts = np.diff(vert_start) if kind.shape[0] else np.zeros(0, np.int64)
    diam = wh[kind == KIND_CIRCLE, 0]
    scratch = np.empty(max(1, int(counts.max(initial=0)), int(diam.max(initial=0))), np.int64)
    shapes = shapes_marker(kind)
    start = [0]
    parts = []
    for i in range(kind.shape[0]):
        x0, y0, x1, y1 = (int(v) for v in ext[i])
        if x1 < x0 or y1 < y0:
            start.append(start[-1])
            continue
        buf = np.zeros((y1 - y0 + 1, x1 - x0 + 1), np.uint8)
        _draw_sprite(
            shapes, buf, i, -x0, -y0, kind, wh, ones, fill, vert_start, verts, scratch,
            0, 0, x1 - x0, y1 - y0,
        )  # fmt: skip
        ys, xs = np.nonzero(buf)
        parts.append(np.stack([xs + x0, ys + y0], axis=1).astype(np.int32))
        start.append(start[-1] + len(xs))
    offsets = np.concatenate(parts) if parts else np.zeros((0, 2), np.int32)
    return np.array(start, np.int64), offsets


def paint(world_w: int, world_h: int, color, start, offsets, ipos) -> np.ndarray:
    """(H, W) palette-index frame from sprites at integer positions ipos (n, 2): the reference
    the viewer's canvas follows (and a check of the sprites against `engine.picture.raster`)."""
    out = np.zeros((world_h, world_w), np.uint8)
    for i in range(len(start) - 1):
        pts = offsets[start[i] : start[i + 1]].astype(np.int64) + ipos[i]
        ok = (pts[:, 0] >= 0) & (pts[:, 0] < world_w) & (pts[:, 1] >= 0) & (pts[:, 1] < world_h)
        pts = pts[ok]
        out[pts[:, 1], pts[:, 0]] = color[i]
    return out


@njit(cache=True)
def _draw_sprite(
    shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1
):
    """`engine.picture.pixels.draw_shape`: compiles only the drawing code of the kinds `shapes`
    names (a scene of boxes never compiles the circle and polygon rasterisers for its sprites)."""
    draw_shape(
        shapes, buf, i, x, y, kind, wh, color, fill, vert_start, verts, scratch, cx0, cy0, cx1, cy1
    )
