"""A sweep's runs on a Dask cluster: each run's figures and final positions, whatever the order.

`run_sweep(client, runs)` submits one task per run (`runs.run_one` on the run's loaded scenario)
and collects what comes back by run index, so each row exists once however many times a task was
run (a task whose worker died is run again by the scheduler). A task that raised (a bug) or kept
killing its workers gives a row with status `error` and the exception in its note. Ctrl-C cancels
what is still pending and returns the runs finished so far with `complete` False.
"""

from __future__ import annotations

from collide2d.runner.sweep import cluster
from collide2d.runner.sweep.runs import STATUS_ERROR, run_one


def run_sweep(client, runs, *, progress=None, on_row=None) -> tuple[dict, dict, bool]:
    """(figures by run index, final positions by run index, complete)."""
    figures: dict[int, dict] = {}
    positions: dict = {}

    def take(i: int, value, error) -> None:
        run = runs[i]
        if error is not None:
            detail = " ".join(str(error).split())[:300]
            figures[run.index] = {
                "status": STATUS_ERROR,
                "note": f"{type(error).__name__}: {detail}",
            }
            positions[run.index] = None
        else:
            figures[run.index], positions[run.index] = value
        if on_row is not None:
            on_row(run, figures[run.index])

    complete = cluster.run_all(
        client,
        run_one,
        [r.scenario for r in runs],
        take,
        progress=progress,
        label="collide2d-sweep",
    )
    return figures, positions, complete
