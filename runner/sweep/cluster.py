"""Dask for sweeps and checks: the cluster to use, and running many tasks on it without losing one.

`connect(workers, scheduler)` is a context manager giving a `distributed.Client`: with a scheduler
address (`tcp://HOST:PORT`, a cluster started with `dask scheduler` and `dask worker`) it joins
that cluster; else it starts an embedded `LocalCluster` of `workers` processes (default one per
core) with one thread each, and closes it on the way out. A scheduler that does not answer
within CONNECT_TIMEOUT_S is `SchedulerUnreachable`, naming its address (`scheduler_address`, the
type of `--scheduler`, refuses an address that is not one). `run_all(client, fn, items, ...)`
submits `fn(item)` for every item, a window of tasks at a time, and hands each result (or the
exception it raised) to `on_result(i, value, error)` as runs finish, in any order. A task whose
worker dies is run again elsewhere by the scheduler (up to its `allowed-failures`), so every item
gets one result; on Ctrl-C (SIGINT, answered inside `connect` even by a process started with it
ignored) the tasks still pending are cancelled and `run_all` returns False, and so they are when
reading `items` or `on_result` raises (a sweep's refused seed), before the exception goes on. A
worker that starts compiling kernels says so (an event on COMPILING_TOPIC), and this process gives
the compile notice then (runner.compiling.told), as a run on its own gives it.

Dask is the optional `dask` extra: `require_dask` raises `DaskMissing` with the install command.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import re
import signal
import sys
import threading
import uuid

from collide2d.runner.output.progress import Progress

INSTALL = 'pip install "collide2d[dask]"'
# Seconds a scheduler has to answer: a live one answers in milliseconds, and a typo should not
# keep the command waiting (Dask's own default is 30 s).
CONNECT_TIMEOUT_S = 3
MESSAGES_KEPT = 16  # messages a connection keeps for debugging (see `connect`)
COMPILING_TOPIC = "collide2d-compiling"  # a worker's event: it started compiling kernels
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")  # Dask's network protocols
_ADDRESS = re.compile(
    r"(?:(?P<scheme>[a-z]+)://)?"
    r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+)"  # a name, an IPv4 or a bracketed IPv6 address
    r":(?P<port>[0-9]{1,5})"
)


class DaskMissing(Exception):
    """dask.distributed is not installed; str is the message with the install command."""


class SchedulerUnreachable(Exception):
    """No Dask scheduler answered at the address given; str names it and says why."""


def scheduler_address(text: str) -> str:
    """argparse type of --scheduler: a Dask scheduler's address, `tcp://HOST:PORT` (or another
    of Dask's protocols, SCHEMES; `HOST:PORT` means tcp)."""
    m = _ADDRESS.fullmatch(text.strip())
    if m is None or (m["scheme"] is not None and m["scheme"] not in SCHEMES):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a scheduler address; expected tcp://HOST:PORT (as `dask scheduler` "
            f"prints it; also {', '.join(s + '://' for s in SCHEMES[1:])})"
        )
    port = int(m["port"])
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{text!r}: port {port} is not 1 to 65535")
    return text.strip()


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
    import dask
    from distributed import Client, LocalCluster

    # Dask keeps the last messages of each connection for debugging, tasks and their arguments
    # (a run's scenario) with them: a thousand by default, so memory would grow with the tasks
    with dask.config.set({"distributed.admin.low-level-log-length": MESSAGES_KEPT}):
        with _connected(Client, LocalCluster, workers, scheduler) as client:
            yield client


