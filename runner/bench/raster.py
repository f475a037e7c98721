"""The raster part of `collide2d bench`: drawing and writing frames of the section IV demo.

The demo's 50 boxes (`scenarios/paper_fifty_boxes.yaml`, 320x240, outlines) move along a path made
here, 1 px per frame on each axis, bouncing off the walls (`moving_positions`), and the part
measures, each the median of several repeats after a warm-up: `Renderer.draw` frames/s with all
boxes moving (the issue's target: at least 20,000) and with 5 of 50 moving (the
erase-only-what-moved path), `Renderer.draw_full` for comparison; the seconds to render and stream a
GIF of GIF_FRAMES frames through `runner.output.files.GifWriter`; the milliseconds to encode and
write one PNG frame. Not a default part (`--part raster`).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from collide2d.runner.bench.scenes import DEMO_SCENARIO, PROJECT_SCENARIOS
from collide2d.runner.bench.timing import median

RASTER_FRAMES = 5000  # frames per timed repeat
QUICK_RASTER_FRAMES = 200
RASTER_REPEATS = 7
GIF_FRAMES = 100
QUICK_GIF_FRAMES = 20
PNG_REPEATS = 20
FEW_MOVERS = 5
PATH_SEED = 7


def moving_positions(start, size, width: int, height: int, frames: int, movers: int) -> np.ndarray:
    """(frames, n, 2) top-left corners from `start` (n, 2): the first `movers` boxes move 1 px per
    frame diagonally (directions seeded) and bounce off the walls; the others stay."""
    rng = np.random.default_rng(PATH_SEED)
    pos = np.array(start, np.float64)
    vel = rng.choice([-1.0, 1.0], size=pos.shape)
    vel[movers:] = 0.0
    hi = np.array([width, height], np.float64) - size
    out = np.empty((frames, *pos.shape))
    for f in range(frames):
        out[f] = pos
        pos = pos + vel
        outside = (pos < 0) | (pos > hi)
        vel[outside] *= -1.0
        pos[outside] += 2.0 * vel[outside]
    return out


def _frames_per_second(renderer, path: np.ndarray, full: bool, repeats: int) -> float:
    draw = renderer.draw_full if full else renderer.draw
    draw(path[0])  # warm-up: load the kernels; the first frame is always a full one
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        for pos in path:
            draw(pos)
        times.append(time.perf_counter() - began)
    return len(path) / median(times)


def raster(quick: bool, echo, folder: Path = PROJECT_SCENARIOS) -> list[dict]:
    """One row per measure (the demo is read from `folder`)."""
    from collide2d.engine.picture.raster import Renderer, to_rgb
    from collide2d.runner.output import files
    from collide2d.runner.scenario.load import load

    frames = QUICK_RASTER_FRAMES if quick else RASTER_FRAMES
    repeats = 1 if quick else RASTER_REPEATS
    demo = load(folder / f"{DEMO_SCENARIO}.yaml")
    world, bodies = demo.world, demo.bodies
    n = bodies.n

    def path(movers: int) -> np.ndarray:
        return moving_positions(bodies.pos, bodies.size, world.width, world.height, frames, movers)

    moving, few = path(n), path(FEW_MOVERS)
    figures = [
        ("Renderer.draw, all moving, frames/s (target >= 20,000)", moving, False),
        ("Renderer.draw_full, all moving, frames/s", moving, True),
        (f"Renderer.draw, {FEW_MOVERS} of {n} moving, frames/s", few, False),
        (f"Renderer.draw_full, {FEW_MOVERS} of {n} moving, frames/s", few, True),
    ]
    rows = []

    def row(value: float, note: str) -> None:
        rows.append(
            {"part": "raster", "scene": DEMO_SCENARIO, "n": n, "value": value, "note": note}
        )
        echo(f"raster   {note:56s} {value:12,.3f}")

    for note, where, full in figures:
        row(_frames_per_second(Renderer(world, bodies), where, full, repeats), note)
    gif_frames = moving[: QUICK_GIF_FRAMES if quick else GIF_FRAMES]
    with tempfile.TemporaryDirectory(prefix="collide2d-bench-") as tmp:
        gif = Path(tmp) / "animation.gif"
        times = []
        for _ in range(repeats + 1):  # the first run warms up
            began = time.perf_counter()
            renderer = Renderer(world, bodies)
            with files.GifWriter(
                gif, demo.palette, world.width, world.height, world.fps, len(gif_frames)
            ) as writer:
                for pos in gif_frames:
                    writer.add(renderer.draw(pos))
            times.append(time.perf_counter() - began)
        row(median(times[1:]), f"GIF of {len(gif_frames)} frames (render and stream), s")
        rgb = to_rgb(Renderer(world, bodies).draw(moving[0]), demo.palette)
        files.write_png(Path(tmp) / "warm.png", rgb)
        times = []
        for k in range(1 if quick else PNG_REPEATS):
            began = time.perf_counter()
            files.write_png(Path(tmp) / f"frame_{k:06d}.png", rgb)
            times.append(time.perf_counter() - began)
        row(1e3 * median(times), "one PNG frame (encode and atomic write), ms")
    return rows
