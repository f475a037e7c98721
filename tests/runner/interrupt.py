"""Ctrl-C as a terminal sends it, for the tests of commands that must stop on it.

A command is started as a shell starts it (`STARTED`): in the foreground (SIGINT as the shell had
it), or in the background of a script (`collide2d ... &`: SIGINT ignored, which Python would keep
but for the command's own handler; `sh -c 'trap "" INT; exec ...'` starts it so).
"""

from __future__ import annotations

import os
import signal
import subprocess
import time

STARTED = {
    "foreground": [],
    "background": ["sh", "-c", 'trap "" INT; exec "$@"', "sh"],
}


def interrupted(started: str, cmd: list, cwd, wait_s: float = 0.0, timeout_s: float = 120.0):
    """Start `cmd` as `started` says, in a process group of its own; once it has printed its first
    line on stderr (and `wait_s` more seconds), send SIGINT to the whole group, as a terminal's
    Ctrl-C does. Returns (that first line, the process, its stdout, the rest of its stderr) once
    it has ended, the process's `took_s` the seconds from SIGINT to its end; a process still
    running after `timeout_s` is killed."""
    proc = subprocess.Popen(
        [*STARTED[started], *map(str, cmd)],
        cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
        text=True, start_new_session=True,
    )  # fmt: skip
    try:
        first = proc.stderr.readline()
        time.sleep(wait_s)
        os.killpg(proc.pid, signal.SIGINT)
        sent = time.monotonic()
        out, err = proc.communicate(timeout=timeout_s)
        proc.took_s = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return first, proc, out, err
