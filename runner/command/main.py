"""The `collide2d` command line (also `python -m collide2d`): parse, dispatch, map errors to exits.

Each subcommand lives with what it drives (`run` here; `validate`/`schema` in
runner.command.validate; `check`/`bless` in runner.golden.cli; `stress`, `bench` and `sweep` in
runner.stress.cli, runner.bench.cli and runner.sweep.cli; `init` in runner.command.newproject,
`config` in runner.command.showconfig) and registers itself on the parser. A command line imports
only the module of its command (`REGISTRARS`), so a run starts without loading the golden, stress,
bench or sweep code; `--help` and an unknown command load them all. Exit status: 0 fine, 1 a check
found a difference, 2 bad input or usage, 3 an unexpected error (one line naming the scenario; the
traceback too with `--debug`), a model plugin's crash or protocol break among them (the line names
the model). A refused scenario prints `FILE:LINE:COL: error: MESSAGE` on stderr
and writes nothing. Ctrl-C is exit 130 (130 is what a command stopped by Ctrl-C returns); the
`collide2d` command itself ends within a second of it, whatever it runs (runner.interrupt), and
`main(argv)` called from Python raises KeyboardInterrupt once the command has answered it, so that
the calling program (a test suite) stops too.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import signal
import sys
import threading
import traceback
from importlib import resources

from collide2d.runner import interrupt
from collide2d.runner.command.exitcodes import (
    EXIT_BAD_INPUT,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_UNEXPECTED,
)
from collide2d.runner.output import escape

# (module, its function that adds subcommands, the commands it adds), in `--help` order.
REGISTRARS = (
    ("collide2d.runner.command.main", "register_run", ("run",)),
    ("collide2d.runner.golden.cli", "register", ("check", "bless")),
    ("collide2d.runner.command.validate", "register", ("validate", "schema")),
    ("collide2d.runner.stress.cli", "register", ("stress",)),
    ("collide2d.runner.bench.cli", "register", ("bench",)),
    ("collide2d.runner.sweep.cli", "register", ("sweep",)),
    ("collide2d.runner.command.newproject", "register", ("init",)),
    ("collide2d.runner.command.showconfig", "register", ("config",)),
)


def demo_path() -> str:
    """The bundled scenario of the paper's section IV: 50 boxes, 10x10, 10 px/s, 10 fps."""
    return str(resources.files("collide2d.runner") / "data" / "paper_fifty_boxes.yaml")


