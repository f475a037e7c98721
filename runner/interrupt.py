"""Ctrl-C, answered within a second whatever the command is running (docs/command-line.md,
"Progress and Ctrl-C").

Ctrl-C (SIGINT) is answered in Python's main thread: a command raises KeyboardInterrupt there
(runner.command.main), a run stops at the end of its chunk of ticks or, inside its model's
`advance()`, at once (runner.run). Both wait for the main thread to run Python again, and some
work keeps it away for long: a compiled kernel running a long chunk of ticks, a model plugin's
`advance()` that keeps the KeyboardInterrupt to itself or sits in C, numba compiling a kernel, a
Dask cluster closing. So the `collide2d` command calls `watch()` as it starts: a watchdog thread
hears each SIGINT as it arrives (Python's C-level handler writes its number to the
`signal.set_wakeup_fd` pipe whatever the main thread runs, and the kernels run without the GIL,
engine.jit) and, when the command is still running GRACE_S later, ends the process itself; a
command that has taken the Ctrl-C in hand and is writing what it has (`answering`: a run whose
chunk has returned) is given up to ANSWER_S. The watchdog waits for a folder swap under way to
finish (runner.output.swap), removes the staging folders and temporary files of the process and
the lock files it holds (runner.output.folder.abandon), so that every output folder is as an
interrupted run leaves it: the previous run whole, nothing half written; prints one line saying
so (none when the command has printed its own, `told`); and exits with status 130 at once
(`os._exit`: no finalizer runs, no thread is waited for). A command that answered Ctrl-C itself
ends the same way once its exit handlers have run, without the interpreter's teardown (a process
that loaded numba takes up to a second of a busy machine to tear down). A Python program that calls
collide2d gets no watchdog: its Ctrl-C is its own.

`RunStop` is how a run answers Ctrl-C (runner.run.drive). `from_ctrl_c(err)` says whether an
exception comes of a Ctrl-C: numba reports a compiled kernel that Ctrl-C stopped as a SystemError
caused by the KeyboardInterrupt. `in_finalizer(frame)` says whether a signal handler was called
inside a `__del__`, where Python would drop what it raises.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import sys
import threading
import time

from collide2d.runner.output import escape, folder, swap  # at hand when the process must end

# Seconds from Ctrl-C to the watchdog ending a command that has not ended itself: long enough for
# a run's chunk of ticks (about a quarter of a second, runner.run.CHUNK_S) and its outputs to be
# written, short enough that the command ends within a second.
GRACE_S = 0.5
# Seconds from Ctrl-C that a command answering it (a run whose chunk has returned, writing the
# run so far) is given before the watchdog ends it all the same: a big run's last files take a
# moment on a busy machine, and ending it loses the run so far.
ANSWER_S = 5.0
# Seconds the watchdog waits for a folder swap under way (a few renames) before it ends the
# process all the same (a stuck file system), leaving the folders to the next run's recovery.
SWAP_WAIT_S = 2.0
# Seconds the watchdog gives the output streams to take what is pending in them (a full pipe
# that nobody reads would hold a flush for ever).
FLUSH_WAIT_S = 0.2
EXIT_INTERRUPTED = 130  # runner.command.exitcodes' (the command line sits above this module)

_state = {"told": False, "watching": False, "answering": False}


def from_ctrl_c(err: BaseException | None) -> bool:
    """Whether `err` comes of a Ctrl-C: a KeyboardInterrupt, or an exception whose chain of
    causes ends in one (numba's SystemError "returned a result with an exception set" for a
    compiled kernel that Ctrl-C stopped)."""
    seen = set()
    while err is not None and id(err) not in seen:
        if isinstance(err, KeyboardInterrupt):
            return True
        seen.add(id(err))
        err = err.__cause__ or err.__context__
    return False


def in_finalizer(frame) -> bool:
    """Whether `frame` (a signal handler's) runs inside a `__del__`: numba's compiler frees LLVM
    objects in finalizers, often, while it compiles, and Python drops an exception raised there
    ("Exception ignored in ...")."""
    while frame is not None:
        if frame.f_code.co_name == "__del__":
            return True
        frame = frame.f_back
    return False


# A Ctrl-C that lands inside a finalizer during a model's advance() (numba's compiler frees LLVM
# objects so) would be dropped there: it is raised this many seconds later instead (SIGALRM).
RETRY_S = 0.01


class RunStop:
    """A run's answer to Ctrl-C, while open (in the main thread): SIGINT sets `seen`, and the run
    stops at the end of its chunk of ticks, `answering` (a Ctrl-C heard outside the model's call
    finds the run writing that chunk's outputs); inside `advancing()` (the model's call) it raises
    KeyboardInterrupt too, or, landing in a finalizer, a moment later, so that a call that would
    not return soon stops at once."""

    def __init__(self):
        self.seen = False
        self.inside = False
        self.previous: dict = {}

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            signals = [signal.SIGINT]
            if hasattr(signal, "setitimer"):  # not on Windows: a Ctrl-C in a finalizer waits
                signals.append(signal.SIGALRM)
            self.previous = {sig: signal.signal(sig, self._caught) for sig in signals}
        return self

    @contextlib.contextmanager
    def advancing(self):
        self.inside = True
        try:
            yield
        finally:
            self.inside = False

    def _caught(self, signum, frame) -> None:
        if signum == signal.SIGINT:
            self.seen = True
        elif not self.seen:
            return  # an alarm of no Ctrl-C of ours
        if not self.inside:  # writing a chunk's outputs, then the run so far
            answering()
            return
        if in_finalizer(frame):
            signal.setitimer(signal.ITIMER_REAL, RETRY_S)
            return
        raise KeyboardInterrupt

    def __exit__(self, *exc) -> None:
        if signal.SIGALRM in self.previous:
            signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)
        if self.seen:  # the run is stopped: what it ran is written now
            answering()


def answering() -> None:
    """Say that the main thread has taken a Ctrl-C in hand and is writing what it has (a run's
    outputs so far) until `told`: the watchdog waits for it, up to ANSWER_S after the Ctrl-C."""
    _state["answering"] = True


def told(line: str) -> None:
    """Print the line a command gives when Ctrl-C stopped it, on stderr above any progress bar;
    a watchdog that must end the process after it then prints nothing more."""
    from collide2d.runner.output import progress

    _state["told"] = True
    progress.say(line)


def watch() -> None:
    """From now on, a SIGINT that the process has not answered by ending within GRACE_S ends it
    (module docstring). Call once, from the main thread of the `collide2d` command; nothing
    happens where set_wakeup_fd cannot take a pipe (not POSIX) or off the main thread."""
    if _state["watching"] or os.name != "posix":
        return
    if threading.current_thread() is not threading.main_thread():
        return
    heard, said = os.pipe()
    os.set_blocking(said, False)  # as set_wakeup_fd requires: a full pipe drops, never blocks
    try:
        signal.set_wakeup_fd(said, warn_on_full_buffer=False)
    except ValueError:
        os.close(heard)
        os.close(said)
        return
    _state["watching"] = True
    threading.Thread(target=_watchdog, args=(heard,), name="collide2d-ctrl-c", daemon=True).start()
    atexit.register(_leave)  # registered before the command runs: called after its own handlers


def _leave() -> None:
    """At exit: a command that answered Ctrl-C (`told`) ends now, its streams flushed."""
    if _state["told"]:
        _last_words(None)
        os._exit(EXIT_INTERRUPTED)


def _watchdog(heard: int) -> None:
    """Wait for SIGINT's byte on the wakeup pipe, then GRACE_S, then end the process."""
    while True:
        try:
            got = os.read(heard, 64)
        except InterruptedError:
            continue
        if not got:
            return
        if signal.SIGINT in got:  # other handled signals (the finalizer retry's alarm) pass
            break
    since = time.monotonic()
    time.sleep(GRACE_S)
    while _state["answering"] and not _state["told"] and time.monotonic() - since < ANSWER_S:
        time.sleep(0.01)
    _end()


def _end() -> None:
    """Leave the output folders as an interrupted run leaves them, say so, exit 130."""
    undone = []
    if swap.stop_renames(SWAP_WAIT_S):
        undone = folder.abandon()
    if not _state["told"]:
        if len(undone) == 1:
            left = f"{undone[0]} is as it was before this run"
        elif undone:
            left = f"{', '.join(map(str, undone))} are as they were before this run"
        else:
            left = "outputs already written are whole"
        line = (
            f"collide2d: interrupted; what was running did not stop within {GRACE_S:g} s of "
            f"Ctrl-C, so it was cut short: {left}"
        )
    else:
        line = None
    _unlink_semaphores()
    _last_words(line)
    os._exit(EXIT_INTERRUPTED)


def _unlink_semaphores() -> None:
    """Unlink the named semaphores of this process's multiprocessing objects (a Dask cluster's
    queues), as their finalizers do at a normal exit; else multiprocessing's resource tracker,
    which outlives the process, reports them as leaked under the command's last line."""
    synchronize = sys.modules.get("multiprocessing.synchronize")
    util = sys.modules.get("multiprocessing.util")
    if synchronize is None or util is None:
        return
    try:
        for finalizer in list(util._finalizer_registry.values()):
            if getattr(finalizer, "_callback", None) is synchronize.SemLock._cleanup:
                finalizer()
    except Exception:  # multiprocessing's insides differ: the warning, at worst
        pass


def _last_words(line: str | None) -> None:
    """Flush stdout and stderr and print `line` on stderr, giving up after FLUSH_WAIT_S (the
    main thread may hold a stream, writing to a pipe that nobody reads)."""

    def flushed() -> None:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:
                pass
        if line is not None:
            text = escape.visible(line) + "\n"
            if sys.stderr.isatty():
                text = "\r\x1b[K" + text  # over a progress bar's line
            try:
                os.write(2, text.encode("utf-8", "replace"))
            except OSError:
                pass

    writer = threading.Thread(target=flushed, daemon=True)
    try:
        writer.start()
    except RuntimeError:  # no new thread at exit (Python 3.12 on): at once, then
        flushed()
        return
    writer.join(FLUSH_WAIT_S)
