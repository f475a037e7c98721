"""What a first run shows, and when: each line a command prints, with the seconds since it started.

Runs one command in a pseudo-terminal of 100 columns (so that the compile notice and its bar are
drawn, as a user sees them) or, with `--piped`, with its output piped (a sweep's lines per run),
from an empty numba cache and without the kernels the wheel ships (`COLLIDE2D_KERNEL_STORE=off`),
as a first run in a fresh clone. Each line, and each redraw of a bar, is printed as
`SECONDS | TEXT`. For example, the compile notice of the gravity pile, and the rows of a cold
sweep of eight small runs:

    python benchmarks/cold_start_lines.py -- collide2d run PILE.yaml --jit on --out /tmp/o
    python benchmarks/cold_start_lines.py --piped -- collide2d sweep \\
        scenarios/paper_fifty_boxes.yaml --set model=paper,stepped --set fps=10,20,30,60 \\
        --workers 2 --out /tmp/sweep

(PILE.yaml: `runner/prebuild.py: pile_scene(1000, 300)`.) `--store` keeps the kernels the wheel
ships, `--cache DIR` uses that numba cache instead of an empty one.
"""

from __future__ import annotations

import argparse
import fcntl
import os
import pty
import select
import struct
import subprocess
import sys
import tempfile
import termios
import time

COLUMNS = 100


def environment(store: bool, cache: str | None) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache or tempfile.mkdtemp(prefix="numba-cache-"))
    if not store:
        env["COLLIDE2D_KERNEL_STORE"] = "off"
    return env


def piped(command: list[str], env: dict) -> int:
    began = time.perf_counter()
    proc = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env
    )
    for line in proc.stdout:
        print(f"{time.perf_counter() - began:7.1f} s | {line.rstrip()}", flush=True)
    return proc.wait()


def in_terminal(command: list[str], env: dict) -> int:
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, COLUMNS, 0, 0))
    began = time.perf_counter()
    proc = subprocess.Popen(
        command, stdin=subprocess.DEVNULL, stdout=follower, stderr=follower, env=env
    )
    os.close(follower)
    while True:
        ready, _, _ = select.select([leader], [], [], 0.5)
        if not ready:
            if proc.poll() is not None:
                break
            continue
        try:
            chunk = os.read(leader, 65536)
        except OSError:  # the terminal closed with the command
            break
        if not chunk:
            break
        at = time.perf_counter() - began
        text = chunk.decode(errors="replace").replace("\r\n", "\n")
        for piece in text.replace("\r", "\n").split("\n"):
            if piece.strip():
                print(f"{at:7.1f} s | {piece.rstrip()}", flush=True)
    return proc.wait()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--piped", action="store_true", help="output piped, not a terminal")
    parser.add_argument("--store", action="store_true", help="keep the kernels the wheel ships")
    parser.add_argument("--cache", metavar="DIR", help="this numba cache, not an empty one")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- COMMAND ...")
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("give a command after --")
    env = environment(args.store, args.cache)
    run = piped if args.piped else in_terminal
    status = run(command, env)
    print(f"exit {status}")
    return status


if __name__ == "__main__":
    sys.exit(main())
