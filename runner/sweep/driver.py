"""A sweep's runs on a Dask cluster: each run's figures and final positions, whatever the order.

`run_sweep(client, runs)` submits the runs in batches (`batch_size`: about eight tasks per worker
thread, so that a run of a few milliseconds does not pay the scheduler's few milliseconds per
task, while the work stays spread), each task `runs.run_batch` on the batch's loaded scenarios,
and collects what comes back by run index, so each row exists once however many times a task was
run (a task whose worker died is run again by the scheduler). A run that raised (a bug) gives a
row with status `error` and the exception in its note; a task that kept killing its workers gives
such a row for each of its runs. Ctrl-C cancels what is still pending and returns the runs
finished so far with `complete` False.
"""

from __future__ import annotations

import math
import time

from collide2d.runner.sweep import cluster
from collide2d.runner.sweep.runs import error_figures, run_batch

TASKS_PER_THREAD = 8
MAX_BATCH = 32  # runs in one task


def batch_size(runs: int, threads: int) -> int:
    """Runs per task: about TASKS_PER_THREAD tasks per worker thread, 1 to MAX_BATCH runs each."""
    return max(1, min(MAX_BATCH, math.ceil(runs / (max(threads, 1) * TASKS_PER_THREAD))))


def run_sweep(client, runs, *, progress=None, on_row=None, batch=None) -> tuple[dict, dict, bool]:
    """(figures by run index, final positions by run index, complete)."""
    if batch is None:
        batch = batch_size(len(runs), sum(client.nthreads().values()))
    batches = [runs[k : k + batch] for k in range(0, len(runs), batch)]
    figures: dict[int, dict] = {}
    positions: dict = {}
    started = time.time()

    def take(i: int, value, error) -> None:
        if error is not None:  # a worker's death says why (runs.error_figures)
            value = [(error_figures(error, since=started), None)] * len(batches[i])
        for run, (row, pos) in zip(batches[i], value, strict=True):
            figures[run.index], positions[run.index] = row, pos
            if on_row is not None:
                on_row(run, row)

    complete = cluster.run_all(
        client,
        run_batch,
        [[r.scenario for r in b] for b in batches],
        take,
        progress=progress,
        label="collide2d-sweep",
        sizes=[len(b) for b in batches],
    )
    return figures, positions, complete
