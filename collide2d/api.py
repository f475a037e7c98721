"""The public Python API: load a scenario, run it under a model, check and bless its goldens.

`load` reads a scenario from a file or a dict into a `Scenario` (the same reader as the command
line: a refused scenario raises `ScenarioError`, whose text is `FILE:LINE:COL: error: MESSAGE`).
`run` runs one under its model or another, in memory or into an output folder, and returns a
`Result`: the final state as named columns, the events as records, the frames asked for as arrays
and the summary. `check` compares runs with the project's goldens, or blesses them, and returns a
`CheckResult`. The `collide2d run`, `check` and `bless` commands are a layer over these functions:
a run from Python and a run from the command line take one path, and an argument is refused as
its option is (`collide2d.arguments`: a TypeError or ValueError naming it).

Importing this module costs only the standard library; the runner is imported when a function is
first called (a command that never runs a scenario does not pay for numpy or numba).
"""

from __future__ import annotations

import os
import weakref
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

from collide2d import arguments

if TYPE_CHECKING:
    import numpy as np

    from collide2d.runner.scenario.limits import Limits
    from collide2d.runner.scenario.load import Scenario

__all__ = ["CheckResult", "Result", "ScenarioCheck", "check", "load", "run"]

Source = Union[str, "os.PathLike[str]", Mapping[str, Any]]

# Where each Scenario `load` returned came from, so that `run(scenario, model=...)` can read it
# again under another model (the model's rules decide what a scenario may hold).
_SOURCES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def load(
    source: Source,
    *,
    model: str | None = None,
    fps: int | None = None,
    ticks: int | None = None,
    max_events_per_tick: int | None = None,
    limits: Limits | None = None,
    defaults: Mapping[str, Any] | None = None,
) -> Scenario:
    """Read and check a scenario.

    Args:
        source: a scenario file (a path), or the scenario itself as a dict (what the YAML file
            would hold: `{"version": 1, "world": {...}, "objects": [...]}`; numpy numbers and
            arrays and tuples stand for the numbers and lists YAML gives).
        model: run it under this model instead of the one it names (a built-in, `paper`,
            `stepped` or `exact`, or a registered plugin); like `collide2d run --model`.
        fps: ticks per simulated second instead of `world.fps` (`--fps`).
        ticks: ticks to run instead of `ticks` or `duration` (`--ticks`).
        max_events_per_tick: the exact model's cap instead of the scenario's.
        limits: the guards against a scenario too big for the machine (`Limits`; default the
            built-in ones).
        defaults: model settings used where the scenario gives none (`kind`, `substeps`,
            `geometry`, `max_events_per_tick`), as a project's `[tool.collide2d.model]` gives.

    Returns:
        The checked `Scenario`: world, model, bodies as arrays, names, output and golden settings.

    Raises:
        ScenarioError: the scenario is refused; `str(err)` is `FILE:LINE:COL: error: MESSAGE`
            (for a dict, the place is in the YAML text it is written as, and a value YAML would
            not give is named by its place in the dict: `objects[1].velocity: ...`).
        TypeError, ValueError: an argument is refused (`fps="10"`, `max_events_per_tick=0`);
            the message starts with it.
    """
    from collide2d.runner.scenario import load as reader

    source = arguments.source("source", source)
    overrides = {
        "model": arguments.model(model),
        "fps": arguments.whole("fps", fps),
        "ticks": arguments.whole("ticks", ticks),
        "max_events_per_tick": arguments.whole("max_events_per_tick", max_events_per_tick, lo=1),
    }
    limits = arguments.limits(limits)
    options = {"overrides": overrides, "limits": limits, "defaults": arguments.defaults(defaults)}
    if isinstance(source, Mapping):
        scenario = reader.loads(arguments.scenario_text(source), **options)
    else:
        scenario = reader.load(source, **options)
    _SOURCES[scenario] = (source, options)
    return scenario


