"""Dask for sweeps and checks: the cluster to use, and running many tasks on it without losing one.

`connect(workers, scheduler)` is a context manager giving a `distributed.Client`: with a scheduler
address (`tcp://HOST:PORT`, a cluster started with `dask scheduler` and `dask worker`) it joins
that cluster; else it starts an embedded `LocalCluster` of `workers` processes (default one per
core) with one thread each, and closes it on the way out. `run_all(client, fn, items, ...)`
submits `fn(item)` for every item and hands each result (or the exception it raised) to
`on_result(i, value, error)` as runs finish, in any order. A task whose worker dies is run again
elsewhere by the scheduler (up to its `allowed-failures`), so every item gets one result; on
Ctrl-C (SIGINT, answered inside `connect` even by a process started with it ignored) the tasks
still pending are cancelled and `run_all` returns False.

Dask is the optional `dask` extra: `require_dask` raises `DaskMissing` with the install command.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
import threading
import uuid

from collide2d.runner.progress import Progress

INSTALL = 'pip install "collide2d[dask]"'
CONNECT_TIMEOUT_S = 30


class DaskMissing(Exception):
    """dask.distributed is not installed; str is the message with the install command."""


def require_dask(what: str = "this command") -> None:
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise DaskMissing(
            f"{what} runs on Dask, which is not installed; install it with: {INSTALL}"
        ) from None


@contextlib.contextmanager
def _sigint(handler):
    """SIGINT handled by `handler` while open (in the main thread, where Python runs signal
    handlers; elsewhere nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@contextlib.contextmanager
def connect(workers: int | None = None, scheduler: str | None = None):
    """A Client on the cluster at `scheduler`, or on an embedded LocalCluster of `workers`
    processes (default: one per core)."""
    require_dask()
    from distributed import Client, LocalCluster

    # Ctrl-C raises KeyboardInterrupt here, as `collide2d run` stops on it: also when the process
    # started with SIGINT ignored, as a shell starts a job in the background (`collide2d sweep
    # ... &`; Python would leave it ignored, and a `kill -INT` would go unanswered)
    with _sigint(signal.default_int_handler):
        if scheduler:
            with Client(scheduler, timeout=CONNECT_TIMEOUT_S) as client:
                yield client
            return
        # worker processes start with SIGINT ignored (they inherit it): Ctrl-C on a terminal
        # reaches every process of the group, and only this one should act on it (cancel,
        # write, close the cluster) instead of each worker printing a traceback as it dies
        with _sigint(signal.SIG_IGN):
            cluster = LocalCluster(
                n_workers=workers or os.cpu_count() or 1,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # the HTTP server on a free port: 8787 may be taken
                silence_logs=logging.CRITICAL,  # shutdown races log tracebacks; rows tell failures
            )
        try:
            with Client(cluster) as client:
                yield client
        finally:
            cluster.close()


def progress_for(total: int, label: str, quiet: bool) -> Progress | None:
    """A progress bar of runs (done/total, rate and time left) on stderr when it is a terminal and
    not quiet, else None."""
    if quiet or not sys.stderr.isatty():
        return None
    return Progress(total, label, unit=" runs")


def run_all(client, fn, items, on_result, *, progress=None, label="collide2d", sizes=None) -> bool:
    """Run fn(item) for every item on the cluster; on_result(i, value, error) for each as it
    finishes. True when every item got its result, False when cancelled by Ctrl-C. `progress`
    counts items, or `sizes[i]` for item i (runs in a batch)."""
    from distributed import as_completed

    token = uuid.uuid4().hex[:12]
    futures = [
        client.submit(fn, item, key=f"{label}-{token}-{i}", pure=False)
        for i, item in enumerate(items)
    ]
    index = {f.key: i for i, f in enumerate(futures)}
    done = 0
    try:
        for future in as_completed(futures):
            i = index[future.key]
            try:
                value, error = future.result(), None
            except Exception as exc:  # a task that failed, or one that killed its workers
                value, error = None, exc
            on_result(i, value, error)
            future.release()
            done += sizes[i] if sizes is not None else 1
            if progress is not None:
                progress.update(done)
    except KeyboardInterrupt:
        client.cancel(futures)
        if progress is not None:
            progress.close()
        return False
    if progress is not None:
        progress.close()
    return True
