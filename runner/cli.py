"""The `collide2d` command line (also `python -m collide2d`): parse, dispatch, map errors to exits.

Each subcommand lives with what it drives (`run` here; `validate`/`schema` in runner.validate;
`check`/`bless` in runner.golden.cli; `stress` and `bench` in runner.stress.cli and
runner.bench.cli, which load the rest of their packages only when their command runs) and registers
itself on the parser. Exit status: 0 fine, 1 a check found a difference, 2 bad input or usage, 3 an
unexpected error (one line naming the scenario; the traceback too with `--debug`). A refused
scenario prints `FILE:LINE:COL: error: MESSAGE` on stderr and writes nothing.
"""

from __future__ import annotations

import argparse
import sys
import traceback
from importlib import resources

from collide2d.runner import validate
from collide2d.runner.bench import cli as bench_cli
from collide2d.runner.exitcodes import EXIT_BAD_INPUT, EXIT_OK, EXIT_UNEXPECTED
from collide2d.runner.golden import cli as golden_cli
from collide2d.runner.options import (
    add_cap_argument,
    add_limit_arguments,
    add_override_arguments,
    add_threads_argument,
    apply_threads,
    limits_from_args,
    overrides_from_args,
    positive_int,
)
from collide2d.runner.outputspec import OVERLAY_NAMES
from collide2d.runner.run import RunOptions, RunStopped, run_to_dir
from collide2d.runner.scenario import ScenarioError, load
from collide2d.runner.stress import cli as stress_cli
from collide2d.runner.sweep import cli as sweep_cli


def demo_path() -> str:
    """The bundled scenario of the paper's section IV: 50 boxes, 10x10, 10 px/s, 10 fps."""
    return str(resources.files("collide2d.runner") / "data" / "paper_fifty_boxes.yaml")


def register_run(subparsers) -> None:
    p = subparsers.add_parser(
        "run",
        help="run a scenario and write its frames, GIF and event log",
        description="Run SCENARIO (default: the bundled 50-box demo of the paper's section IV) "
        "and write OUT/NAME/: frames/*.png, animation.gif, events.jsonl, final.csv, summary.json. "
        "Flags override the scenario's output and settings.",
    )
    p.add_argument("scenario", nargs="?", help="scenario YAML file (default: the bundled demo)")
    p.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    p.add_argument(
        "--gif",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write animation.gif (default: the scenario's output.gif)",
    )
    p.add_argument(
        "--png",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write PNG frames: the scenario's output.frames, or all when it asks for "
        "none (default: only if output.frames asks for some)",
    )
    p.add_argument(
        "--events",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write events.jsonl (default: the scenario's output.events)",
    )
    p.add_argument(
        "--viewer",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="write viewer.html, a player of the run (default: the scenario's output.viewer)",
    )
    p.add_argument(
        "--overlay",
        type=overlay_names,
        default=None,
        metavar="LIST",
        help="draw debug overlays into the PNG and GIF frames, comma-separated: "
        f"{', '.join(OVERLAY_NAMES)}, or none (default: the scenario's output.overlay)",
    )
    add_override_arguments(p)
    p.add_argument(
        "--scale",
        type=positive_int,
        default=1,
        metavar="K",
        help="enlarge PNG and GIF frames K times, nearest neighbour (default 1)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar, no notes")
    add_limit_arguments(p, output=True)
    add_cap_argument(p)
    add_threads_argument(p)
    p.set_defaults(func=cmd_run)


def overlay_names(text: str) -> tuple[str, ...]:
    """`--overlay a,b`: the overlay names in their fixed order; `none` for none."""
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
    apply_threads(args)
    path = args.scenario or demo_path()
    limits = limits_from_args(args)
    scenario = load(path, overrides=overrides_from_args(args), limits=limits)
    out = scenario.output
    options = RunOptions(
        png=bool(out.frames) if args.png is None else args.png,
        gif=out.gif if args.gif is None else args.gif,
        events=out.events if args.events is None else args.events,
        scale=args.scale,
        quiet=args.quiet,
        viewer=out.viewer if args.viewer is None else args.viewer,
        overlay=out.overlay if args.overlay is None else args.overlay,
    )
    target, summary = run_to_dir(scenario, args.out, options, limits)
    if not args.quiet:
        counts = summary["events"]
        print(
            f"{scenario.name}: {scenario.ticks} ticks under {scenario.model}, "
            f"{counts['wall']:,} wall and {counts['pair']:,} pair events "
            f"in {summary['run_time_s']:.3f}s -> {target}"
        )
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="collide2d",
        description="Declarative 2D collision scenarios: run them, see them, keep them honest.",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    register_run(subparsers)
    golden_cli.register(subparsers)
    validate.register(subparsers)
    stress_cli.register(subparsers)
    bench_cli.register(subparsers)
    sweep_cli.register(subparsers)
    for sub in subparsers.choices.values():
        sub.add_argument(
            "--debug", action="store_true", help="print the traceback of an unexpected error"
        )
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ScenarioError as err:
        print(str(err), file=sys.stderr)
        return EXIT_BAD_INPUT
    except RunStopped as err:
        print(str(err), file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as err:
        where = f"{err.filename}: " if err.filename else ""
        print(f"collide2d: error: {where}{err.strerror or err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("collide2d: interrupted; outputs already written are whole", file=sys.stderr)
        return 130
    except Exception as err:  # a bug, not the user's input: say so in one line, exit 3
        return unexpected(err, args)


def unexpected(err: Exception, args: argparse.Namespace) -> int:
    """Report an unexpected error in one line naming what was being run (with the traceback
    under --debug); the exit status is EXIT_UNEXPECTED."""
    if getattr(args, "debug", False):
        traceback.print_exception(type(err), err, err.__traceback__, file=sys.stderr)
    what = getattr(args, "scenario", None)
    if isinstance(what, list):
        what = " ".join(what)
    where = f" while running {what or args.command}"
    print(
        f"collide2d: unexpected error{where}: {type(err).__name__}: {err} "
        "(this is a bug; --debug shows where)",
        file=sys.stderr,
    )
    return EXIT_UNEXPECTED


if __name__ == "__main__":
    sys.exit(main())