@dataclass(frozen=True)
class Result:
    """What one run gives back.

    Attributes:
        scenario: the Scenario that ran (under the model that ran it: `scenario.model`).
        final: the final state as named columns, one row per object in id order: `id` (int64),
            `x`, `y` (the top-left corner, px), `vx`, `vy` (px/s) as float64 arrays, and `name`
            (a tuple, None for an object without one); the columns of `final.csv`.
        events: the events as records in the order they happened, a numpy structured array of
            `collide2d.engine.events.EVENT_DTYPE` (`tick`, `t`, `type`, `a`, `b`, `code`,
            `xdiff`, `ydiff`); empty when events were not asked for. `event_log()` gives them as
            the dicts of `events.jsonl`.
        frames: frame number -> (height, width, 3) uint8 RGB picture, for the frames asked for.
        summary: what `summary.json` holds (event counts, energy and momentum, run time).
        folder: the output folder written (`run(..., out=DIR)`), else None.
    """

    scenario: Scenario
    final: dict[str, Any]
    events: np.ndarray
    frames: dict[int, np.ndarray] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)
    folder: Path | None = None

    @property
    def positions(self) -> np.ndarray:
        """(n, 2) float64: each object's final top-left corner, px."""
        import numpy as np

        return np.stack([self.final["x"], self.final["y"]], axis=1)

    @property
    def velocities(self) -> np.ndarray:
        """(n, 2) float64: each object's final velocity, px/s."""
        import numpy as np

        return np.stack([self.final["vx"], self.final["vy"]], axis=1)

    def event_log(self) -> list[dict[str, Any]]:
        """The events as the JSON objects of `events.jsonl`, in order."""
        from collide2d.engine.events import event_dict

        return [event_dict(rec) for rec in self.events]


def run(
    scenario: Scenario | Source,
    model: str | None = None,
    frames: Iterable[int] | str | None = None,
    events: bool = True,
    *,
    out: str | os.PathLike[str] | None = None,
    png: bool | None = None,
    gif: bool | None = None,
    viewer: bool | None = None,
    overlay: Sequence[str] | None = None,
    scale: int = 1,
    quiet: bool = True,
    limits: Limits | None = None,
) -> Result:
    """Run a scenario and return what it ended with.

    Args:
        scenario: a Scenario from `load`, or what `load` takes (a path or a dict).
        model: run under this model instead of the scenario's (the scenario is read again under
            it, as `load(..., model=...)` would).
        frames: the frames (0 to `ticks`) to keep as arrays in `Result.frames`: frame numbers,
            `"all"`, `"last"`, `"golden"` (the scenario's golden frames) or `"output"` (its
            `output.frames`); None keeps none. In memory only (refused with `out`).
        events: record the events (`Result.events`; with `out`, write `events.jsonl`).
        out: write the run's files (frames, GIF, event log, `final.csv`, `summary.json`) into
            `OUT/NAME/` as `collide2d run --out OUT` does, replacing a previous run whole; the
            result then holds the final state and the summary, and its events and frames are
            in the folder.
        png: with `out`, write PNG frames (default: as the scenario's `output` says).
        gif: with `out`, write `animation.gif` (default: as the scenario's `output` says).
        viewer: with `out`, write `viewer.html` (default: as the scenario's `output` says).
        overlay: with `out`, the debug overlays drawn into the frames (default: the scenario's):
            names, or one text of names separated by commas as `--overlay` takes; `"none"` or
            `[]` for none.
        scale: with `out`, enlarge PNG and GIF frames this many times.
        quiet: with `out`, no progress bar or notes on the terminal.
        limits: the guards (`Limits`): on the scenario read when `scenario` is a path or a dict,
            and with `out` on what may be written (`--max-output-bytes` ...).

    The arguments marked "with `out`" are refused (ValueError) without it, as `frames` is with
    it: a run never leaves an argument unused without a word.

    Returns:
        A `Result`.

    Raises:
        ScenarioError: the scenario is refused (or, with `out`, the output would pass a limit).
        RunStopped: the model stopped the run (a runaway); `str(err)` says why. With `out`, the
            run folder then holds the run so far (`err.folder`; docs/limits.md#runaways).
        RunInterrupted: with `out`, Ctrl-C stopped the run; the run folder holds the run so far
            (`err.folder`, its summary `err.summary`; docs/outputs.md#interrupted-runs). It is
            a KeyboardInterrupt, as Ctrl-C raises without `out`: the calling program stops too
            unless it catches it.
        ModelError: a plugin model raised or broke the model protocol; `str(err)` names it.
        TypeError, ValueError: an argument is refused (`frames=True`, `overlay=["nope"]`,
            `scale=0`); the message starts with it, and nothing has run.
    """
    from collide2d.runner import run as runner
    from collide2d.runner.output.options import RunOptions

    given = {"png": png, "gif": gif, "viewer": viewer, "overlay": overlay, "scale": scale}
    given |= {"quiet": quiet, "frames": frames}
    model = arguments.model(model)
    frames = arguments.frames(frames)
    events = arguments.flag("events", events)
    out = arguments.folder("out", out)
    png = arguments.flag("png", png, none=True)
    gif = arguments.flag("gif", gif, none=True)
    viewer = arguments.flag("viewer", viewer, none=True)
    overlay = arguments.overlay(overlay)
    scale = arguments.whole("scale", scale, lo=1)
    quiet = arguments.flag("quiet", quiet)
    limits = arguments.limits(limits)
    checked = {"png": png, "gif": gif, "viewer": viewer, "overlay": overlay, "scale": scale}
    checked |= {"quiet": quiet, "frames": frames}
    arguments.with_out(out, {name: (given[name], checked[name]) for name in given})
    scenario = _scenario(scenario, model, limits)
    if out is not None:
        options = RunOptions.asked(
            scenario, events=events, png=png, gif=gif, viewer=viewer, overlay=overlay,
            scale=scale, quiet=quiet,
        )  # fmt: skip
        folder, done = runner.write_run(scenario, out, options, limits)
        return _result(done, folder)
    keep = _frames(scenario, frames)
    return _result(runner.simulate(scenario, keep_frames=keep, log_events=events), None)


