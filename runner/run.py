"""Drive a model over a scenario's ticks and hand frames and events to whoever asked for them.

`drive` is the one loop: it builds the model named by the scenario, advances it in chunks that end
at every frame someone needs (and often enough to show progress and stream events), rasterises only
those frames, and calls back with events and frames as they come. Two front ends sit on it:
`simulate` keeps everything in memory (goldens, tests), `run_to_dir` streams the files of
docs/outputs.md into a staging folder that replaces `OUT/NAME/` whole when the run is done, under a
lock (`runner.output.folder`), after `runner.output.budget` has checked what its frames will cost;
the event log is counted as it is written, and a run whose log would pass what the frames leave of
`--max-output-bytes` stops there with an error, its staging folder removed (the previous run stays).
Frames are a `FrameRule`, so nothing sized by the number of ticks is built. A model that stops a run
as a runaway (an `engine.errors.Runaway`: the exact model's event cap or an object with no room to
move, the stepped model's fold limit) raises `RunStopped` with a message for the user. The summary
counts the wall and pair events whether or not they are logged (the models count them as they
happen), and gives the kinetic, potential and total energy at the start and the end
(`engine.invariants.energies`). Each run's kernels run compiled or interpreted (`runner.lanes`:
under `auto`, a run starts interpreted and goes on compiled between two chunks once compiling pays;
the summary's `kernels` says which). Kernels compiled during a run (a first run, before numba has
cached them) are timed apart (`runner.compiling`): the summary's `compile_time_s` holds them and
`run_time_s` leaves them out. Ctrl-C during `run_to_dir` stops the run at the end of the current
chunk of ticks, or at once inside the model's `advance()` (a chunk still compiling its kernels, a
model plugin's loop), the run then ending where the last whole chunk ended: what was written so
far (events, PNG frames, the final state at that tick, a summary with `interrupted_at_tick`)
becomes OUT/NAME, without the GIF, which would be an animation of part of the run, and then
RunInterrupted (a KeyboardInterrupt) is raised, naming that folder: a Python caller stops too, as
it would on Ctrl-C anywhere else. A runaway during `run_to_dir` does the same at the end of the
last whole chunk before it (its summary holds `stopped_at_tick` and the error), and then raises
RunStopped naming that folder. (What the main thread cannot answer in time, a compiled kernel
running on, is the `collide2d` command's watchdog's: runner.interrupt.)
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from collide2d.engine import jit, models
from collide2d.engine.errors import Runaway
from collide2d.engine.events import empty_events
from collide2d.engine.invariants import energies, momentum
from collide2d.engine.picture.raster import Renderer
from collide2d.runner import compiling, interrupt, lanes
from collide2d.runner.output import budget, files, viewerdata
from collide2d.runner.output.folder import (
    OutputBusy,
    OutputRefused,
    RunLock,
    check_replaceable,
    clean_leftovers,
    new_stage,
    swap_in,
)
from collide2d.runner.output.options import RunOptions
from collide2d.runner.output.overlay import Overlay
from collide2d.runner.output.progress import Progress
from collide2d.runner.scenario.frames import FrameRule
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import Scenario, ScenarioError

# Ticks per model call when nothing else ends a chunk: about CHUNK_S seconds of ticks and of
# their outputs at the pace of the chunks so far (FIRST_CHUNK_TICKS before any), at most
# CHUNK_TICKS: long enough that the kernel dominates, short enough that events stream out, progress
# moves and Ctrl-C stops the run within a fraction of a second even where one tick takes long or
# makes many events to write (a dense scene).
CHUNK_TICKS = 65_536
CHUNK_S = 0.25
FIRST_CHUNK_TICKS = 16


class RunStopped(Exception):
    """A model stopped the run with a clear error (a runaway: the exact model's event cap or an
    object with no room to move, or what it cannot carry on exactly yet, or an object crossing the
    world too many times in one stepped step). str(err) is the message; `folder`, for a run that
    writes its files, is OUT/NAME holding the run up to the last whole chunk of ticks before the
    stop (None otherwise)."""

    def __init__(self, message: str, folder: Path | None = None):
        super().__init__(message)
        self.folder = folder


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a run that writes its files: OUT/NAME (`folder`) holds the run so far, its
    `summary` (summary.json's, with `interrupted_at_tick`) too. str(err) says where it stopped."""

    def __init__(self, message: str, folder: Path, summary: dict):
        super().__init__(message)
        self.folder = folder
        self.summary = summary


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
    frames: FrameRule | Iterable[int] = (),
    on_frame: Callable[[int, np.ndarray], None] | None = None,
    log_events: bool = False,
    on_events: Callable[[np.ndarray], None] | None = None,
    progress: Progress | None = None,
    on_tick: Callable[[object], None] | None = None,
    overlay=None,
    interruptible: bool = False,
) -> tuple[object, dict]:
    """Run the scenario; returns (the model at the end, the summary).

    frames: the frames (0..ticks) to rasterise, a FrameRule or frame numbers; each is passed to
    `on_frame(k, index_frame)` as an (H, W) uint8 palette-index image that is only valid during the
    call. log_events: record events and pass each chunk's array to `on_events`. on_tick: called with
    the model at tick 0 and after every tick (the viewer records each tick's state); the model then
    advances one tick per call. overlay: a `runner.output.overlay.Overlay`; it may wrap the model,
    takes the events and draws over each frame before `on_frame` sees it. interruptible: Ctrl-C
    (SIGINT, in the main thread) ends the run after the current chunk of ticks, or inside the
    model's `advance()` at once, where the last whole chunk ended; the summary then holds
    `interrupted_at_tick`. And a runaway ends it where the last whole chunk ended, instead of
    raising RunStopped. Ended where the last whole chunk ended, the returned model is that state
    (its positions, velocities and event counts); after a runaway the summary holds
    `stopped_at_tick` and `stopped` (RunStopped's message).
    """
    if not isinstance(frames, FrameRule):
        frames = FrameRule.of(frames, scenario.ticks)
    lane = lanes.RunLane(scenario, len(frames))
    with lane.opened():
        model, summary = _drive(
            scenario, frames, on_frame, log_events, on_events, progress, on_tick, overlay,
            interruptible, lane,
        )  # fmt: skip
    summary["kernels"] = lane.name()
    return model, summary


