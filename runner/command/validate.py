"""The `validate` and `schema` commands: check scenario files without running them; the schema.

`register(subparsers)` adds both to an argparse subparsers object, each with `func(args) -> int`
(the exit status) as its default. `validate [SCENARIO...]` reads every file (with none, every
scenario file of the project's scenarios folder, as `check` runs them) with the same limits and
overrides a run would use and prints `PATH: ok (N objects, model M, T ticks)` on stdout for each
good file and the located errors `PATH:LINE:COL: error: MESSAGE` on stderr for each bad one, every
file read whatever the others hold; the exit status is 2 when any file is bad, else 0. `schema`
prints the scenario format's JSON Schema
(draft 2020-12, indent 2) on stdout.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

from collide2d.runner.command.exitcodes import EXIT_BAD_INPUT, EXIT_OK
from collide2d.runner.command.options import (
    add_limit_arguments,
    add_override_arguments,
    limits_from_args,
    overrides_from_args,
)
from collide2d.runner.scenario.load import ScenarioError, load
from collide2d.runner.scenario.schema import json_schema


def run_validate(args: argparse.Namespace) -> int:
    """Check every file of args.scenarios; print one line per file; 2 if any is bad, else 0."""
    from collide2d.runner.command import settings
    from collide2d.runner.command.main import plural

    project = settings.find()
    limits = limits_from_args(args, project)
    overrides = overrides_from_args(args)
    paths = args.scenarios or project_files(project)
    if not paths:
        folder = shown_path(project.scenarios)
        print(f"collide2d validate: error: no scenario files in {folder}", file=sys.stderr)
        return EXIT_BAD_INPUT
    status = EXIT_OK
    for path in paths:
        try:
            sc = load(path, overrides=overrides, limits=limits, defaults=project.model_defaults())
        except ScenarioError as err:
            print(str(err), file=sys.stderr)
            status = EXIT_BAD_INPUT
            continue
        print(
            f"{path}: ok ({plural(sc.bodies.n, 'object')}, model {sc.model}, "
            f"{plural(sc.ticks, 'tick')})"
        )
    return status


# The files a project's scenarios folder holds as scenarios, as `check` lists them.
SCENARIO_SUFFIXES = (".yaml", ".yml")


def project_files(project) -> list[str]:
    """The scenario files of the project's scenarios folder, sorted by name, as shown."""
    folder = project.scenarios
    if not folder.is_dir():
        return []
    files = [p for p in folder.iterdir() if p.suffix in SCENARIO_SUFFIXES and p.is_file()]
    return [shown_path(p) for p in sorted(files, key=lambda p: p.name)]


def shown_path(path) -> str:
    """`path` relative to the current folder when inside it, else as it is."""
    shown = os.path.relpath(path)
    return str(path) if shown.startswith("..") else shown


def run_schema(args: argparse.Namespace) -> int:
    """Print the JSON Schema of the scenario format."""
    print(json.dumps(json_schema(), indent=2))
    return EXIT_OK


def register(subparsers) -> None:
    """Add the `validate` and `schema` subcommands to an argparse subparsers object."""
    p = subparsers.add_parser(
        "validate",
        help="check scenario files without running them",
        description="Check scenario files (with none, the project's scenarios folder); print one "
        "line per file; exit 2 if any is bad.",
    )
    p.add_argument(
        "scenarios",
        nargs="*",
        metavar="SCENARIO",
        help="scenario YAML files (default: every one in the project's scenarios folder)",
    )
    add_override_arguments(p)
    add_limit_arguments(p)
    p.set_defaults(func=run_validate)

    s = subparsers.add_parser(
        "schema",
        help="print the JSON Schema of the scenario format",
        description="Print the JSON Schema (draft 2020-12) of the scenario format.",
    )
    s.set_defaults(func=run_schema)