def _scenario(scenario, model: str | None, limits=None):
    """The Scenario to run: `scenario` itself, read by `load` (under `limits`) when it is not one,
    read again under `model` when that differs from its own."""
    from collide2d.runner.scenario.load import Scenario

    if not isinstance(scenario, Scenario):
        return load(arguments.source("scenario", scenario), model=model, limits=limits)
    if model is None or model == scenario.model:
        return scenario
    source, options = _SOURCES.get(scenario, (scenario.path, None))
    if source is None:
        raise ValueError(
            "this Scenario was not read by collide2d.load, so it cannot be read again under "
            f"another model; load it with model={model!r}"
        )
    options = dict(options or {"overrides": {}})
    options.pop("overrides", None)
    kept = {"limits": limits or options.get("limits"), "defaults": options.get("defaults")}
    return load(source, model=model, **kept)


def _frames(scenario, frames):
    """The FrameRule of `run(frames=...)`."""
    from collide2d.runner.scenario.frames import FrameRule

    ticks = scenario.ticks
    if frames is None:
        return FrameRule.none(ticks)
    if isinstance(frames, str):  # a word of collide2d.arguments.FRAME_WORDS
        if frames == "all":
            return FrameRule.all(ticks)
        if frames == "last":
            return FrameRule.last(ticks)
        if frames == "output":
            return scenario.output.frames
        return FrameRule.of(sorted(set(scenario.golden.frames)), ticks)
    numbers = list(frames)
    bad = [k for k in numbers if not 0 <= k <= ticks]
    if bad:
        raise ValueError(f"frame {bad[0]} is not one of the run's frames 0 to {ticks}")
    return FrameRule.of(numbers, ticks)


def _result(done, folder) -> Result:
    """The public Result of the runner's RunResult."""
    import numpy as np

    scenario = done.scenario
    pos = np.asarray(done.final_pos, np.float64)
    vel = np.asarray(done.final_vel, np.float64)
    final = {
        "id": np.arange(len(pos), dtype=np.int64),
        "x": pos[:, 0].copy(),
        "y": pos[:, 1].copy(),
        "vx": vel[:, 0].copy(),
        "vy": vel[:, 1].copy(),
        "name": tuple(scenario.names),
    }
    return Result(scenario, final, done.events, dict(done.frames), dict(done.summary), folder)


@dataclass(frozen=True)
class ScenarioCheck:
    """The check (or bless) of one scenario.

    Attributes:
        name: the scenario's name.
        path: its file as shown in messages.
        status: check: `passed`, `failed`, `missing` (no golden yet) or `unreadable`;
            bless: `created`, `updated` or `unchanged`.
        ok: passed (check) or written (bless).
        problems: one text per difference found (events, frames, final state), in order.
        message: the text `collide2d check` / `bless` prints for it.
        report: its report page when one was written (`check(..., report=DIR)`), else None.
    """

    name: str
    path: str
    status: str
    ok: bool
    problems: tuple[str, ...] = ()
    message: str = ""
    report: Path | None = None
    _record: Any = field(default=None, repr=False, compare=False)  # the runner's own record


@dataclass(frozen=True)
class CheckResult:
    """What `check` found: one `ScenarioCheck` per scenario, in the order run.

    Attributes:
        scenarios: the ScenarioChecks.
        ok: every scenario passed (or was blessed).
    """

    scenarios: tuple[ScenarioCheck, ...]

    @property
    def ok(self) -> bool:
        return all(s.ok for s in self.scenarios)

    def __getitem__(self, name: str) -> ScenarioCheck:
        """The check of the scenario called `name`."""
        for s in self.scenarios:
            if s.name == name:
                return s
        raise KeyError(name)


