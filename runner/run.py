"""Drive a model over a scenario's ticks and hand frames and events to whoever asked for them.

`drive` is the one loop: it builds the model named by the scenario, advances it in chunks that end
at every frame someone needs (and often enough to show progress and stream events), rasterises only
those frames, and calls back with events and frames as they come. Two front ends sit on it:
`simulate` keeps everything in memory (goldens, tests), `run_to_dir` streams the files of SPEC
section 5 into `OUT/NAME/`, each through a temporary name and a rename (temporaries a killed run
left there are removed first). A model that stops a run as a runaway (an `engine.errors.Runaway`:
the exact model's event cap or an object with no room to move, the stepped model's fold limit)
raises `RunStopped` with a message for the user. The summary counts the wall and pair events
whether or not they are logged (the models count them as they happen).
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from engine import models
from engine.errors import Runaway
from engine.events import empty_events
from engine.raster import Renderer
from engine.world import kinetic_energy, momentum
from runner import outputs
from runner.progress import Progress
from runner.scenario import Limits, Scenario, ScenarioError

# Ticks per model call when nothing else ends a chunk: large enough that the kernel dominates,
# small enough that events stream out and progress moves.
CHUNK_TICKS = 65_536
# Upper bound of a frame's bytes on disk used to refuse runs whose output would be too big:
# PNG and GIF frames are compressed, so raw RGB (PNG) and raw indices (GIF) bound them.
PNG_BYTES_PER_PIXEL = 3
GIF_BYTES_PER_PIXEL = 1
# The largest side of a GIF picture, px (its header holds 16-bit sizes).
GIF_MAX_SIDE_PX = 65535
# The output files `run_to_dir` knows; any of them not written by a run is removed, so the folder
# always shows one run.
OUTPUT_FILES = ("animation.gif", "events.jsonl", "final.csv", "summary.json")


class RunStopped(Exception):
    """A model stopped the run with a clear error (a runaway: the exact model's event cap or an
    object with no room to move, or an object crossing the world too many times in one stepped
    step). str(err) is the message."""


@dataclass
class RunResult:
    """What one run produced, in memory."""

    scenario: Scenario
    events: np.ndarray  # EVENT_DTYPE records in order (empty when not logged)
    final_pos: np.ndarray  # (n, 2) float64
    final_vel: np.ndarray  # (n, 2) float64
    frames: dict[int, np.ndarray] = field(default_factory=dict)  # frame -> (H, W, 3) uint8
    summary: dict = field(default_factory=dict)


def drive(
    scenario: Scenario,
    *,
    frames: Iterable[int] = (),
    on_frame: Callable[[int, np.ndarray], None] | None = None,
    log_events: bool = False,
    on_events: Callable[[np.ndarray], None] | None = None,
    progress: Progress | None = None,
) -> tuple[object, dict]:
    """Run the scenario; returns (the model at the end, the summary).

    frames: frame numbers (0..ticks) to rasterise; each is passed to `on_frame(k, index_frame)` as
    an (H, W) uint8 palette-index image that is only valid during the call.
    log_events: record events and pass each chunk's array to `on_events`.
    """
    bodies = scenario.bodies
    options = {"substeps": scenario.substeps, "geometry": scenario.geometry}
    if scenario.model == "exact":
        options["max_events_per_tick"] = scenario.max_events_per_tick
    try:
        model = models.make(scenario.model, scenario.world, bodies, **options)
    except Runaway as exc:
        raise RunStopped(
            f"{scenario.path or scenario.name}: error: the {scenario.model} model refused the "
            f"scene: {exc}"
        ) from None
    wanted = sorted({int(k) for k in frames if 0 <= k <= scenario.ticks})
    renderer = Renderer(scenario.world, bodies) if wanted else None
    start = _energy_momentum(bodies, model.velocities())
    began = time.perf_counter()

    next_frame = 0
    if wanted and wanted[0] == 0:
        on_frame(0, renderer.draw(model.positions()))
        next_frame = 1
    while model.tick < scenario.ticks:
        stop = min(scenario.ticks, model.tick + CHUNK_TICKS)
        if next_frame < len(wanted):
            stop = min(stop, wanted[next_frame])
        try:
            events = model.advance(stop - model.tick, log_events)
        except Runaway as exc:
            when = f"tick {stop}" if stop == model.tick + 1 else f"ticks {model.tick + 1}-{stop}"
            raise RunStopped(
                f"{scenario.path or scenario.name}: error: the {scenario.model} model stopped "
                f"the run in {when}: {exc}"
            ) from None
        if log_events and len(events) and on_events is not None:
            on_events(events)
        if next_frame < len(wanted) and model.tick == wanted[next_frame]:
            on_frame(model.tick, renderer.draw(model.positions()))
            next_frame += 1
        if progress is not None:
            progress.update(model.tick)
    run_time = time.perf_counter() - began
    if progress is not None:
        progress.close()

    end = _energy_momentum(bodies, model.velocities())
    walls, pairs = model.event_counts()
    summary = {
        "name": scenario.name,
        "model": scenario.model,
        "fps": scenario.world.fps,
        "ticks": scenario.ticks,
        "objects": bodies.n,
        "events": {"wall": walls, "pair": pairs},
        "kinetic_energy": {"start": start[0], "end": end[0]},
        "momentum": {"start": list(start[1]), "end": list(end[1])},
        "run_time_s": round(run_time, 6),
    }
    return model, summary


def simulate(
    scenario: Scenario,
    *,
    keep_frames: Iterable[int] = (),
    log_events: bool = True,
    progress: bool = False,
) -> RunResult:
    """Run in memory; frames in `keep_frames` come back as RGB arrays."""
    kept: dict[int, np.ndarray] = {}
    chunks: list[np.ndarray] = []
    palette = scenario.palette

    model, summary = drive(
        scenario,
        frames=keep_frames,
        on_frame=lambda k, idx: kept.__setitem__(k, palette[idx]),
        log_events=log_events,
        on_events=chunks.append,
        progress=Progress.for_terminal(scenario.ticks, scenario.name) if progress else None,
    )
    events = np.concatenate(chunks) if chunks else empty_events()
    return RunResult(scenario, events, model.positions(), model.velocities(), kept, summary)


@dataclass(frozen=True)
class RunOptions:
    """What `collide2d run` writes: PNG frames, GIF, events (final.csv and summary always)."""

    png: bool
    gif: bool
    events: bool
    scale: int = 1
    quiet: bool = False


def output_dir(out_root: str | os.PathLike, scenario: Scenario) -> Path:
    """OUT/NAME, refusing a path that would lead outside OUT (a link in the way)."""
    root = Path(out_root)
    target = root / scenario.name
    for path in (target, target / "frames"):
        if path.is_symlink():
            raise ScenarioError(
                scenario.path or "<scenario>",
                1,
                1,
                f"output folder {path} is a symbolic link; refusing to write through it",
            )
    return target


def check_output_size(scenario: Scenario, options: RunOptions, limits: Limits) -> None:
    """Refuse before running when the frames asked for could pass limits.max_output_bytes, or a
    GIF would be larger than a GIF can be."""
    pixels = scenario.world.width * scenario.world.height * options.scale**2
    side = max(scenario.world.width, scenario.world.height) * options.scale
    if options.gif and side > GIF_MAX_SIDE_PX:
        raise ScenarioError(
            scenario.path or "<scenario>",
            1,
            1,
            f"a GIF is at most {GIF_MAX_SIDE_PX} px a side, and this world at scale "
            f"{options.scale} needs {side} px; use a smaller --scale or --no-gif",
        )
    total = 0
    if options.png:
        total += len(png_frames(scenario)) * pixels * PNG_BYTES_PER_PIXEL
    if options.gif:
        total += (scenario.ticks + 1) * pixels * GIF_BYTES_PER_PIXEL
    if total > limits.max_output_bytes:
        raise ScenarioError(
            scenario.path or "<scenario>",
            1,
            1,
            f"the frames asked for could take up to {total:,} bytes, past the output limit of "
            f"{limits.max_output_bytes:,} bytes; ask for fewer frames (output.frames, --no-png, "
            f"--no-gif, a smaller --scale) or raise --max-output-bytes",
        )


def png_frames(scenario: Scenario) -> tuple[int, ...]:
    """The frames written as PNG when PNGs are on: the scenario's choice, or all if none."""
    if scenario.output.frames:
        return scenario.output.frames
    return tuple(range(scenario.ticks + 1))


