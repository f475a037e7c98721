"""The picture stage: positions in, frames out (docs/drawing.md).

`pixels` draws one object (DDA lines, boxes, midpoint circles, polygons, fills), `raster` draws a
whole frame and redraws only what moved, and `sprites` gives each object's pixels once, relative to
its position, for the viewer. No model draws: the run calls this stage for the frames it keeps. It
may import the engine's shared modules (the world's arrays, jit, threads), never a model's package.
"""