def check(
    scenarios: Scenario | Source | Iterable[Scenario | Source] | None = None,
    *,
    root: str | os.PathLike[str] | None = None,
    bless: bool = False,
    report: str | os.PathLike[str] | None = None,
) -> CheckResult:
    """Compare scenarios' runs with their goldens, or write the goldens (`bless=True`).

    Args:
        scenarios: one scenario or several: Scenarios from `load`, paths, or names of files in
            the project's scenarios folder; None: every scenario of the project.
        root: the project folder (holding `scenarios/` and `goldens/`, or a pyproject.toml with
            a `[tool.collide2d]` table); default: found upward from the current folder.
        bless: write each scenario's golden from its run (atomically; never when the CI
            environment variable is set) instead of comparing.
        report: with a failing check, write its report (expected, actual and diff images, an
            HTML page) into this folder.

    Returns:
        A `CheckResult`; `result.ok` is True when every scenario matched (or was written).

    Raises:
        ScenarioError: a scenario is refused.
        GoldenError: a golden cannot be written (a symbolic link in the way, CI set for bless).
        RunStopped, ModelError: as for `run`.
        TypeError, ValueError: an argument is refused as `collide2d check` refuses it, before
            anything runs: a `root` without a scenarios folder, no scenario to check (an empty
            list, a project without scenario files), two scenarios of one name, a `report`
            folder that meets the project's folders (or with `bless`).
    """
    from collide2d.runner.golden import store
    from collide2d.runner.golden.report import check_target

    items = arguments.scenarios(scenarios)
    root = arguments.folder("root", root)
    bless = arguments.flag("bless", bless)
    report = arguments.folder("report", report)
    if bless and report is not None:
        raise ValueError(
            f"report={arguments.brief(report)}: a report is written by a check, not by bless"
        )
    project = _project(root)
    folder = project.value("scenarios")
    if root is not None and not (project.root / folder).is_dir():
        raise ValueError(f"root={arguments.brief(root)} has no {folder}/ folder")
    goldens = store.GoldenStore(project.root, project.value("goldens"))
    goldens.check_dir()
    if bless and store.ci_active():
        raise store.GoldenError("CI is set: goldens are never written in CI")
    report_dir = project.apart("report", report, "report") if report is not None else None
    if items is None:
        items = store.scenario_files(project.root, folder)
        if not items:
            raise ValueError(f"no scenario files in {store.shown_path(project.root / folder)}")
    loaded = [_loaded(item, project) for item in items]
    named = [
        (path or scenario.path or f"<{scenario.name}>", scenario.name) for path, scenario in loaded
    ]
    for refusal in store.same_names(named).values():
        raise ValueError(refusal)
    if report_dir is not None:
        check_target(report_dir, [scenario.name for _, scenario in loaded])
    done = [
        _checked(scenario, goldens, path, bless, report_dir)
        for path, scenario in loaded
    ]
    return CheckResult(tuple(done))


def _loaded(item, project) -> tuple[Path | None, Scenario]:
    """(its file, the Scenario) of a scenario given to `check`: read (under the project's
    settings) when it is a file, a name or a dict."""
    if isinstance(item, Mapping):
        return None, load(item, **project.load_options())
    if isinstance(item, (str, os.PathLike)):
        path = _resolve(item, project)
        return path, load(path, **project.load_options())
    return None, item


def _checked(scenario: Scenario, store: Any, path: str | os.PathLike[str] | None, bless: bool,
             report: Path | None) -> ScenarioCheck:
    """Check (or bless) one Scenario against `store` (a `runner.golden.store.GoldenStore`), the
    step the `collide2d check` and `bless` commands take (runner.golden.cli.check_one), as a
    ScenarioCheck."""
    from collide2d.runner.golden.cli import check_one

    outcome = check_one(scenario, store, path=path, bless=bless, report=report)
    if bless:
        shown = str(path or scenario.path or scenario.name)
        return ScenarioCheck(
            outcome.name, shown, outcome.status, True, (), outcome.line(), None, outcome
        )
    problems = tuple(p if isinstance(p, str) else p.message for p in outcome.problems)
    return ScenarioCheck(
        outcome.name,
        outcome.scenario,
        outcome.status,
        outcome.ok,
        problems,
        outcome.message(),
        outcome.report,
        outcome,
    )


def _project(root):
    """The project (runner.command.settings.Config) at `root`, else found upward from here."""
    from collide2d.runner.command import settings
    from collide2d.runner.golden.store import find_root

    if root is not None:
        return settings.at(root)
    project = settings.find()
    return project if project.file is not None else settings.at(find_root())


def _resolve(item, project) -> Path:
    """A scenario given to `check` as a file: the path itself, else the project's
    `scenarios/ITEM.yaml` (or `.yml`)."""
    from collide2d.runner.golden.store import SCENARIO_SUFFIXES

    path = Path(item)
    if path.is_file():
        return path
    for suffix in SCENARIO_SUFFIXES:
        candidate = project.folder("scenarios") / f"{item}{suffix}"
        if candidate.is_file():
            return candidate
    raise FileNotFoundError(f"no scenario {str(item)!r}: not a file, nor in the scenarios folder")
