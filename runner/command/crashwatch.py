"""A process that dies of a fatal signal says so: which signal, and the kernel cache to clear.

A fault inside compiled code (SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT), as a damaged kernel
cache can cause, kills the process before any Python code of it runs again: the command cannot
explain itself. Python's faulthandler can still write the dying thread's traceback to a file
descriptor, so:

- `watch()` (the command line, before a command runs) starts a small watcher, a POSIX shell that
  holds the read end of a pipe, and points faulthandler at the write end. A command that ends in
  any ordinary way writes nothing there, and the watcher leaves without a word when the pipe
  closes. After a fatal signal the watcher has Python (`tell`) print, on the command's stderr, one
  `collide2d: error:` line naming the signal and the kernel cache with the command that clears it
  (`message`), then the traceback. The exit status stays the shell's 128 + signal (139 for
  SIGSEGV). Where there is no POSIX shell (Windows), faulthandler writes the traceback to stderr
  directly.
- `record_in_worker()` (a sweep's worker, before its runs) points faulthandler at a file of its
  own in `crash_folder()`; the sweep, told that a task's workers died, reads the newest such file
  (`worker_death`) to say why in the rows of that task.
"""

from __future__ import annotations

import faulthandler
import os
import re
import stat
import sys
import time

from collide2d.engine.jit import cache_clear_hint

# The first line faulthandler writes: "Fatal Python error: Segmentation fault".
_FATAL = re.compile(rb"Fatal Python error: ([^\n]+)")
# faulthandler's names of the fatal signals, and the signals'.
_SIGNALS = {
    "Segmentation fault": "SIGSEGV",
    "Bus error": "SIGBUS",
    "Illegal instruction": "SIGILL",
    "Floating-point exception": "SIGFPE",
    "Floating point exception": "SIGFPE",
    "Aborted": "SIGABRT",
}
# Bytes of a traceback kept (faulthandler writes at most 100 frames per thread).
_MAX_REPORT = 1 << 16
# Seconds a worker's record is kept at most.
KEEP_RECORDS_S = 7 * 86400

_BUG = "this is a bug; the traceback follows"

_sink = None  # the write end faulthandler writes to: kept open as long as the process lives


def signal_name(report: bytes) -> str | None:
    """The signal ("SIGSEGV") a faulthandler report names, its text if unknown; None if the text is
    not one."""
    found = _FATAL.search(report)
    if found is None:
        return None
    text = found.group(1).decode("utf-8", "replace").strip()
    return _SIGNALS.get(text, text)


def message(signal_text: str, in_kernel: bool = True) -> str:
    """The one line said of a process that died of `signal_text`, in a kernel (or numba) or not."""
    return f"collide2d: error: the process died of {_reason(signal_text, in_kernel)}"


def _reason(signal_text: str, in_kernel: bool, bug: str = _BUG) -> str:
    """What killed the process, and what to do about it."""
    if in_kernel:
        return (
            f"{signal_text} in a compiled kernel; numba's kernel cache may be damaged: "
            f"{cache_clear_hint()}, then run the command again"
        )
    return (
        f"{signal_text} ({bug}); if it happens again, clear "
        f"numba's kernel cache: {cache_clear_hint()}"
    )


def _in_kernel(report: bytes) -> bool:
    """Whether the crashed thread was in a kernel call (engine.jit) or in numba's code."""
    frames = re.findall(rb'File "([^"]*)", line \d+ in (\S+)', report)
    if not frames:
        return True  # no Python frame to tell: say where a fault is likeliest
    path, function = frames[0]
    path = path.replace(b"\\", b"/")
    kernel_call = path.endswith(b"engine/jit.py") and function == b"__call__"
    return kernel_call or b"/numba/" in path


# The watcher: a POSIX shell (started without copying this process, unlike a fork) that reads
# the pipe to its end; only when a traceback came does it start Python to say what happened
# (`tell`), else it leaves at once. Ctrl-C, which reaches the whole process group, it ignores.
_WATCHER = """trap '' INT
report=''
while IFS= read -r line || [ -n "$line" ]; do report="$report$line
"; done
[ -n "$report" ] || exit 0
printf '%s' "$report" | "$1" -m collide2d.runner.command.crashwatch || printf '%s' "$report" >&2
"""
_SHELL = "/bin/sh"