@contextlib.contextmanager
def _connected(Client, LocalCluster, workers, scheduler):
    # Ctrl-C raises KeyboardInterrupt here, as `collide2d run` stops on it: also when the process
    # started with SIGINT ignored, as a shell starts a job in the background (`collide2d sweep
    # ... &`; Python would leave it ignored, and a `kill -INT` would go unanswered)
    with _sigint(signal.default_int_handler):
        if scheduler:
            with _joined(Client, scheduler) as client:
                yield client
            return
        # worker processes start with SIGINT ignored (they inherit it): Ctrl-C on a terminal
        # reaches every process of the group, and only this one should act on it (cancel,
        # write, close the cluster) instead of each worker printing a traceback as it dies.
        # The disposition is the whole process's, so a Ctrl-C while they start (a second or
        # two) goes unseen here too; `sweep` says when the cluster is up. (Holding it back
        # with a signal mask instead does not work: processes spawned do not inherit a mask,
        # and native threads, OpenBLAS's, would take the signal and drop it.)
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


def _joined(Client, scheduler: str):
    """A Client on the scheduler at `scheduler`, or SchedulerUnreachable within about
    CONNECT_TIMEOUT_S (also when what answers there is no Dask scheduler)."""
    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT_S)
    except Exception as exc:  # a timeout, a refused or unknown host, a server that is not Dask
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise SchedulerUnreachable(
            f"no Dask scheduler answered at {scheduler} within {CONNECT_TIMEOUT_S} s ({detail}); "
            "start one with `dask scheduler`, or check the address"
        ) from None


def progress_for(total: int, label: str, quiet: bool, unit: str = " runs") -> Progress | None:
    """A progress bar of runs (done/total, rate and time left) on stderr when it is a terminal and
    not quiet, else None; drawn at once, its clock running while the first runs compile."""
    if quiet or not sys.stderr.isatty():
        return None
    return Progress(total, label, unit=unit, waiting=True)


def _tell_compiling() -> None:
    """Send COMPILING_TOPIC's event from the worker compiling (nothing outside a task: a cluster
    in this very process, whose first compilation may come on another thread)."""
    from distributed import get_worker

    try:
        worker = get_worker()
    except ValueError:
        return
    worker.log_event(COMPILING_TOPIC, "compiling")


def _telling(fn, item):
    """fn(item) in a worker, which says when it starts compiling kernels (COMPILING_TOPIC)."""
    from collide2d.runner import compiling

    compiling.relay(_tell_compiling)
    return fn(item)


def _heard(_event) -> None:
    from collide2d.runner import compiling

    compiling.told()


def run_all(
    client, fn, items, on_result, *, progress=None, label="collide2d", size=None, window=None
) -> bool:
    """Run fn(item) for every item on the cluster; on_result(i, value, error) for each as it
    finishes. True when every item got its result, False when cancelled by Ctrl-C. `items` may be
    an iterator: it is read as tasks are sent, at most `window` tasks in flight at a time (None:
    all at once), so what waits to be sent is never held. `progress` counts items, or
    `size(item)` each (runs in a batch)."""
    from distributed import as_completed

    token = uuid.uuid4().hex[:12]
    source = enumerate(items)
    pending: dict = {}  # key -> (index, size, future)
    finished = as_completed()

    def send() -> bool:
        for i, item in source:
            future = client.submit(_telling, fn, item, key=f"{label}-{token}-{i}", pure=False)
            pending[future.key] = (i, size(item) if size is not None else 1, future)
            finished.add(future)
            return True
        return False

    done = 0
    client.subscribe_topic(COMPILING_TOPIC, _heard)
    try:
        while send() and (window is None or len(pending) < window):
            pass
        for future in finished:
            i, count, _ = pending.pop(future.key)
            try:
                value, error = future.result(), None
            except Exception as exc:  # a task that failed, or one that killed its workers
                value, error = None, exc
            on_result(i, value, error)
            future.release()
            done += count
            if progress is not None:
                progress.update(done)
            send()
    except BaseException as exc:  # Ctrl-C, or what `items` or `on_result` raised
        client.cancel([f for _i, _n, f in pending.values()])
        if isinstance(exc, KeyboardInterrupt):
            return False
        raise
    finally:
        client.unsubscribe_topic(COMPILING_TOPIC)
        if progress is not None:
            progress.close()
    return True
