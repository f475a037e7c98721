"""A cold sweep, or a check on a cluster, is never silent: from an empty kernel cache, on a
terminal, the bar of runs is drawn before the first run is done and the compile notice comes as a
worker starts compiling, relayed from the worker process."""

from __future__ import annotations

import fcntl
import os
import pty
import select
import signal
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest

from collide2d.runner.output import progress

BIN = Path(sys.executable).parent
NOTICE = "compiling kernels, first run only"
SMALL = """version: 1
name: small
world: {width: 60, height: 40, fps: 10}
ticks: 40
objects:
  - {name: left, shape: box, size: 6, position: [5, 5], velocity: [20, 0]}
  - {name: right, shape: box, size: 6, position: [40, 5], velocity: [-20, 0]}
"""


def on_terminal(argv, cwd: Path, env: dict, until, deadline_s: float = 120) -> str:
    """What `argv` shows on a 100-column terminal until `until(text)` holds, it ends, or the
    deadline passes; the command (and its worker processes) are then stopped."""
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    proc = subprocess.Popen(
        argv, cwd=cwd, env=env, stdin=follower, stdout=follower, stderr=follower,
        start_new_session=True,
    )  # fmt: skip
    os.close(follower)
    text, ends = "", time.monotonic() + deadline_s
    try:
        while time.monotonic() < ends and not until(text):
            if not select.select([leader], [], [], 0.5)[0]:
                if proc.poll() is not None:
                    break
                continue
            try:
                data = os.read(leader, 100_000)
            except OSError:  # the command ended and closed the terminal
                break
            if not data:
                break
            text += data.decode(errors="replace")
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        os.close(leader)
    return text


def before_first_run(text: str) -> str:
    """What was shown before the bar counted its first run done (1/N)."""
    return text.split("| 1/")[0]


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
@pytest.mark.parametrize(
    "command",
    [
        ["sweep", "scenarios/small.yaml", "--set", "fps=10,20", "--workers", "1", "--out", "o"],
        ["check", "--workers", "1", "--jit", "on"],
    ],
    ids=["sweep", "check"],
)
def test_a_cold_cluster_run_shows_its_bar_and_the_notice_before_any_run_is_done(tmp_path, command):
    pytest.importorskip("distributed")
    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "small.yaml").write_text(SMALL)
    (tmp_path / "cache").mkdir()  # an empty kernel cache, as a CI job starts with
    env = dict(os.environ, COLLIDE2D_KERNEL_STORE="off", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("NUMBA_DISABLE_JIT", None)

    def seen(text: str) -> bool:  # stop once both are there (or a run is done)
        early = before_first_run(text)
        return ("| 1/" in text) or (NOTICE in early and "| 0/" in early)

    text = on_terminal([str(BIN / "collide2d"), *command], tmp_path, env, seen)
    early = before_first_run(text)
    assert NOTICE in early, text[-2000:]
    assert "| 0/" in early, text[-2000:]  # the bar, drawn while nothing is done yet


def test_a_waiting_bar_is_drawn_at_once_and_its_clock_runs(monkeypatch):
    monkeypatch.setattr(progress, "TICK_S", 0.05)
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
    with os.fdopen(follower, "w") as stream:
        bar = progress.Progress(3, "sweep", stream, unit=" runs", waiting=True)
        time.sleep(1.3)  # nothing done: the bar still redraws, its elapsed time moving
        progress.say("a line above the bar", stream)
        bar.close()
        stream.flush()
        text = b""
        while select.select([leader], [], [], 0.3)[0]:
            text += os.read(leader, 100_000)
    os.close(leader)
    text = text.decode()
    draws = [d for d in text.split("\r") if "0/3" in d]
    assert "[00:00" in draws[0] and any("[00:01" in d for d in draws)
    line_at = text.index("a line above the bar")
    assert "0/3" in text[line_at:]  # drawn again below the line
