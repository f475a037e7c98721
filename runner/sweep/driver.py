"""A sweep's runs on a Dask cluster: each run's figures, kept by run number, whatever the order.

`run_sweep(client, plan)` sends the plan's runs in their sorted order (`plan.Plan.runs`) in batches
(`batch_size`: about eight tasks per worker thread, so that a run of a few milliseconds does not
pay the scheduler's few milliseconds per task, while the work stays spread), each task
`worker.run_batch` on the batch's runs as (their combination's scenario, their seed), and at most
WINDOW_PER_THREAD tasks per worker thread in flight: the scenarios are loaded as their batch is
sent (`plan.Plan.base`) and dropped when it is done, so memory does not grow with the runs. A batch
is sent once its runs' seeds are checked (`runner.sweep.seedcheck`, in the background from the
start, ahead of the runs); a run refused stops the sweep: the tasks in flight are cancelled and
its located error is raised (bad input, as if refused before any run). What
comes back is kept by run number in a `results.Table`, so each row exists once however many times
a task was run (a task whose worker died is run again by the scheduler). A run that raised (a bug)
gives a row with status `error` and the exception in its note; a task that kept killing its
workers gives such a row for each of its runs. Ctrl-C cancels what is still pending and returns
the runs finished so far with `complete` False.
"""

from __future__ import annotations

import itertools
import math
import time

from collide2d.runner.sweep import cluster
from collide2d.runner.sweep.results import Table
from collide2d.runner.sweep.seedcheck import SeedChecks
from collide2d.runner.sweep.worker import error_figures, run_batch

TASKS_PER_THREAD = 8
MAX_BATCH = 32  # runs in one task
WINDOW_PER_THREAD = 4  # tasks in flight per worker thread


def batch_size(runs: int, threads: int) -> int:
    """Runs per task: about TASKS_PER_THREAD tasks per worker thread, 1 to MAX_BATCH runs each."""
    return max(1, min(MAX_BATCH, math.ceil(runs / (max(threads, 1) * TASKS_PER_THREAD))))


def run_sweep(client, plan, *, progress=None, on_row=None, batch=None) -> tuple[Table, bool]:
    """(the table of the runs done, complete). A Ctrl-C before the first task is sent (asking the
    cluster its threads, starting the seeds' checks) cancels the sweep as one later does: no run
    done, `complete` False, the table written as such."""
    table = Table(plan)
    try:
        complete = _run_sweep(client, plan, table, progress, on_row, batch)
    except KeyboardInterrupt:
        complete = False
    table.finish()
    return table, complete


def _run_sweep(client, plan, table, progress, on_row, batch) -> bool:
    threads = sum(client.nthreads().values())
    if batch is None:
        batch = batch_size(len(plan), threads)
    sent: dict[int, list] = {}  # task number -> its runs, until its result is taken
    started = time.time()

    def batches(checks: SeedChecks):
        runs = plan.runs()
        for i in itertools.count():
            chunk = list(itertools.islice(runs, batch))
            if not chunk:
                return
            checks.wait(chunk[-1].index)  # raises a refusal found at any run
            sent[i] = chunk
            yield [(plan.base(r.combo), r.seed) for r in chunk]

    def take(i: int, value, error) -> None:
        runs = sent.pop(i)
        if error is not None:  # a worker's death says why (worker.error_figures)
            value = [(error_figures(error, since=started), None)] * len(runs)
        for run, (row, pos) in zip(runs, value, strict=True):
            table.take(run, row, pos)
            if on_row is not None:
                on_row(run, row)

    with SeedChecks(plan) as checks:
        return cluster.run_all(
            client,
            run_batch,
            batches(checks),
            take,
            progress=progress,
            label="collide2d-sweep",
            size=len,
            window=max(2, WINDOW_PER_THREAD * threads),
        )