def _drive(
    scenario, frames, on_frame, log_events, on_events, progress, on_tick, overlay, interruptible,
    lane,
):  # fmt: skip
    """`drive` in the lanes `lane` chooses as the run goes."""
    bodies = scenario.bodies
    try:
        model = make_model(scenario)
    except Runaway as exc:
        raise RunStopped(
            f"{scenario.path or scenario.name}: error: the {scenario.model} model refused the "
            f"scene: {exc}"
        ) from None
    if overlay is not None:
        model = overlay.wrap(model)
    logging = log_events or (overlay is not None and overlay.wants_events)
    renderer = Renderer(scenario.world, bodies) if frames else None
    start = _energy_momentum(scenario, model)
    began = time.perf_counter()
    compiled_before = compiling.seconds()
    interrupted = interrupt.RunStop() if interruptible else None
    kept = _Kept(model) if interruptible else None  # the state at the last whole chunk's end
    stopped = None
    cut = False  # Ctrl-C inside the model's advance(): the run ends where the last chunk ended
    pace = _Pace()

    if on_tick is not None:
        on_tick(model)
    next_frame = frames.next_from(0)
    if next_frame == 0:
        on_frame(0, _drawn(renderer, model, 0, overlay))
        next_frame = frames.next_from(1)
    with interrupted or contextlib.nullcontext():
        while model.tick < scenario.ticks and not (interrupted and interrupted.seen):
            stop = min(scenario.ticks, model.tick + pace.ticks())
            if next_frame is not None:
                stop = min(stop, next_frame)
            if on_tick is not None:
                stop = model.tick + 1
            stop = model.tick + lane.step(stop - model.tick)
            ticks = stop - model.tick
            pace.start()
            try:
                with lane.timed(ticks):
                    with interrupted.advancing() if interrupted else contextlib.nullcontext():
                        events = model.advance(ticks, logging)
            except Runaway as exc:
                when = (
                    f"tick {stop}" if stop == model.tick + 1 else f"ticks {model.tick + 1}-{stop}"
                )
                stopped = (
                    f"{scenario.path or scenario.name}: error: the {scenario.model} model stopped "
                    f"the run in {when}: {exc}{_names_of(exc, scenario.names)}"
                )
                if kept is None:
                    raise RunStopped(stopped) from None
                break
            except BaseException as exc:
                if not (interrupted and interrupted.seen and interrupt.from_ctrl_c(exc)):
                    raise
                cut = True
                break
            if log_events and len(events) and on_events is not None:
                on_events(events)
            if overlay is not None and logging:
                overlay.events(events)
            if on_tick is not None:
                on_tick(model)
            if model.tick == next_frame:
                with jit.lane(lane.compiled):
                    on_frame(model.tick, _drawn(renderer, model, model.tick, overlay))
                next_frame = frames.next_from(model.tick + 1)
            if progress is not None:
                progress.update(model.tick)
            if kept is not None:
                kept.take(model)
            pace.took(ticks)
    run_time = time.perf_counter() - began - (compiling.seconds() - compiled_before)
    if stopped is not None or cut:
        model = kept  # the model's state is past the outputs written: the kept one is not
    if progress is not None:
        progress.close()

    end = _energy_momentum(scenario, model)
    _check_finite(scenario, model, start, end)
    walls, pairs = model.event_counts()
    summary = {
        "name": scenario.name,
        "model": scenario.model,
        "fps": scenario.world.fps,
        "ticks": scenario.ticks,
        "objects": bodies.n,
        "events": {"wall": walls, "pair": pairs},
        "kinetic_energy": {"start": start[0][0], "end": end[0][0]},
        "potential_energy": {"start": start[0][1], "end": end[0][1]},
        "total_energy": {"start": start[0][2], "end": end[0][2]},
        "momentum": {"start": list(start[1]), "end": list(end[1])},
        "run_time_s": round(max(run_time, 0.0), 6),
        "compile_time_s": round(compiling.seconds(), 6),
    }
    if stopped is not None:
        summary["stopped_at_tick"] = model.tick
        summary["stopped"] = stopped
    elif model.tick < scenario.ticks:
        summary["interrupted_at_tick"] = model.tick
    return model, summary