def register_run(subparsers) -> None:
    from collide2d.runner.command.options import (
        add_cap_argument,
        add_jit_argument,
        add_limit_arguments,
        add_override_arguments,
        add_threads_argument,
        positive_int,
    )
    from collide2d.runner.scenario.sections import OVERLAY_NAMES

    p = subparsers.add_parser(
        "run",
        help="run a scenario and write its frames, GIF and event log",
        usage="collide2d run [SCENARIO] [options]",
        description=RUN_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scenario", nargs="?", help="scenario YAML file (default: the bundled demo)")
    written = p.add_argument_group("what is written (default: as the scenario's output says)")
    written.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default: the project's [tool.collide2d] out, else out)",
    )
    written.add_argument(
        "--gif",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write animation.gif (default: the scenario's output.gif)",
    )
    written.add_argument(
        "--png",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write PNG frames: the scenario's output.frames, or all when it asks for "
        "none (default: only if output.frames asks for some)",
    )
    written.add_argument(
        "--events",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write events.jsonl (default: the scenario's output.events)",
    )
    written.add_argument(
        "--viewer",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write viewer.html, a player of the run (default: the scenario's output.viewer)",
    )
    written.add_argument(
        "--overlay",
        type=overlay_names,
        default=None,
        metavar="LIST",
        help="draw debug overlays into the PNG and GIF frames, comma-separated: "
        f"{', '.join(OVERLAY_NAMES)}, or none (default: the scenario's output.overlay)",
    )
    written.add_argument(
        "--scale",
        type=positive_int,
        default=1,
        metavar="K",
        help="enlarge PNG and GIF frames K times, nearest neighbour (default 1)",
    )
    add_override_arguments(p.add_argument_group("instead of the scenario's settings"))
    running = p.add_argument_group("how it runs")
    running.add_argument("--quiet", action="store_true", help="no progress bar, no notes")
    add_threads_argument(running)
    add_jit_argument(running)
    add_cap_argument(add_limit_arguments(p, output=True))
    p.set_defaults(func=cmd_run)


RUN_EXAMPLES = """\
Run SCENARIO (default: the bundled 50-box demo of the paper's section IV) and write OUT/NAME/:
frames/*.png, animation.gif, events.jsonl, final.csv, summary.json.

examples:
  collide2d run                                 the bundled demo -> out/paper_fifty_boxes/
  collide2d run scenarios/example.yaml          a scenario of yours -> out/example/
  collide2d run s.yaml --model exact --fps 60   the same scene under another model and rate
  collide2d run s.yaml --png --scale 4          every frame as PNG, four times the size
  collide2d run s.yaml --overlay velocity,labels --viewer
                                                debug overlays, and viewer.html to play it
  collide2d run s.yaml --quiet --no-gif         no progress bar, no animation.gif

The options below override what the scenario file says; the --max-* limits, last, guard against
a scenario too big for the machine (raise them for a big run, or in pyproject.toml's
[tool.collide2d.limits]).
"""


def overlay_names(text: str) -> tuple[str, ...]:
    """`--overlay a,b`: the overlay names in their fixed order; `none` for none."""
    from collide2d.runner.scenario.sections import OVERLAY_NAMES

    names = [n.strip() for n in text.split(",") if n.strip()]
    if names == ["none"]:
        return ()
    bad = [n for n in names if n not in OVERLAY_NAMES]
    if bad or not names:
        raise argparse.ArgumentTypeError(
            f"unknown overlay {', '.join(bad) or repr(text)}; choose from "
            f"{', '.join(OVERLAY_NAMES)} or none"
        )
    return tuple(n for n in OVERLAY_NAMES if n in names)


def cmd_run(args: argparse.Namespace) -> int:
    from collide2d.runner.command import settings
    from collide2d.runner.command.options import (
        apply_jit,
        apply_threads,
        limits_from_args,
        overrides_from_args,
    )
    from collide2d.runner.output.options import RunOptions
    from collide2d.runner.run import RunInterrupted, write_run
    from collide2d.runner.scenario.load import load

    project = settings.find()
    if args.out and (project.file or project.scenarios.is_dir()):
        # a folder of its own, apart from the project's other folders (runner.command.settings)
        try:
            project.apart("out", args.out, "--out")
        except settings.FolderClash as exc:
            print(f"collide2d: error: {exc}", file=sys.stderr)
            return EXIT_BAD_INPUT
    apply_threads(args, project)
    apply_jit(args, project)
    path = args.scenario or demo_path()
    limits = limits_from_args(args, project)
    scenario = load(
        path,
        overrides=overrides_from_args(args),
        limits=limits,
        defaults=project.model_defaults(),
    )
    out_root = args.out or (project.folder("out") if project.file else "out")
    options = RunOptions.asked(
        scenario,
        events=scenario.output.events if args.events is None else args.events,
        png=args.png,
        gif=args.gif,
        viewer=args.viewer,
        overlay=args.overlay,
        scale=args.scale,
        quiet=args.quiet,
    )
    try:
        folder, done = write_run(scenario, out_root, options, limits)
    except RunInterrupted as stop:  # Ctrl-C: the run so far is written (docs/outputs.md)
        _ran(args, scenario, stop.folder, stop.summary)
        interrupt.told(f"collide2d: {stop}")
        return EXIT_INTERRUPTED
    _ran(args, scenario, folder, done.summary)
    return EXIT_OK


def _ran(args: argparse.Namespace, scenario, target, summary: dict) -> None:
    """The line saying what a run did (not with --quiet)."""
    if not args.quiet:
        counts = summary["events"]
        compiled = summary.get("compile_time_s", 0.0)
        also = f" (+{compiled:.1f}s compiling kernels)" if compiled >= 0.05 else ""
        ran = plural(scenario.ticks, "tick")
        if "interrupted_at_tick" in summary:  # the ticks run, not the ticks asked for
            ran = f"{summary['interrupted_at_tick']:,} of {ran}"
        print(
            f"{scenario.name}: {ran} under {scenario.model}, "
            f"{counts['wall']:,} wall and {plural(counts['pair'], 'pair event')} "
            f"in {summary['run_time_s']:.3f}s{also} -> {target}"
        )


def plural(count: int, noun: str) -> str:
    """`1 tick`, `2 ticks`, `1,000 ticks` (nouns that take an s)."""
    return f"{count:,} {noun}{'' if count == 1 else 's'}"


# The commands that run kernels: they time compilation apart and say when it starts.
COMPILING_COMMANDS = ("run", "check", "bless", "validate", "stress", "bench", "sweep")


def command_of(argv: list[str]) -> str | None:
    """The subcommand named in argv (the first word that is not an option), or None."""
    for word in argv:
        if not word.startswith("-"):
            return word
        if word == "--":
            return None
    return None


class _Version(argparse.Action):
    """`--version`, the distribution's version read only when asked for (collide2d.__getattr__)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from collide2d.runner.command.version import version

        print(f"collide2d {version()}")
        parser.exit()


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser; with `command`, one of REGISTRARS' commands, only its module is loaded ("":
    none)."""
    parser = argparse.ArgumentParser(
        prog="collide2d",
        description="Declarative 2D collision scenarios: run them, see them, keep them honest.",
    )
    parser.add_argument("--version", action=_Version, help="show the version and exit")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module, function, commands in REGISTRARS:
        if command is None or command in commands:
            getattr(importlib.import_module(module), function)(subparsers)
    for sub in subparsers.choices.values():
        sub.add_argument(
            "--debug", action="store_true", help="print the traceback of an unexpected error"
        )
    return parser


def main(argv: list[str] | None = None) -> int:
    called = argv is not None  # from Python, not the `collide2d` command itself
    if not called:
        from collide2d.runner.command import crashwatch

        crashwatch.watch()  # a fatal signal (a crash in a kernel) is told, never silent
        interrupt.watch()  # Ctrl-C ends the command within a second, whatever it runs
    argv = sys.argv[1:] if argv is None else list(argv)
    command = command_of(argv)
    known = any(command in commands for _m, _f, commands in REGISTRARS)
    if command is None and "--version" in argv and "-h" not in argv and "--help" not in argv:
        known, command = True, ""  # the version alone: no command's module is needed
    parser = build_parser(command if known else None)
    with escape.visible_streams():  # names and file names never reach a terminal raw
        args = parser.parse_args(argv)
        if args.command in COMPILING_COMMANDS:
            from collide2d.runner import compiling
            from collide2d.runner.command.compilenotice import CompileNotice

            quiet = getattr(args, "quiet", False) or not sys.stderr.isatty()
            compiling.install(None if quiet else CompileNotice())
        status = _answered(args)
    if called and status == EXIT_INTERRUPTED:
        raise KeyboardInterrupt  # the caller's Ctrl-C too, answered by the command (above)
    return status


def _answered(args: argparse.Namespace) -> int:
    """Run the command; its errors are printed and become its exit status."""
    from collide2d.runner.scenario.parse import ScenarioError

    try:
        with _ctrl_c_answered():
            return args.func(args)
    except ScenarioError as err:  # a refused scenario, or a refused [tool.collide2d] table
        print(str(err), file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as err:
        if interrupt.from_ctrl_c(err):
            return _interrupted()
        if type(err).__name__ == "RunStopped":  # runner.run's, not imported unless a run ran
            print(str(err), file=sys.stderr)
            return EXIT_BAD_INPUT
        if isinstance(err, OSError):
            where = f"{err.filename}: " if err.filename else ""
            print(f"collide2d: error: {where}{err.strerror or err}", file=sys.stderr)
            return EXIT_BAD_INPUT
        return unexpected(err, args)
    except KeyboardInterrupt:
        return _interrupted()


def _interrupted() -> int:
    interrupt.told("collide2d: interrupted; outputs already written are whole")
    return EXIT_INTERRUPTED


# A Ctrl-C that arrives while Python runs a finalizer (`__del__`: numba's compiler frees LLVM
# objects so, often, while it compiles a kernel) would be lost there: Python prints "Exception
# ignored" and goes on. The interrupt is raised this many seconds later instead, once out of it.
INTERRUPT_RETRY_S = 0.01


def _interrupt(signum, frame):
    """Raise KeyboardInterrupt, or, inside a finalizer, raise it a moment later (SIGALRM)."""
    if hasattr(signal, "setitimer") and interrupt.in_finalizer(frame):
        signal.setitimer(signal.ITIMER_REAL, INTERRUPT_RETRY_S)
        return
    raise KeyboardInterrupt


@contextlib.contextmanager
def _ctrl_c_answered():
    """Ctrl-C (SIGINT) raises KeyboardInterrupt while a command runs (`_interrupt`), also when
    the process started with SIGINT ignored, as a shell starts a job in the background of a
    script (Python keeps it ignored then); the handlers it had are put back after. Commands that
    stop more gently (`run` at the end of a chunk, a sweep cancelling its tasks) set their own
    inside."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    retry = hasattr(signal, "setitimer")  # not on Windows: there a Ctrl-C in a finalizer is lost
    signals = (signal.SIGINT, signal.SIGALRM) if retry else (signal.SIGINT,)
    before = {sig: signal.signal(sig, _interrupt) for sig in signals}
    try:
        yield
    finally:
        if retry:
            signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in before.items():
            signal.signal(sig, handler)


def unexpected(err: Exception, args: argparse.Namespace) -> int:
    """Report an unexpected error in one line naming what was being run (with the traceback
    under --debug); the exit status is EXIT_UNEXPECTED."""
    if getattr(args, "debug", False):
        traceback.print_exception(type(err), err, err.__traceback__, file=sys.stderr)
    what = getattr(args, "scenario", None)
    if isinstance(what, list):
        what = " ".join(what)
    where = f" while running {what or args.command}"
    if type(err).__name__ == "ModelError":  # a model plugin's fault (engine.models.protocol)
        print(f"collide2d: error{where}: {err} (--debug shows where)", file=sys.stderr)
        return EXIT_UNEXPECTED
    print(
        f"collide2d: unexpected error{where}: {type(err).__name__}: {err} "
        "(this is a bug; --debug shows where)",
        file=sys.stderr,
    )
    return EXIT_UNEXPECTED


if __name__ == "__main__":
    sys.exit(main())
