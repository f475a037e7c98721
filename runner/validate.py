"""The `validate` and `schema` commands: check scenario files without running them; the schema.

`register(subparsers)` adds both to an argparse subparsers object, each with `func(args) -> int`
(the exit status) as its default. `validate SCENARIO...` reads every file with the same limits and
overrides a run would use and prints `PATH: ok (N objects, model M, T ticks)` on stdout for each
good file and the located error `PATH:LINE:COL: error: MESSAGE` on stderr for each bad one; the
exit status is 2 when any file is bad, else 0. `schema` prints the scenario format's JSON Schema
(draft 2020-12, indent 2) on stdout.

The option helpers (`add_limit_arguments` / `limits_from_args`, `add_override_arguments` /
`overrides_from_args`) let other commands take the same options the same way.
"""

from __future__ import annotations

import argparse
import json
import sys

from engine.models import MODEL_NAMES
from runner.scenario import Limits, ScenarioError, json_schema, load

EXIT_OK = 0
EXIT_BAD_INPUT = 2

_LIMIT_OPTIONS = (
    ("--max-objects", "max_objects", "objects in a scenario"),
    ("--max-ticks", "max_ticks", "ticks of a run"),
    ("--max-side", "max_side", "pixels per world side"),
    ("--max-frames", "max_frames", "frame numbers one `frames` entry may ask for"),
)


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be at least 1")
    return value


def add_limit_arguments(parser: argparse.ArgumentParser) -> None:
    """Add --max-objects, --max-ticks, --max-side and --max-frames (defaults from Limits)."""
    defaults = Limits()
    for flag, field, what in _LIMIT_OPTIONS:
        parser.add_argument(
            flag,
            dest=field,
            type=_positive_int,
            default=getattr(defaults, field),
            metavar="N",
            help=f"largest number of {what} (default {getattr(defaults, field)})",
        )


def limits_from_args(args: argparse.Namespace) -> Limits:
    """The Limits asked for on the command line (defaults for options not present)."""
    given = {f: getattr(args, f) for _, f, _ in _LIMIT_OPTIONS if getattr(args, f, None)}
    return Limits(**given)


def add_override_arguments(parser: argparse.ArgumentParser) -> None:
    """Add --model, --fps and --ticks, which override the scenario file."""
    parser.add_argument("--model", choices=MODEL_NAMES, help="model to use instead of the file's")
    parser.add_argument(
        "--fps", type=int, metavar="F", help="ticks per second instead of the file's"
    )
    parser.add_argument("--ticks", type=int, metavar="N", help="ticks to run instead of the file's")


def overrides_from_args(args: argparse.Namespace) -> dict:
    """{"model", "fps", "ticks"} from the command line; None where not given."""
    return {key: getattr(args, key, None) for key in ("model", "fps", "ticks")}


def run_validate(args: argparse.Namespace) -> int:
    """Check every file of args.scenarios; print one line per file; 2 if any is bad, else 0."""
    limits = limits_from_args(args)
    overrides = overrides_from_args(args)
    status = EXIT_OK
    for path in args.scenarios:
        try:
            sc = load(path, overrides=overrides, limits=limits)
        except ScenarioError as err:
            print(str(err), file=sys.stderr)
            status = EXIT_BAD_INPUT
            continue
        print(f"{path}: ok ({sc.bodies.n} objects, model {sc.model}, {sc.ticks} ticks)")
    return status


def run_schema(args: argparse.Namespace) -> int:
    """Print the JSON Schema of the scenario format."""
    print(json.dumps(json_schema(), indent=2))
    return EXIT_OK


def register(subparsers) -> None:
    """Add the `validate` and `schema` subcommands to an argparse subparsers object."""
    p = subparsers.add_parser(
        "validate",
        help="check scenario files without running them",
        description="Check scenario files; print one line per file; exit 2 if any is bad.",
    )
    p.add_argument("scenarios", nargs="+", metavar="SCENARIO", help="scenario YAML files")
    add_override_arguments(p)
    add_limit_arguments(p)
    p.set_defaults(func=run_validate)

    s = subparsers.add_parser(
        "schema",
        help="print the JSON Schema of the scenario format",
        description="Print the JSON Schema (draft 2020-12) of the scenario format.",
    )
    s.set_defaults(func=run_schema)
