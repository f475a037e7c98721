"""The `config` command: print a project's effective settings and where each came from.

`collide2d config [--root DIR] [--max-... N] [--max-events-per-tick N]` finds the project as every
command does (`runner.command.settings.find`, or `--root`), lays the command line's options over it,
and prints one line per setting: name, value, source (`command line`, the `pyproject.toml
[tool.collide2d]` table, or `default`). Model settings with no value in force are the scenario's
own, else the model's default.
"""

from __future__ import annotations

import argparse

from collide2d.runner.command.exitcodes import EXIT_OK


def register(subparsers) -> None:
    from collide2d.runner.command.options import add_cap_argument, add_limit_arguments

    p = subparsers.add_parser(
        "config",
        help="print the project's settings and where each comes from",
        description="Print the effective settings of the project here (its pyproject.toml "
        "[tool.collide2d] table): folders, limits and model defaults, each with its source. "
        "Precedence: command line, then scenario, then the table, then defaults.",
    )
    p.add_argument("--root", metavar="DIR", help="project folder (default: found upward)")
    add_limit_arguments(p, output=True)
    add_cap_argument(p)
    p.set_defaults(func=run_config)


def run_config(args: argparse.Namespace) -> int:
    from collide2d.runner.command import settings
    from collide2d.runner.scenario.limits import Limits

    project = settings.at(args.root) if args.root else settings.find()
    for key in Limits.__dataclass_fields__:
        project.override(f"limits.{key}", getattr(args, key, None))
    project.override("model.max_events_per_tick", args.max_events_per_tick)
    for line in project.lines():
        print(line)
    return EXIT_OK
