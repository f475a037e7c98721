"""The `sweep` subcommand: its arguments, and the run that builds the matrix, runs it, writes it.

`register` adds the subcommand without loading Dask; `cmd_sweep` reads the matrix (scenario files
and `--set`/`--seeds`, or one sweep file), checks every combination of settings before anything
runs (`plan.check`), runs them on the cluster (`--scheduler`, else an embedded LocalCluster of
`--workers` processes), each run sent once its seed is checked (`driver`, `seedcheck`: a refused
one stops the sweep, bad input), and writes OUT/sweep/ whole (`folder`; OUT is `--out`, else the
project's `out` setting, else `out`). Exit status: 0 done, 2 bad input (nothing written), Dask
not installed, a scheduler that does not answer or OUT/sweep taken by another sweep, 3 when a run
failed unexpectedly (its row says so), 130 when cancelled by Ctrl-C (the rows done are written,
marked incomplete). The line `sweep: N runs on ...` comes once the cluster is up; a Ctrl-C while
it starts goes unseen (runner.sweep.cluster). Each run done prints a line on stdout (`finished`),
in the order they finish; `--quiet` prints none.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from collide2d.runner import interrupt
from collide2d.runner.command.exitcodes import EXIT_BAD_INPUT, EXIT_OK, EXIT_UNEXPECTED
from collide2d.runner.output import escape
from collide2d.runner.output.progress import say

EXIT_CANCELLED = 130
REPORT_DIR = "sweep"


# An embedded cluster's workers are processes of this machine, each loading its own kernels: at
# most this many per core (more is a typo, or a cluster to start with `dask worker` instead).
LOCAL_WORKERS_PER_CORE = 8


def local_workers(text: str) -> int:
    """argparse type of --workers: a whole number from 1 to LOCAL_WORKERS_PER_CORE x the cores."""
    from collide2d.runner.command.options import positive_int

    value = positive_int(text)
    cores = os.cpu_count() or 1
    most = LOCAL_WORKERS_PER_CORE * cores
    if value > most:
        raise argparse.ArgumentTypeError(
            f"{value:,} worker processes on a machine of {cores} cores (at most {most}); for "
            "more, start a cluster with `dask scheduler` and `dask worker` and name it with "
            "--scheduler"
        )
    return value


def add_cluster_arguments(parser: argparse.ArgumentParser) -> None:
    """--workers N | --scheduler ADDRESS (also on `check`)."""
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=local_workers,
        metavar="N",
        help="run on an embedded Dask cluster of N processes (default: one per core)",
    )
    from collide2d.runner.sweep.cluster import scheduler_address

    where.add_argument(
        "--scheduler",
        type=scheduler_address,
        metavar="ADDRESS",
        help="run on the Dask cluster whose scheduler is at ADDRESS (tcp://HOST:PORT), started "
        "with `dask scheduler` and `dask worker`",
    )


def register(subparsers) -> None:
    """Add the `sweep` subcommand to an argparse subparsers object."""
    from collide2d.runner.command.options import add_limit_arguments

    p = subparsers.add_parser(
        "sweep",
        help="run scenarios over a matrix of settings and seeds on Dask; a table of results",
        description="Run every combination of the --set values and --seeds for each scenario "
        "(or the matrix of one sweep file) on a Dask cluster, and write OUT/sweep/results.csv "
        "(one row per run, sorted by its parameters), results.md and, with the plot extra and "
        "the exact model in the sweep, runtime_vs_error.png.",
    )
    p.add_argument(
        "scenarios", nargs="+", metavar="SCENARIO", help="scenario files, or one sweep file"
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        dest="sets",
        metavar="KEY=V1,V2",
        help="sweep KEY over these values (repeat): model, fps, ticks, substeps, geometry or a "
        "dotted scenario key such as world.width or generate.0.count",
    )
    p.add_argument("--seeds", metavar="A-B", help="sweep every generate block's seed over A..B")
    add_cluster_arguments(p)
    p.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default: the project's [tool.collide2d] out, else out)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress, no summary")
    add_limit_arguments(p)
    p.set_defaults(func=cmd_sweep)


def matrix_from_args(args):
    """(scenario paths, axes, seeds) from the command line (and a sweep file)."""
    from collide2d.runner.command.options import limits_from_args
    from collide2d.runner.sweep import matrix, sweepfile

    limits = limits_from_args(args)
    paths, axes, seeds = list(args.scenarios), [], None
    files = [p for p in paths if Path(p).is_file() and sweepfile.is_sweep_file(p, limits)]
    if files:
        if len(paths) > 1:
            raise matrix.SweepError(f"give one sweep file on its own ({files[0]} is one)")
        paths, axes, seeds = sweepfile.read(files[0], limits)
    given = [matrix.parse_set(s, limits) for s in args.sets]
    axes = [a for a in axes if a.key not in {g.key for g in given}] + given
    if args.seeds is not None:
        seeds = matrix.parse_seeds(args.seeds)
    for path in paths:
        if not Path(path).is_file():
            raise matrix.SweepError(f"{path}: no such scenario file")
    return paths, axes, seeds, limits


def finished(total: int, keys: list[str], quiet: bool):
    """`on_row` for the driver: a line on stdout for each run done, above the bar (not quiet):
    `sweep: [3/8] NAME model=stepped seed=2: ok, 12 pair events, 0.123s`."""
    if quiet:
        return None
    count = {"done": 0}

    def told(run, row: dict) -> None:
        count["done"] += 1
        params = run.params
        shown = " ".join(f"{k}={params[k]}" for k in [*keys, "seed"] if k in params)
        what = escape.one_line(f"{params['scenario']} {shown}".strip())
        if row["status"] == "ok":
            pairs = f"{row['pair_events']:,} pair event{'' if row['pair_events'] == 1 else 's'}"
            how = f"ok, {pairs}, {row['run_time_s']:.3f}s"
        else:
            how = f"{row['status']}: {escape.one_line(row['note'])}"
        say(f"sweep: [{count['done']}/{total}] {what}: {how}", sys.stdout)

    return told


def cmd_sweep(args: argparse.Namespace) -> int:
    from collide2d.runner.command import settings
    from collide2d.runner.sweep import cluster, driver, folder, matrix, plan, results

    project = settings.find()
    out_root = args.out or (project.folder("out") if project.file else "out")

    def checking(total: int):  # the combinations of settings, each loaded in full
        return cluster.progress_for(total, "checking", args.quiet, unit=" combinations")

    try:
        cluster.require_dask("collide2d sweep")
        paths, axes, seeds, limits = matrix_from_args(args)
        folder.check_replaceable(out_root)
        runs = plan.check(paths, axes, seeds, limits, progress=checking)
        # the bar from the start: starting the cluster and compiling the kernels take a while
        progress = cluster.progress_for(len(runs), "sweep", args.quiet)
        try:
            with cluster.connect(args.workers, args.scheduler) as client:
                with folder.staged(out_root) as stage:
                    if not args.quiet:  # the cluster is up: from here Ctrl-C writes the rows done
                        where = args.scheduler or f"{args.workers or os.cpu_count()} local workers"
                        say(f"sweep: {len(runs)} runs on {where}")
                    done = finished(len(runs), [a.key for a in axes], args.quiet)
                    table, complete = driver.run_sweep(
                        client, runs, progress=progress, on_row=done
                    )
                    written = results.write(stage, table, complete)
                if not complete:  # said before the cluster closes, which may take seconds
                    interrupt.told(  # that Ctrl-C does not wait for (runner.interrupt)
                        f"sweep: cancelled; {table.done} of {len(runs)} runs written, marked "
                        f"incomplete -> {Path(out_root) / folder.NAME}"
                    )
        finally:
            if progress is not None:
                progress.close()
    except (
        cluster.DaskMissing,
        cluster.SchedulerUnreachable,
        matrix.SweepError,
        folder.FolderRefused,
    ) as exc:
        print(f"collide2d: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    target = Path(out_root) / folder.NAME
    if not complete:
        return EXIT_CANCELLED
    failed = [r for r in table.rows() if r["status"] == "error"]
    for row in failed:
        print(f"collide2d: run failed: {row['scenario']}: {row['note']}", file=sys.stderr)
    if not args.quiet:
        stopped = table.count("stopped")
        said = f", {stopped} stopped by their model" if stopped else ""
        said += f", {len(failed)} failed" if failed else ""
        print(f"sweep: {table.done} runs{said} -> {target} ({', '.join(written)})")
    return EXIT_UNEXPECTED if failed else EXIT_OK