def watch() -> None:
    """Report a fatal signal of this process on its stderr (module docstring). Call once, early."""
    global _sink
    if _sink is not None:
        return
    if not (hasattr(os, "posix_spawn") and os.path.exists(_SHELL)):
        faulthandler.enable(file=sys.stderr)  # the traceback alone, as Python gives it
        _sink = sys.stderr
        return
    read_end, write_end = os.pipe()
    try:
        os.posix_spawn(
            _SHELL,
            ["sh", "-c", _WATCHER, "sh", sys.executable],
            os.environ,
            file_actions=[
                (os.POSIX_SPAWN_DUP2, read_end, 0),
                (os.POSIX_SPAWN_OPEN, 1, os.devnull, os.O_WRONLY, 0),
            ],
        )
    except OSError:
        os.close(write_end)
        faulthandler.enable(file=sys.stderr)
        _sink = sys.stderr
        return
    finally:
        os.close(read_end)
    _sink = os.fdopen(write_end, "wb", buffering=0)
    faulthandler.enable(file=_sink, all_threads=False)


def tell(report: bytes) -> bytes:
    """What the watcher prints of `report` (what faulthandler wrote): the line naming the signal
    and the cache to clear, then the report; the report alone when it names no signal."""
    name = signal_name(report)
    if name is None:
        return report
    return message(name, _in_kernel(report)).encode() + b"\n" + report


def crash_folder() -> str:
    """The folder where sweep workers leave the traceback of a fatal signal (this user's)."""
    import tempfile

    user = os.getuid() if hasattr(os, "getuid") else "user"
    return os.path.join(tempfile.gettempdir(), f"collide2d-crashes-{user}")


def record_in_worker() -> None:
    """Point faulthandler at this process's own file in `crash_folder()` (once per process)."""
    global _sink
    if _sink is not None or faulthandler.is_enabled():  # reported already (pytest, the CLI)
        return
    folder = crash_folder()
    try:
        os.makedirs(folder, mode=0o700, exist_ok=True)
        if not _own(folder):
            return
        _forget_old_records(folder)
        _sink = open(os.path.join(folder, f"{os.getpid()}.txt"), "wb", buffering=0)
    except OSError:
        return
    faulthandler.enable(file=_sink, all_threads=False)


def worker_death(since: float) -> str:
    """The note of runs whose worker died: the signal and the cache to clear, when a worker of
    this machine left a traceback after `since` (time.time()); else what is known."""
    newest, report = 0.0, b""
    folder = crash_folder()
    try:
        entries = list(os.scandir(folder)) if _own(folder) else []
    except OSError:
        entries = []
    for entry in entries:
        try:
            stamp = entry.stat().st_mtime
            if stamp < since or stamp <= newest or not entry.is_file():
                continue
            with open(entry.path, "rb") as f:
                text = f.read(_MAX_REPORT)
        except OSError:
            continue
        if signal_name(text) is not None:
            newest, report = stamp, text
    name = signal_name(report) if report else None
    if name is None:
        return (
            "its worker died on every try (killed by a signal, or out of memory); if a compiled "
            f"kernel crashed, numba's kernel cache may be damaged: {cache_clear_hint()}"
        )
    return f"its worker died of {_reason(name, _in_kernel(report), bug='a bug')}"


def _forget_old_records(folder: str, keep_s: float = KEEP_RECORDS_S) -> None:
    """Remove the records of workers that ended without a fault (empty files of processes gone),
    and any older than `keep_s` seconds: a record only explains a recent sweep."""
    now = time.time()
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        try:
            info = entry.stat()
            stem = entry.name.removesuffix(".txt")
            gone = info.st_size == 0 and stem.isdigit() and not _alive(int(stem))
            if entry.is_file() and (gone or now - info.st_mtime > keep_s):
                os.unlink(entry.path)
        except OSError:
            continue


def _own(folder: str) -> bool:
    """Whether `folder` is a real folder of this user's that only this user may write (a shared
    temporary folder holds it)."""
    try:
        info = os.lstat(folder)
    except OSError:
        return False
    mine = not hasattr(os, "getuid") or info.st_uid == os.getuid()
    return stat.S_ISDIR(info.st_mode) and mine and not info.st_mode & 0o022


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


if __name__ == "__main__":  # the watcher's Python, given the report on stdin
    sys.stdout.flush()
    sys.stderr.buffer.write(tell(sys.stdin.buffer.read(_MAX_REPORT)))
    sys.stderr.flush()