class _Kept:
    """A model's state as the outputs last saw it (taken after each chunk of ticks): what a run
    stopped by a runaway writes as its final state, its summary's counts and energies. It answers
    as a model does for those (tick, positions, velocities, event_counts)."""

    def __init__(self, model):
        self.take(model)

    def take(self, model) -> None:
        self.tick = model.tick
        self._pos, self._vel = model.positions(), model.velocities()
        self._counts = model.event_counts()

    def positions(self) -> np.ndarray:
        return self._pos

    def velocities(self) -> np.ndarray:
        return self._vel

    def event_counts(self) -> tuple[int, int]:
        return self._counts


def make_model(scenario: Scenario):
    """The scenario's model at tick 0, with the options the scenario sets (engine.models)."""
    options = models.scenario_options(
        scenario.model,
        substeps=scenario.substeps,
        geometry=scenario.geometry,
        max_events_per_tick=scenario.max_events_per_tick,
        iterations=scenario.iterations,
        slop=scenario.slop,
        rest_speed=scenario.rest_speed,
        sleep=scenario.sleep,
        sleep_after=scenario.sleep_after,
        rest_height=scenario.rest_height,
    )
    return models.make(scenario.model, scenario.world, scenario.bodies, **options)


def _names_of(exc: Runaway, names) -> str:
    """The names of the objects a runaway names by id (engine.errors.NoRoom.objects), for its
    message: " (object 3 is ball, object 4 is cup)"; "" when none of them has a name."""
    named = [f"object {i} is {names[i]}" for i in getattr(exc, "objects", ()) if names[i]]
    return f" ({', '.join(named)})" if named else ""


def _drawn(renderer, model, k: int, overlay) -> np.ndarray:
    """Frame k's index picture, with the overlays when there are any."""
    idx = renderer.draw(model.positions())
    return idx if overlay is None else overlay.draw(k, idx, model)


class _Pace:
    """How many ticks the next model call runs: CHUNK_S seconds at the pace of the last chunk,
    from `start` (before the call) to `took` (once its events are written and its frame drawn:
    in a dense scene, writing the events takes longer than the ticks), leaving out the time spent
    compiling kernels."""

    def __init__(self):
        self.per_tick = None  # seconds per tick of the last chunk

    def ticks(self) -> int:
        if self.per_tick is None:
            return FIRST_CHUNK_TICKS
        return int(min(CHUNK_TICKS, max(1, CHUNK_S / max(self.per_tick, 1e-9))))

    def start(self) -> None:
        self._began, self._compiled = time.perf_counter(), compiling.seconds()

    def took(self, ticks: int) -> None:
        spent = time.perf_counter() - self._began - (compiling.seconds() - self._compiled)
        self.per_tick = max(spent, 0.0) / max(ticks, 1)


def simulate(
    scenario: Scenario,
    *,
    keep_frames: Iterable[int] = (),
    log_events: bool = True,
    progress: bool = False,
) -> RunResult:
    """Run in memory; frames in `keep_frames` come back as RGB arrays."""
    if not isinstance(keep_frames, FrameRule):
        keep_frames = FrameRule.of(keep_frames, scenario.ticks)
    with lanes.run(scenario, len(keep_frames)):  # drive's lane, for the final state too
        return _simulate(scenario, keep_frames, log_events, progress)