def run_to_dir(
    scenario: Scenario,
    out_root: str | os.PathLike,
    options: RunOptions,
    limits: Limits | None = None,
) -> tuple[Path, dict]:
    """Run and write SPEC section 5's files under OUT/NAME; returns (that folder, the summary)."""
    limits = limits or Limits()
    check_output_size(scenario, options, limits)
    target = output_dir(out_root, scenario)
    frames_dir = target / "frames"
    target.mkdir(parents=True, exist_ok=True)
    png_set = set(png_frames(scenario)) if options.png else set()
    if png_set:
        frames_dir.mkdir(exist_ok=True)
    for folder in (target, frames_dir):  # what a killed run left (`.NAME.PID.XXXXXXXX.tmp`)
        outputs.clean_temporaries(folder)
    wanted = set(png_set)
    gif = None
    if options.gif:
        wanted.update(range(scenario.ticks + 1))
        gif = outputs.GifWriter(
            target / "animation.gif",
            scenario.palette,
            scenario.world.width,
            scenario.world.height,
            scenario.world.fps,
            scenario.ticks + 1,
            scale=options.scale,
        )
        if gif.note and not options.quiet:
            print(f"{scenario.name}: {gif.note}", file=sys.stderr)
    log = outputs.EventsWriter(target / "events.jsonl") if options.events else None
    digits = max(6, len(str(scenario.ticks)))
    written: set[str] = set()

    def on_frame(k: int, idx: np.ndarray) -> None:
        if gif is not None:
            gif.add(idx)
        if k in png_set:
            name = f"frame_{k:0{digits}d}.png"
            outputs.write_png(frames_dir / name, scenario.palette[idx], scale=options.scale)
            written.add(name)

    progress = None if options.quiet else Progress.for_terminal(scenario.ticks, scenario.name)
    try:
        model, summary = drive(
            scenario,
            frames=sorted(wanted),
            on_frame=on_frame,
            log_events=options.events,
            on_events=log.write if log else None,
            progress=progress,
        )
    except BaseException:
        for writer in (gif, log):
            if writer is not None:
                writer.abort()
        raise
    for writer in (gif, log):
        if writer is not None:
            writer.close()
    outputs.write_final_csv(target / "final.csv", model.positions(), model.velocities())
    outputs.write_json(target / "summary.json", summary)
    _remove_stale(target, frames_dir, options, written)
    return target, summary


def _remove_stale(target: Path, frames_dir: Path, options: RunOptions, written: set[str]) -> None:
    """Remove outputs of an earlier run that this run did not write (only names we own)."""
    keep = {"final.csv", "summary.json"}
    if options.gif:
        keep.add("animation.gif")
    if options.events:
        keep.add("events.jsonl")
    for name in OUTPUT_FILES:
        path = target / name
        if name not in keep and path.is_file() and not path.is_symlink():
            path.unlink()
    if frames_dir.is_dir() and not frames_dir.is_symlink():
        for path in frames_dir.glob("frame_*.png"):
            if path.name not in written and not path.is_symlink():
                path.unlink()


def _energy_momentum(bodies, vel: np.ndarray) -> tuple[float, tuple[float, float]]:
    return (
        kinetic_energy(bodies.mass, bodies.static, vel),
        momentum(bodies.mass, bodies.static, vel),
    )
