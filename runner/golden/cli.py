"""The `check` and `bless` commands (docs/command-line.md, docs/goldens.md).

Inputs: command-line arguments — scenario files or names (none: every file in `scenarios/`), the
project root (`--root`, default the nearest folder upward with `scenarios/`), `--report DIR`,
`--prune`, `--quiet`, `--max-events-per-tick N` (the exact model's cap, over each scenario's),
`--workers N` / `--scheduler ADDRESS` (check: the runs on Dask, `runner.sweep.checks`).
Outputs: console text (stdout: one block per scenario and a closing count;
stderr: errors and, on a terminal, progress), report folders, golden folders, and the exit status:
0 fine, 1 a check found a difference (or a golden is missing, damaged or hostile), 2 bad input or
usage (a scenario refused, a symbolic link in the way, a file that cannot be read or written such
as a report image on a full disk, named), 3 an unexpected error. Each scenario is checked or
blessed on its own: whatever goes wrong in one is reported (an unexpected error as one line naming
the scenario, its traceback with `--debug`) and the others still run; the exit status is the worst
seen (3 over 2 over 1). `check` also goes on past a scenario file it cannot read (one scenario not
checked, named by its path in the JUnit file and the JSON summaries); `bless` refuses one before
anything runs.

`register(subparsers)` adds both commands to the `collide2d` parser; each sets `func(args) -> int`.
Each scenario is checked or blessed by `check_one`, the step the public `collide2d.check` takes
too. The scenario loader and the simulator can be handed in (tests use
synthetic ones); by default they are `runner.scenario.load.load` and `runner.run.simulate`.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import traceback
from functools import partial
from pathlib import Path

from collide2d.runner.command.exitcodes import (
    EXIT_BAD_INPUT,
    EXIT_DIFFERENCE,
    EXIT_OK,
    EXIT_UNEXPECTED,
)
from collide2d.runner.golden import golden_frames, report, shown_path
from collide2d.runner.golden.formats import Output, add_check_formats, stdout_held
from collide2d.runner.golden.fromreport import add_from_report, bless_from_report
from collide2d.runner.golden.store import (
    GOLDENS_DIR,
    SCENARIO_SUFFIXES,
    SCENARIOS_DIR,
    GoldenError,
    GoldenStore,
    ci_active,
    find_root,
    same_names,
    scenario_files,
)

# `--report` given with no folder: the project's report folder (runner.command.settings).
REPORT_FROM_PROJECT = object()


class _Usage(Exception):
    """Bad input: the message goes to stderr and the command exits with EXIT_BAD_INPUT. `located`
    messages (a refused scenario's `FILE:LINE:COL: error: ...`) are printed as they are."""

    def __init__(self, message: str, *, located: bool = False):
        super().__init__(message)
        self.located = located

    def exit(self) -> int:
        print(str(self) if self.located else f"collide2d: error: {self}", file=sys.stderr)
        return EXIT_BAD_INPUT


def default_load(path, **kwargs):
    """runner.scenario.load.load (imported when first needed)."""
    from collide2d.runner.scenario.load import load

    return load(path, **kwargs)


def default_simulate(scenario, **kwargs):
    """runner.run.simulate (imported when first needed)."""
    from collide2d.runner.run import simulate

    return simulate(scenario, **kwargs)


def viewer_of(simulate):
    """What makes a failing check's viewer: `replay.viewer_page` when the runs are the runner's
    own (`default_simulate`), else None (a stand-in run cannot be run again)."""
    from collide2d.runner.golden import replay

    return replay.viewer_page if simulate is default_simulate else None


def check_one(
    scenario,
    store,
    *,
    path=None,
    bless: bool = False,
    report=None,
    simulate=None,
    run=None,
    viewer=None,
    progress: bool = False,
):
    """Check (or bless) one Scenario against `store` (a `store.GoldenStore`): the session's
    outcome (`session.CheckOutcome`, or what `session.bless_run` gives). `simulate` stands in
    for the runner's in-memory run, `run()` gives the golden run done elsewhere (on a cluster);
    `viewer` makes a failing check's viewer page; `progress` shows a bar on the terminal."""
    from collide2d.runner.golden import session

    simulate = simulate or default_simulate
    result = run() if run is not None else run_scenario(scenario, simulate, progress=progress)
    if bless:
        return session.bless_run(scenario, result, store)
    return session.check_run(scenario, result, store, path=path, report_dir=report, viewer=viewer)


def run_scenario(scenario, simulate, *, progress=False, jit=None):
    """The golden run of `scenario`: events logged, its golden frames kept; `jit`, when given, the
    kernel mode to run it in (runner.lanes: a cluster worker does not share this process's)."""
    if jit is not None:
        from collide2d.runner import lanes

        lanes.set_mode(jit)
    return simulate(
        scenario, keep_frames=tuple(golden_frames(scenario)), log_events=True, progress=progress
    )


def register(subparsers, *, load=None, simulate=None) -> None:
    """Add `check` and `bless` to an argparse subparsers object."""
    load = load or default_load
    simulate = simulate or default_simulate
    commands = (
        (
            "check",
            check_command,
            "compare runs with their goldens",
            "Run scenarios and compare them with goldens/; exit 1 on any difference.",
        ),
        (
            "bless",
            bless_command,
            "write goldens anew",
            "Run scenarios and write their goldens atomically; print what changed.",
        ),
    )
    for name, command, summary, description in commands:
        p = subparsers.add_parser(name, help=summary, description=description)
        p.add_argument(
            "scenarios", nargs="*", metavar="SCENARIO", help="file or name (default: all)"
        )
        if name == "check":
            p.add_argument(
                "--report",
                metavar="DIR",
                nargs="?",
                const=REPORT_FROM_PROJECT,
                help="write expected/actual/diff images and HTML into DIR (with no DIR: the "
                "project's [tool.collide2d] report folder, else report/)",
            )
            add_check_formats(p)
            _cluster_arguments(p)
        else:
            p.add_argument("--prune", action="store_true", help="remove goldens no scenario uses")
            add_from_report(p)
        _common(p)
        p.set_defaults(func=partial(command, load=load, simulate=simulate))


def _cluster_arguments(p) -> None:
    """--workers N | --scheduler ADDRESS: run the scenarios on Dask (runner.sweep)."""
    from collide2d.runner.sweep.cli import add_cluster_arguments

    add_cluster_arguments(p)


def _cluster_runs(args, scenarios, run):
    """None, or the scenarios' runs done on a Dask cluster (runner.sweep.checks)."""
    from collide2d.runner.sweep.checks import cluster_runs

    return cluster_runs(args, scenarios, run, _Usage)


def _common(p) -> None:
    from collide2d.runner.command.options import add_cap_argument, add_jit_argument

    p.add_argument("--root", metavar="DIR", help="project folder holding scenarios/ and goldens/")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    add_cap_argument(p)
    add_jit_argument(p)


def _debug_option(parser) -> None:
    """`--debug` for `main` run on its own (the `collide2d` CLI has a global one)."""
    parser.add_argument(
        "--debug", action="store_true", help="print tracebacks of unexpected errors"
    )


def main(argv=None, *, load=None, simulate=None) -> int:
    """Run `check` or `bless` from `argv` on their own (the `collide2d` CLI adds the others)."""
    parser = argparse.ArgumentParser(prog="collide2d")
    _debug_option(parser)
    register(parser.add_subparsers(dest="command", required=True), load=load, simulate=simulate)
    args = parser.parse_args(argv)
    return args.func(args)


def check_command(args, *, load=default_load, simulate=default_simulate) -> int:
    """`collide2d check`: 0 when every scenario matches its golden, 1 if not, 2 on bad input,
    3 on an unexpected error in any scenario (the others are still checked), never 0 when none
    was checked. Under `--format json`, what the runs print goes to stderr (formats)."""
    json_format = getattr(args, "format", "text") == "json"
    with stdout_held() if json_format else contextlib.nullcontext():
        done = _check_all(args, load, simulate)
    if isinstance(done, int):
        return done
    status, out, outcomes, unused, errors = done
    try:
        out.finish(outcomes, unused, errors)
    except OSError as exc:
        status = max(status, _io_error(exc))
    return status


def _check_all(args, load, simulate):
    """Check every scenario: (status so far, Output, outcomes, unused goldens, errors), or the
    exit status of bad input found before anything ran."""
    refused = []  # (path, error) of the scenario files that could not be read
    try:
        root, scenarios = _prepare(args, load, refused=refused)
        report_dir = _report_dir(args)
        store = _store(args, root)
        if report_dir is not None:
            try:
                report.check_target(report_dir, [scn.name for _p, scn in scenarios])
            except GoldenError as exc:
                raise _Usage(str(exc)) from None
        # Unused goldens are only known when every scenario is read and checked.
        used = None if args.scenarios or refused else [scn.name for _p, scn in scenarios]
        try:
            out = Output(args)
        except GoldenError as exc:
            raise _Usage(str(exc)) from None
        from collide2d.runner import lanes

        runs = _cluster_runs(
            args, scenarios, partial(run_scenario, simulate=simulate, jit=lanes.mode())
        )
    except _Usage as exc:
        return exc.exit()
    outcomes, status, errors = [], EXIT_OK, []
    for path, exc in refused:  # each one case not checked; the others are still checked
        status = max(status, _scenario_failed(args, "reading", path, Path(path).stem, exc))
        said = (
            str(exc)
            if isinstance(exc, scenario_errors())
            else f"{type(exc).__name__}: {_text(exc)}"
        )
        errors.append((shown_path(path), said))
    for i, (path, scn) in enumerate(scenarios, start=1):
        _progress(args, f"[{i}/{len(scenarios)}] checking {scn.name}")
        try:
            outcome = check_one(
                scn,
                store,
                path=path,
                report=report_dir,
                simulate=simulate,
                run=runs[i - 1] if runs is not None else None,  # on Dask (--workers, --scheduler)
                viewer=viewer_of(simulate),
                progress=_show_progress(args),
            )
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # whatever stops one scenario, never the others
            status = max(status, _scenario_failed(args, "checking", path, scn.name, exc))
            errors.append((scn.name, f"{type(exc).__name__}: {_text(exc)}"))
            continue
        outcomes.append(outcome)
        out.say(outcome.message())
    if not outcomes and status == EXIT_OK:  # scenarios found, none checked: never a pass
        status = EXIT_UNEXPECTED
    unused = store.unused(used) if used is not None else []
    if unused:
        out.say(
            f"unused goldens (no scenario uses them): {', '.join(unused)}; "
            "remove them with: collide2d bless --prune"
        )
    elif refused and not args.scenarios:
        out.say("unused goldens not listed: a scenario file could not be read")
    if report_dir is not None:
        try:
            index = report.write_index(report_dir, outcomes, unused, errors)
            out.say(f"report: {shown_path(index)}")
        except OSError as exc:
            status = max(status, _io_error(exc))
    failed = [o for o in outcomes if not o.ok]
    said = f", {len(errors)} not checked (errors above)" if errors else ""
    out.say(f"{len(outcomes) - len(failed)} passed, {len(failed)} failed{said}")
    return max(status, EXIT_DIFFERENCE if failed else EXIT_OK), out, outcomes, unused, errors


def _io_error(exc: OSError, name: str = "") -> int:
    """Print a file that could not be read or written (a full disk), naming it: bad input or
    surroundings, not a bug; returns EXIT_BAD_INPUT."""
    where = "".join(f"{w}: " for w in (name, exc.filename) if w)
    print(f"collide2d: error: {where}{exc.strerror or exc}", file=sys.stderr, flush=True)
    return EXIT_BAD_INPUT


def _text(exc: BaseException) -> str:
    """str(exc), or "<str() failed>" when that raises (an exception of a model plugin's)."""
    try:
        return str(exc)
    except KeyboardInterrupt:
        raise
    except BaseException:
        return "<str() failed>"


def _scenario_failed(args, doing: str, path, name: str, exc: BaseException) -> int:
    """Report what stopped one scenario (`name`) on stderr; returns its exit status:
    EXIT_BAD_INPUT for a refusal (a bad scenario or run, a link in the way) or a file that could
    not be read or written (a full disk), EXIT_UNEXPECTED for anything else (one line naming the
    scenario; the traceback too with --debug)."""
    if isinstance(exc, OSError):
        return _io_error(exc, name)
    if isinstance(exc, _refusals()):
        text = str(exc)
        if isinstance(exc, GoldenError):
            text = f"collide2d: error: {name}: {text}"
        print(text, file=sys.stderr, flush=True)
        return EXIT_BAD_INPUT
    detail = " ".join(_text(exc).split())[:300]
    if type(exc).__name__ == "ModelError":  # a model plugin's doing, named (engine.models)
        what = f"error while {doing} {name} ({shown_path(path)}): {detail}"
    else:
        what = (
            f"unexpected error while {doing} {name} ({shown_path(path)}): "
            f"{type(exc).__name__}{': ' + detail if detail else ''}"
        )
    print(
        f"collide2d: {what}"
        + ("" if getattr(args, "debug", False) else " (run with --debug for the traceback)"),
        file=sys.stderr,
        flush=True,
    )
    if getattr(args, "debug", False):
        traceback.print_exception(type(exc), exc, exc.__traceback__, file=sys.stderr)
    return EXIT_UNEXPECTED


def _refusals() -> tuple:
    """The exception types that refuse one scenario as bad input rather than a bug."""
    from collide2d.runner.run import RunStopped

    return (GoldenError, RunStopped, *scenario_errors())


def bless_command(args, *, load=default_load, simulate=default_simulate) -> int:
    """`collide2d bless`: write the named goldens (all with no argument); 2 on bad input, in CI
    or when a symbolic link stands in the way, 3 on an unexpected error (the other scenarios are
    still blessed)."""
    try:
        if ci_active():
            raise _Usage(
                "CI is set: goldens are never written in CI; bless locally and commit goldens/"
            )
        if getattr(args, "from_report", None):
            return bless_from_report(args, partial(_prepare, load=load))
        root, scenarios = _prepare(args, load)
        store = _store(args, root)
        used = _all_names(root, scenarios, load, args.project) if args.prune else []
    except _Usage as exc:
        return exc.exit()
    status = EXIT_OK
    for i, (path, scn) in enumerate(scenarios, start=1):
        _progress(args, f"[{i}/{len(scenarios)}] running {scn.name}")
        try:
            line = check_one(
                scn, store, path=path, bless=True, simulate=simulate, progress=_show_progress(args)
            ).line()
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # whatever stops one scenario, never the others
            status = max(status, _scenario_failed(args, "blessing", path, scn.name, exc))
            continue
        print(line, flush=True)
    if args.prune:
        for name in store.unused(used):
            try:
                store.remove(name)
            except GoldenError as exc:
                print(f"collide2d: error: {exc}", file=sys.stderr, flush=True)
                status = max(status, EXIT_BAD_INPUT)
                continue
            print(f"{'removed':<9} {name}: no scenario uses it")
    elif not args.scenarios:
        unused = store.unused(scn.name for _p, scn in scenarios)
        if unused:
            print(f"unused goldens kept: {', '.join(unused)} (remove them with --prune)")
    return status


def _prepare(args, load, refused=None):
    """(root, [(path, Scenario)]) for the command's arguments; _Usage on any bad input, before
    anything runs. With a list `refused`, a scenario file that cannot be read (refused, or an
    unexpected error reading it) is left out and added to it as (path, error) instead."""
    from collide2d.runner.command.options import apply_jit

    project = _project(args)
    apply_jit(args, project)
    root, folder = project.root, project.value("scenarios")
    if args.root and not (root / folder).is_dir():
        raise _Usage(f"--root {args.root} has no {folder}/ folder")
    if getattr(args, "report", None) is REPORT_FROM_PROJECT:
        args.report = shown_path(project.folder("report"))
    try:
        _store(args, root).check_dir()
    except GoldenError as exc:
        raise _Usage(str(exc)) from None
    paths = [_resolve(a, root, folder) for a in args.scenarios] or scenario_files(root, folder)
    if not paths:
        raise _Usage(f"no scenario files in {shown_path(root / folder)}")
    load = partial(load, **project.load_options())
    cap = getattr(args, "max_events_per_tick", None)
    if cap is not None:
        load = partial(load, overrides={"max_events_per_tick": cap})
    scenarios = _load_all(paths, load, refused)
    for refusal in same_names((path, scn.name) for path, scn in scenarios).values():
        raise _Usage(refusal)
    return root, scenarios


def _project(args):
    """The project (runner.command.settings.Config) of --root, else found upward from here: the
    nearest folder with a [tool.collide2d] table or a scenarios/ folder; _Usage when there is none
    or its table is refused. Kept on `args` for the goldens folder."""
    from collide2d.runner.command import settings

    try:
        if args.root:
            project = settings.at(args.root)
        else:
            project = settings.find()
            if project.file is None:
                project = settings.at(find_root())
    except GoldenError as exc:
        raise _Usage(str(exc)) from None
    except settings.ConfigError as exc:
        raise _Usage(str(exc), located=True) from None
    args.project = project
    return project


def _store(args, root) -> GoldenStore:
    """The goldens of the project: its [tool.collide2d] goldens folder, else goldens/."""
    project = getattr(args, "project", None)
    return GoldenStore(root, project.value("goldens") if project else GOLDENS_DIR)


def _load_all(paths, load, refused=None):
    errors = scenario_errors()
    out = []
    for path in paths:
        try:
            out.append((path, load(shown_path(path))))
        except Exception as exc:
            if refused is not None:
                refused.append((path, exc))
            elif isinstance(exc, errors):
                raise _Usage(str(exc), located=True) from None
            else:
                raise
    return out


def scenario_errors() -> tuple:
    """The exception types that mean "this scenario file is refused"."""
    from collide2d.runner.scenario.load import ScenarioError

    return (ScenarioError,)


def _resolve(arg: str, root: Path, folder: str = SCENARIOS_DIR) -> Path:
    """A scenario argument as a file: the path itself, else ROOT/scenarios/ARG.yaml."""
    path = Path(arg)
    if path.is_file():
        return path
    for suffix in SCENARIO_SUFFIXES:
        candidate = root / folder / f"{arg}{suffix}"
        if candidate.is_file():
            return candidate
    raise _Usage(f"no scenario {arg!r}: not a file, and no {folder}/{arg}.yaml")


def _all_names(root, scenarios, load, project) -> list[str]:
    """The names of every scenario in ROOT/scenarios/ plus the ones given."""
    loaded = {Path(p).resolve(): s.name for p, s in scenarios}
    files = scenario_files(root, project.value("scenarios"))
    rest = [p for p in files if p.resolve() not in loaded]
    return sorted(set(loaded.values()) | {s.name for _p, s in _load_all(rest, load)})


def _report_dir(args) -> Path | None:
    """The folder of `--report`, None without it; _Usage when it is the project folder, holds
    it, or meets another of the project's folders (runner.command.settings.Config.apart)."""
    if not args.report:
        return None
    from collide2d.runner.command.settings import FolderClash

    try:
        return args.project.apart("report", args.report, "--report")
    except FolderClash as exc:
        raise _Usage(str(exc)) from None


def _show_progress(args) -> bool:
    return not args.quiet and sys.stderr.isatty()


def _progress(args, text: str) -> None:
    if _show_progress(args):
        print(text, file=sys.stderr, flush=True)