def _simulate(scenario: Scenario, keep_frames: FrameRule, log_events: bool, progress: bool):
    kept: dict[int, np.ndarray] = {}
    chunks: list[np.ndarray] = []
    # overlays only when the scenario asks for them (then its goldens show them too)
    layer = Overlay(scenario, scenario.output.overlay) if scenario.output.overlay else None
    palette = layer.palette if layer is not None else scenario.palette

    model, summary = drive(
        scenario,
        frames=keep_frames,
        on_frame=lambda k, idx: kept.__setitem__(k, palette[idx]),
        log_events=log_events,
        on_events=chunks.append,
        progress=Progress.for_terminal(scenario.ticks, scenario.name) if progress else None,
        overlay=layer,
    )
    events = np.concatenate(chunks) if chunks else empty_events()
    return RunResult(scenario, events, model.positions(), model.velocities(), kept, summary)


def output_dir(out_root: str | os.PathLike, scenario: Scenario) -> Path:
    """OUT/NAME, refusing a path that would lead outside OUT (a link in the way)."""
    target = Path(out_root) / scenario.name
    try:
        check_replaceable(target)
    except OutputRefused as exc:
        raise ScenarioError(scenario.path or "<scenario>", 1, 1, str(exc)) from None
    return target


def run_to_dir(
    scenario: Scenario,
    out_root: str | os.PathLike,
    options: RunOptions,
    limits: Limits | None = None,
) -> tuple[Path, dict]:
    """Run and write the files of docs/outputs.md as OUT/NAME; returns (that folder, the summary)
    (`write_run`, which also returns the final state)."""
    target, result = write_run(scenario, out_root, options, limits)
    return target, result.summary


def write_run(
    scenario: Scenario,
    out_root: str | os.PathLike,
    options: RunOptions,
    limits: Limits | None = None,
) -> tuple[Path, RunResult]:
    """Run and write the files of docs/outputs.md as OUT/NAME; returns (that folder, a RunResult
    holding the final state and the summary; its events and frames are in the folder, not here).

    The frames are planned and checked against the limits first; then, holding OUT/NAME's lock,
    everything is written into a staging folder that replaces OUT/NAME whole at the end (see
    `runner.output.folder`). On any failure the staging folder goes and the previous run stays.
    """
    limits = limits or Limits()
    plan = budget.plan_frames(
        scenario, png=options.png, gif=options.gif, scale=options.scale, limits=limits
    )
    root = Path(out_root)
    target = output_dir(root, scenario)
    files.make_folder(root)
    try:
        with RunLock(root, scenario.name):
            clean_leftovers(root, scenario.name)
            output_dir(root, scenario)  # again, now that no other run can change it
            stage = new_stage(root, scenario.name)
            try:
                result = _write_run(scenario, stage, options, plan)
                swap_in(stage, target)
            except BaseException as exc:
                shutil.rmtree(stage, ignore_errors=True)
                if isinstance(exc, OSError) and exc.filename:
                    exc.filename = _shown(exc.filename, stage, target)
                raise
    except OutputBusy as exc:
        raise ScenarioError(scenario.path or "<scenario>", 1, 1, str(exc)) from None
    summary = result.summary
    if "interrupted_at_tick" in summary:  # Ctrl-C: the run so far is written, then the caller's
        raise RunInterrupted(
            f"interrupted at tick {summary['interrupted_at_tick']:,} of {scenario.ticks:,}; "
            f"{target} holds the run so far (no GIF)",
            target,
            summary,
        )
    if "stopped_at_tick" in summary:  # a runaway: the run so far is written, then the error
        raise RunStopped(
            f"{summary['stopped']}\n{target} holds the run up to tick "
            f"{summary['stopped_at_tick']:,} (no GIF)",
            target,
        )
    return target, result


def _shown(filename, stage: Path, target: Path) -> str:
    """A path inside the staging folder as the user will know it: under OUT/NAME."""
    path = Path(os.fsdecode(filename))
    try:
        inside = path.relative_to(stage)
    except ValueError:
        return str(path)
    final = inside.with_name(files.final_name(inside.name))
    return str(target / final)


def _write_run(scenario: Scenario, folder: Path, options: RunOptions, plan) -> RunResult:
    """Run the scenario, writing its files into the empty `folder`; returns what it ended with."""
    with lanes.run(scenario, len(plan.draw)):  # the lane `drive` takes, for the viewer's too
        return _write_files(scenario, folder, options, plan)


