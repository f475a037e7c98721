"""`collide2d check --workers N | --scheduler ADDRESS`: a golden corpus run on a Dask cluster.

`cluster_runs(args, scenarios, run, usage)` returns None when neither option is given (the check
runs each scenario itself, as always). Otherwise it runs `run(scenario)` for every scenario on the
cluster (`runner.sweep.cluster`) and returns, in the scenarios' order, one callable per scenario
that gives its run's result or raises what the run raised; the check then compares each with its
golden locally, exactly as it compares a local run, so its output is the same. Dask missing, or
a scheduler that does not answer, is bad input (`usage`, the check's exception for it).
"""

from __future__ import annotations


def _outcome(value, error):
    def result():
        if error is not None:
            raise error
        return value

    return result


def cluster_runs(args, scenarios, run, usage):
    """None, or [callable giving scenario k's run result] (see the module docstring)."""
    workers, scheduler = getattr(args, "workers", None), getattr(args, "scheduler", None)
    if not workers and not scheduler:
        return None
    from collide2d.runner.sweep import cluster

    try:
        cluster.require_dask("collide2d check --workers/--scheduler")
    except cluster.DaskMissing as exc:
        raise usage(str(exc)) from None
    got: dict[int, tuple] = {}
    items = [scn for _path, scn in scenarios]
    progress = cluster.progress_for(len(items), "check", args.quiet)  # from the start
    try:
        with cluster.connect(workers, scheduler) as client:
            complete = cluster.run_all(
                client,
                run,
                items,
                lambda i, value, error: got.__setitem__(i, (value, error)),
                progress=progress,
                label="collide2d-check",
            )
    except cluster.SchedulerUnreachable as exc:
        raise usage(str(exc)) from None
    finally:
        if progress is not None:
            progress.close()
    if not complete:
        raise KeyboardInterrupt
    return [_outcome(*got[i]) for i in range(len(items))]
