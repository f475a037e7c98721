"""The `bench` subcommand: its arguments, and the run that drives the parts and writes the report.

`register` adds the subcommand without loading the parts; `cmd_bench` loads them when
`collide2d bench` runs, runs the parts asked for (default: scaling, error, skips, targets) and
writes OUT/bench/bench.csv, bench.md and the plots. The parts that read scenario files (FILE_PARTS)
read them from `--scenarios`, else from the project's scenarios folder (runner.command.settings),
else, when that folder lacks the benchmark scenarios (a user's project, an installed wheel), from
the copies the package ships (runner.bench.scenes). On a terminal a bar counts the parts done from
the start, the progress lines printed above it. Exit status: 0 when every target of the headline
is met, 1 when one is missed (each named on stderr), 2 on bad input (a part asked for whose
scenarios are missing from the folder `--scenarios` names, a report folder that is a symbolic
link).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from collide2d.engine import models
from collide2d.runner.command.exitcodes import EXIT_BAD_INPUT, EXIT_DIFFERENCE, EXIT_OK

PARTS = ("scaling", "error", "peers", "skips", "targets", "paper", "exact", "raster")
PARTS += ("stages", "load", "jit", "gravity")  # bench/stages.py, load.py, targets.py, gravity/
DEFAULT_PARTS = ("scaling", "error", "skips", "targets")
FILE_PARTS = ("error", "skips", "targets", "paper", "raster", "jit")  # read scenarios/*.yaml
REPORT_DIR = "bench"


def cmd_bench(args: argparse.Namespace) -> int:
    from collide2d.runner import lanes
    from collide2d.runner.bench import plots, report, scaling, scenes, timing
    from collide2d.runner.output import files

    lanes.set_mode("on")  # every run the bench times is compiled (runner.lanes)
    parts = tuple(dict.fromkeys(args.part)) if args.part else DEFAULT_PARTS
    if args.peers and "peers" not in parts:
        parts += ("peers",)
    quick = args.quick
    ns = args.n or list(scaling.QUICK_N if quick else scaling.SCALING_N)
    models_ = args.model or list(models.MODEL_NAMES)
    in_process = args.in_process or quick
    folder = Path(args.scenarios) if args.scenarios else project_scenarios()
    missing = [n for n in scenes.NEEDED_SCENARIOS if not (folder / f"{n}.yaml").is_file()]
    if missing and not args.scenarios:  # a user's project, an installed wheel: the copies shipped
        folder, missing = scenes.PACKAGED_SCENARIOS, []
    if missing and any(p in FILE_PARTS for p in parts):
        print(
            f"collide2d bench: error: {folder} lacks {missing[0]}.yaml; point "
            "--scenarios at a folder of the benchmark scenarios",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    target = Path(args.out) / REPORT_DIR
    if target.is_symlink():
        print(f"collide2d bench: error: {target} is a symbolic link", file=sys.stderr)
        return EXIT_BAD_INPUT
    echo = timing.Echo(args.quiet, parts)
    try:
        rows, seconds = _run_parts(args, parts, ns, models_, quick, in_process, folder, echo)
    finally:
        echo.close()
    files.make_folder(target)
    args_line = "collide2d bench " + " ".join(sys.argv[2:]) if len(sys.argv) > 1 else "bench"
    files.atomic_write_text(target / "bench.csv", report.csv_text(rows))
    files.atomic_write_text(target / "bench.md", report.markdown(rows, args_line, seconds))
    written = ["bench.csv", "bench.md"] + plots.plots(rows, target)
    headline = report.headline(rows)
    if not args.quiet:
        for what, figure, goal, met in headline:
            goal = f"  (target {goal}) {met}" if goal else ""
            print(f"{figure:>14}  {what}{goal}")
        print(f"bench: {len(rows)} rows in {seconds:.1f}s -> {target} ({', '.join(written)})")
    missed = report.missed(headline)
    for what, figure, goal in missed:
        print(f"collide2d bench: target missed: {what}: {figure} (target {goal})", file=sys.stderr)
    return EXIT_DIFFERENCE if missed else EXIT_OK


def _run_parts(args, parts, ns, models_, quick, in_process, folder, echo) -> tuple[list, float]:
    """(the rows of the parts, seconds they took)."""
    from collide2d.runner.bench import (
        error,
        exact,
        gravity,
        paper,
        peers,
        raster,
        scaling,
        scenes,
        skips,
        targets,
    )

    began = time.perf_counter()
    rows: list[dict] = []
    # pymunk is timed in turn with the stepped model's runs, when both are asked for (peers.py)
    peer = peers.timer(quick) if "peers" in parts and peers.pymunk_available() else None
    if "scaling" in parts:
        echo.part("scaling")
        rows += scaling.scaling(models_, ns, quick, in_process, echo, peer)
    if "peers" in parts:
        echo.part("peers")
        if peer is not None:
            stepped = [r for r in rows if r["part"] == "scaling" and r["model"] == "stepped"]
            missing = [n for n in ns if n not in {r["n"] for r in stepped}]
            if missing:
                extra = scaling.scaling(["stepped"], missing, quick, in_process, echo, peer)
                stepped += extra
                rows += extra
            ours = {r["n"]: r["steps_per_s"] for r in stepped}
            timed = {r["n"]: (r["peer_steps_per_s"], r["peer_how"]) for r in stepped}
            rows += peers.peers(ns, ours, timed, echo)
        else:
            print(
                "collide2d bench: pymunk is not installed (pip install 'collide2d[bench]'); "
                "no peers",
                file=sys.stderr,
            )
    if "error" in parts:
        echo.part("error")
        rows += error.error_ladder(scenes.BENCH_SCENARIOS, models_, quick, echo, folder)
    if "skips" in parts:
        echo.part("skips")
        rows += skips.skips(quick, echo, folder)
    if "targets" in parts:
        echo.part("targets")
        rows += targets.targets(quick, echo, folder)
    if "paper" in parts:
        echo.part("paper")
        rows += paper.paper(quick, echo, folder)
    if "exact" in parts:
        echo.part("exact")
        rows += exact.exact(quick, echo)
    if "raster" in parts:
        echo.part("raster")
        rows += raster.raster(quick, echo, folder)
    if "stages" in parts:
        echo.part("stages")
        from collide2d.runner.bench import stages

        rows += stages.stages(quick, echo, args.n)
    if "load" in parts:
        echo.part("load")
        from collide2d.runner.bench import load

        rows += load.load(quick, echo)
    if "jit" in parts:
        echo.part("jit")
        rows += targets.cold_start(quick, echo, folder)
    if "gravity" in parts:
        echo.part("gravity")
        rows += gravity.part(quick, echo)
    return rows, time.perf_counter() - began


def project_scenarios() -> Path:
    """The scenarios folder of the project here (runner.command.settings: its [tool.collide2d]
    table, else the nearest scenarios/ folder up from here)."""
    from collide2d.runner.command import settings

    return settings.find().folder("scenarios")


def register(subparsers) -> None:
    """Add the `bench` subcommand to an argparse subparsers object."""
    p = subparsers.add_parser(
        "bench",
        help="run time against error; scaling; pymunk as a peer; what the skips save",
        description="Benchmark the models: the standard scene at several N (steps/s through "
        "`collide2d run`, events/s, time per stage), the benchmark scenarios at a ladder of fps "
        "and substeps against the exact model (run time against error, Pareto plot), what each "
        "skip saves, and the section IV targets; with --peers, pymunk on the same scene; with "
        "--part, also the paper model three ways, the exact model's events/s, the drawing and "
        "writing of frames, (jit) each --jit mode's wall time from an empty kernel cache, and "
        "(gravity) a settling pile against pymunk, the stepped and exact models and pymunk "
        "against the closed forms, and the exact model's events/s under gravity. "
        "Writes OUT/bench/bench.csv, bench.md and, with matplotlib, "
        "scaling.png, runtime_vs_error.png and gravity_runtime_vs_error.png.",
    )
    p.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    p.add_argument("--quick", action="store_true", help="small and short everything (seconds)")
    p.add_argument("--peers", action="store_true", help="also time pymunk (the `bench` extra)")
    p.add_argument(
        "--part",
        action="append",
        choices=PARTS,
        help="run only this part (repeat; default: scaling, error, skips, targets)",
    )
    p.add_argument(
        "--n", action="append", type=_positive, metavar="N", help="scaling at this N (repeat)"
    )
    p.add_argument(
        "--model",
        action="append",
        type=_model,
        metavar="MODEL",
        help=f"only this model (repeat): {', '.join(models.MODEL_NAMES)} or a plugin's",
    )
    p.add_argument(
        "--in-process",
        action="store_true",
        help="time runs through runner.run.drive in this process instead of `collide2d run`",
    )
    p.add_argument(
        "--scenarios",
        metavar="DIR",
        help="folder of the benchmark scenarios (default: the project's scenarios/)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress, no summary")
    p.set_defaults(func=cmd_bench)


def _model(text: str) -> str:
    """A model's name: a built-in one or a registered plugin's (engine.models)."""
    if text not in models.names_for(text):
        raise argparse.ArgumentTypeError(
            f"unknown model {text!r}; expected one of {', '.join(models.names())}"
        )
    return text


def _positive(text: str) -> int:
    from collide2d.runner.command.options import positive_int

    return positive_int(text)