def _write_files(scenario: Scenario, folder: Path, options: RunOptions, plan) -> RunResult:
    frames_dir = folder / "frames"  # made with its first frame: never an empty folder
    layer = None
    if options.overlay or options.viewer:
        layer = Overlay(scenario, options.overlay, record=options.viewer)
    palette = layer.palette if layer is not None else scenario.palette
    gif = None
    if plan.gif:
        gif = files.GifWriter(
            folder / "animation.gif",
            palette,
            scenario.world.width,
            scenario.world.height,
            scenario.world.fps,
            scenario.ticks + 1,
            scale=options.scale,
        )
        if gif.note and not options.quiet and sys.stderr.isatty():
            print(f"{scenario.name}: {gif.note}", file=sys.stderr)
    log = None
    if options.events:  # within what the frames leave of --max-output-bytes (runner.output.budget)
        log = files.EventsWriter(folder / "events.jsonl", scenario.names, plan.log_room)
    # the viewer refuses a run too long to view
    recorder = viewerdata.Recorder(scenario, layer) if options.viewer else None
    digits = max(6, len(str(scenario.ticks)))

    def on_frame(k: int, idx: np.ndarray) -> None:
        if gif is not None:
            gif.add(idx)
        if k in plan.png:
            frames_dir.mkdir(exist_ok=True)
            name = f"frame_{k:0{digits}d}.png"
            files.write_png(frames_dir / name, palette[idx], scale=options.scale)

    progress = None if options.quiet else Progress.for_terminal(scenario.ticks, scenario.name)
    writers = [w for w in (gif, log) if w is not None]
    try:
        model, summary = drive(
            scenario,
            frames=plan.draw,
            on_frame=on_frame,
            log_events=options.events or recorder is not None,
            on_events=_tee(log.write if log else None, recorder),
            progress=progress,
            on_tick=recorder.add if recorder is not None else None,
            overlay=layer,
            interruptible=True,
        )
        part = "interrupted_at_tick" in summary or "stopped_at_tick" in summary
        if part and gif is not None:
            writers.remove(gif)  # an animation of part of the run: not kept
            gif.abort()
        for writer in writers:
            writer.close()
    except BaseException as exc:
        for writer in writers:
            writer.abort()
        if isinstance(exc, files.LogFull):
            raise _log_full(scenario, exc, plan) from None
        raise
    files.write_final_csv(
        folder / "final.csv", model.positions(), model.velocities(), scenario.names
    )
    if recorder is not None and not part:
        files.atomic_write_bytes(folder / viewerdata.VIEWER_FILE, recorder.page())
    files.write_json(folder / "summary.json", summary)
    return RunResult(scenario, empty_events(), model.positions(), model.velocities(), {}, summary)


def _log_full(scenario: Scenario, full, plan) -> ScenarioError:
    """The refusal of a run whose event log passed its share of --max-output-bytes."""
    limit = f"the output limit of {plan.bytes_bound + full.limit:,} bytes"
    if plan.bytes_bound:
        limit = f"the {full.limit:,} bytes {limit} leaves it after the frames' {plan.bytes_bound:,}"
    return ScenarioError(
        scenario.path or "<scenario>",
        1,
        1,
        f"the run stopped at tick {full.tick:,} of {scenario.ticks:,}: its event log would pass "
        f"{limit}; no file of it was kept (a previous run stays as it was). Log fewer events "
        "(--no-events, fewer ticks or objects) or raise --max-output-bytes",
    )


def _tee(write, recorder):
    """The events callback: the log's writer and the viewer's recorder, whichever are on."""
    if recorder is None:
        return write
    if write is None:
        return recorder.events

    def both(events):
        write(events)
        recorder.events(events)

    return both


def _check_finite(scenario: Scenario, model, start, end) -> None:
    """RunStopped unless the summary's figures and the final state are finite numbers.

    The scenario's bounds (runner.scenario.load, "Numbers") keep them finite; this makes sure that a
    model breaking them stops the run with a message instead of writing inf or nan."""
    figures = np.array([*start[0], *start[1], *end[0], *end[1]], np.float64)
    if not (
        np.isfinite(figures).all()
        and np.isfinite(model.positions()).all()
        and np.isfinite(model.velocities()).all()
    ):
        raise RunStopped(
            f"{scenario.path or scenario.name}: error: the {scenario.model} model ended the run "
            "with a position, velocity, energy or momentum that is not a finite number"
        )


def _energy_momentum(scenario: Scenario, model) -> tuple[tuple, tuple[float, float]]:
    """((kinetic, potential, total energy), momentum) of the model's state now
    (engine.invariants; potential relative to the world's origin, 0 without gravity)."""
    bodies, vel = scenario.bodies, model.velocities()
    found = energies(bodies, model.positions(), vel, scenario.world.gravity)
    return found, momentum(bodies.mass, bodies.static, vel)
