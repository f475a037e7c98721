"""Where a cold kernel cache's seconds go: each kernel's own compile time, in one process.

Runs the project's scenarios (or the files given) compiled (`--jit on`) from an empty kernel
cache, in one fresh process, and reports the wall time and, per kernel, its specialisations and
the seconds numba spent compiling it, not counting the kernels it calls (those are their own
rows; a caller's time includes linking and optimising their code into its own). The compile
time of the kernels is most of a cold test suite's and of a big scene's first run: this is the
script to run before and after a change that may add to it. Usage:

    python benchmarks/compile_time.py [SCENARIO ...] [--top 25]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# Run in a fresh process with an empty cache: records (kernel, own seconds) per compilation.
CHILD = """
import json, sys, time
from numba.core import event

stack, rows = [], []


class Listen(event.Listener):
    def on_start(self, ev):
        func = ev.data["dispatcher"].py_func
        stack.append([f"{func.__module__}.{func.__qualname__}", time.perf_counter(), 0.0])

    def on_end(self, ev):
        name, began, inner = stack.pop()
        took = time.perf_counter() - began
        if stack:
            stack[-1][2] += took
        rows.append((name, took - inner))


event.register("numba:compile", Listen())
from collide2d.runner.cli import main

out, paths = sys.argv[1], sys.argv[2:]
began = time.perf_counter()
for path in paths:
    status = main(["run", path, "--out", out, "--jit", "on", "--quiet", "--no-gif", "--no-png"])
    if status:
        raise SystemExit(f"{path}: exit {status}")
print(json.dumps({"wall_s": time.perf_counter() - began, "rows": rows}))
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", help="default: every file of scenarios/")
    parser.add_argument("--top", type=int, default=25, help="kernels listed (default 25)")
    args = parser.parse_args()
    paths = args.scenarios or sorted(str(p) for p in (ROOT / "scenarios").glob("*.yaml"))
    with tempfile.TemporaryDirectory(prefix="collide2d-compile-") as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"))
        env.pop("COLLIDE2D_JIT", None)
        done = subprocess.run(
            [sys.executable, "-c", CHILD, str(Path(tmp) / "out"), *paths],
            env=env, capture_output=True, text=True,
        )  # fmt: skip
    if done.returncode:
        raise SystemExit(done.stderr)
    result = json.loads(done.stdout.splitlines()[-1])
    kernels: dict[str, list[float]] = {}
    for name, seconds in result["rows"]:
        kernels.setdefault(name, []).append(seconds)
    total = sum(seconds for _, seconds in result["rows"])
    print(f"{len(paths)} scenarios, compiled from an empty cache: {result['wall_s']:.1f} s wall, "
          f"{total:.1f} s compiling {len(result['rows'])} specialisations")  # fmt: skip
    print(f"{'own s':>7}  {'specs':>5}  kernel")
    ranked = sorted(kernels.items(), key=lambda item: -sum(item[1]))
    for name, times in ranked[: args.top]:
        print(f"{sum(times):7.2f}  {len(times):5d}  {name}")


if __name__ == "__main__":
    main()
