"""The `stress` subcommand: its arguments, and the run that drives scenes, cases and report.

`register` adds the subcommand without loading the stress modules (numba kernels and scenes);
`cmd_stress` loads them when `collide2d stress` runs. Exit status: 0 every invariant held, 1 one
broke, 2 bad input (an unknown scene, a report folder that is a symbolic link).
"""

from __future__ import annotations

import argparse
import sys
import time

from collide2d.engine.models import MODEL_NAMES
from collide2d.runner.command.exitcodes import EXIT_BAD_INPUT, EXIT_DIFFERENCE, EXIT_OK


def cmd_stress(args: argparse.Namespace) -> int:
    from collide2d.runner.output import files
    from collide2d.runner.stress.cases import VERDICT_FAIL, run_suite
    from collide2d.runner.stress.falling import every_scene
    from collide2d.runner.stress.report import (
        HEADER,
        line,
        report_dir,
        report_json,
        report_markdown,
    )

    try:
        target = report_dir(args.out)
    except ValueError as exc:
        print(f"collide2d stress: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    known = [s.name for s in every_scene(True)]
    unknown = [s for s in args.scene or () if s not in known]
    if unknown:
        print(
            f"collide2d stress: error: unknown scene {unknown[0]!r}; expected one of "
            f"{', '.join(known)}",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    target.mkdir(parents=True, exist_ok=True)
    on_case = None
    if not args.quiet:
        print(HEADER)

        def on_case(result):
            print(line(result))

    began = time.perf_counter()
    results = run_suite(args.quick, args.scene or (), args.model or (), on_case)
    total = time.perf_counter() - began
    files.atomic_write_text(target / "report.md", report_markdown(results, args.quick, total))
    files.write_json(target / "report.json", report_json(results, args.quick, total))
    broken = [r for r in results if r.verdict == VERDICT_FAIL]
    for r in broken:
        for p in r.problems:
            print(f"{r.scene} / {r.model}: {p}", file=sys.stderr)
    if not args.quiet:
        print(
            f"stress: {len(results)} cases, {len(broken)} failed, in {total:.1f}s -> "
            f"{target / 'report.md'}"
        )
    return EXIT_DIFFERENCE if broken else EXIT_OK


def register(subparsers) -> None:
    """Add the `stress` subcommand to an argparse subparsers object."""
    p = subparsers.add_parser(
        "stress",
        help="run hostile scenes under every model and check invariants every tick",
        description="Run the stress scenes under every model where they apply, checking every "
        "tick: finite state, objects inside the world, energy and momentum within the model's "
        "bound, no overlap after an exact tick, a clear stop for runaways, the same bytes twice. "
        "Writes OUT/stress/report.md and report.json; exit 1 when an invariant breaks.",
    )
    p.add_argument("--quick", action="store_true", help="shorter, smaller scenes (for CI)")
    p.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    p.add_argument("--scene", action="append", metavar="NAME", help="run only this scene (repeat)")
    p.add_argument(
        "--model", action="append", choices=MODEL_NAMES, help="run only this model (repeat)"
    )
    p.add_argument("--quiet", action="store_true", help="print only problems")
    p.set_defaults(func=cmd_stress)
