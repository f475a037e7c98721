"""Rendering and GIF speed on the paper's section IV scene (320x240, 50 boxes 10x10, outlines).

Measures, each as the median of several repeats after a warm-up (numba compiles on first use):
- `Renderer.draw` frames per second with all 50 boxes moving 1 px per frame on each axis
  (target: at least 20,000 frames/s), and for comparison `Renderer.draw_full` and a scene where
  only 5 of the 50 boxes move (the erase-only-what-moved path);
- the seconds to render and stream a 100-frame GIF of the moving scene through `GifWriter`;
- the milliseconds to encode and write one PNG frame.

Run: `/tmp/venv/bin/python benchmarks/bench_raster.py [--frames N] [--repeats R]`.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from collide2d.engine.raster import Renderer, to_rgb
from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner import outputs

WIDTH, HEIGHT = 320, 240  # px, the paper's VGA frame
N_BOXES = 50
BOX_PX = 10
GIF_FRAMES = 100
FPS = 10
PALETTE = np.array([[0, 0, 0], [255, 255, 255]], np.uint8)


def scene_positions(n_frames: int, movers: int = N_BOXES, seed: int = 7) -> np.ndarray:
    """(n_frames, 50, 2) float64 top-left corners: boxes on a grid, the first `movers` of them
    moving 1 px per frame diagonally and bouncing off the walls."""
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(10) * 31 + 4, np.arange(5) * 46 + 8)
    pos = np.stack([gx.ravel(), gy.ravel()], axis=1).astype(np.float64)
    vel = rng.choice([-1.0, 1.0], size=(N_BOXES, 2))
    vel[movers:] = 0.0
    hi = np.array([WIDTH - BOX_PX, HEIGHT - BOX_PX], np.float64)
    out = np.empty((n_frames, N_BOXES, 2))
    for f in range(n_frames):
        out[f] = pos
        pos = pos + vel
        outside = (pos < 0) | (pos > hi)
        vel[outside] *= -1.0
        pos[outside] += 2.0 * vel[outside]
    return out


def frames_per_second(renderer: Renderer, frames: np.ndarray, full: bool, repeats: int) -> float:
    draw = renderer.draw_full if full else renderer.draw
    draw(frames[0])  # warm-up: compiles, and the first frame is always a full one
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for pos in frames:
            draw(pos)
        times.append(time.perf_counter() - t0)
    return len(frames) / statistics.median(times)


def gif_seconds(
    bodies: Bodies, frames: np.ndarray, folder: Path, repeats: int
) -> tuple[float, int]:
    world = WorldSpec(WIDTH, HEIGHT, FPS)
    times = []
    path = folder / "animation.gif"
    for _ in range(repeats + 1):  # the first run warms up
        t0 = time.perf_counter()
        renderer = Renderer(world, bodies)
        with outputs.GifWriter(path, PALETTE, WIDTH, HEIGHT, FPS, len(frames)) as gif:
            for pos in frames:
                gif.add(renderer.draw(pos))
        times.append(time.perf_counter() - t0)
    return statistics.median(times[1:]), path.stat().st_size


def png_ms(bodies: Bodies, frames: np.ndarray, folder: Path, repeats: int) -> float:
    renderer = Renderer(WorldSpec(WIDTH, HEIGHT, FPS), bodies)
    rgb = to_rgb(renderer.draw(frames[0]), PALETTE)
    outputs.write_png(folder / "warm.png", rgb)
    times = []
    for r in range(repeats):
        t0 = time.perf_counter()
        outputs.write_png(folder / f"frame_{r:06d}.png", rgb)
        times.append(time.perf_counter() - t0)
    return 1000 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=5000, help="frames per timed repeat")
    parser.add_argument("--repeats", type=int, default=7, help="timed repeats (median reported)")
    args = parser.parse_args()

    world = WorldSpec(WIDTH, HEIGHT, FPS)
    moving = scene_positions(args.frames)
    few = scene_positions(args.frames, movers=5)
    bodies = Bodies.boxes(moving[0], BOX_PX, 0.0)
    fps_draw = frames_per_second(Renderer(world, bodies), moving, False, args.repeats)
    fps_full = frames_per_second(Renderer(world, bodies), moving, True, args.repeats)
    fps_few = frames_per_second(Renderer(world, bodies), few, False, args.repeats)
    fps_few_full = frames_per_second(Renderer(world, bodies), few, True, args.repeats)
    print(f"section IV scene {WIDTH}x{HEIGHT}, {N_BOXES} boxes {BOX_PX}x{BOX_PX}, outlines")
    print(f"  Renderer.draw, all moving:       {fps_draw:12,.0f} frames/s  (target >= 20,000)")
    print(f"  Renderer.draw_full, all moving:  {fps_full:12,.0f} frames/s")
    print(f"  Renderer.draw, 5 of 50 moving:   {fps_few:12,.0f} frames/s")
    print(f"  Renderer.draw_full, 5 of 50:     {fps_few_full:12,.0f} frames/s")
    with tempfile.TemporaryDirectory() as tmp:
        secs, size = gif_seconds(bodies, moving[:GIF_FRAMES], Path(tmp), args.repeats)
        ms = png_ms(bodies, moving, Path(tmp), max(args.repeats, 20))
    print(f"  GIF of {GIF_FRAMES} frames (render + stream): {secs:.3f} s, {size:,} bytes")
    print(f"  one PNG frame (encode + atomic write):  {ms:.2f} ms")


if __name__ == "__main__":
    main()
