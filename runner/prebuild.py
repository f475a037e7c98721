"""The prebuild: compile the kernels a wheel ships into the package's kernel store.

A release runs `python -m collide2d.runner.prebuild` before `python -m build`, from the project's
folder (it reads the bundled scenarios). It empties the store (engine.kernelstore), then runs a set
of scenes compiled, in a process of its own told to compile for a generic CPU and to keep every
kernel in the store: each bundled scenario under its own model with its own outputs (so the
picture kernels compile too), the bench's standard scene under every model at sizes that take
each broad phase, the gravity pile of the docs' first-run figures at 1,000 and 10,000 boxes, and
`collide2d bench --quick` (its scaling, error, skips and targets parts; `--no-bench` leaves it out,
as CI does to keep within its time).
Last it writes the store's manifest, which makes the store readable where the same sources, Python
and numba run. A kernel no scene reached compiles on the user's machine as before.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from collide2d.engine import kernelstore

# The bench's standard scene at sizes that take each broad phase (as the compile-time table's).
STANDARD_N = (30, 300, 3000)
STANDARD_TICKS = 30
# The gravity pile: boxes dropped in rows that settle on the floor (the big one for its first
# contacts only: its ticks cost seconds).
PILE_TICKS = {1000: 300, 10000: 60}


def pile_scene(n: int, ticks: int = 300) -> str:
    """N boxes of 8 px in rows with 4 px gaps, ceil(2 sqrt N) to a row, in a world three times as
    tall as the rows, dropping under gravity (restitution and friction 0.3) as scenario text."""
    cols = math.ceil(2 * math.sqrt(n))
    rows = math.ceil(n / cols)
    width, height = cols * 12 + 8, max(200, 3 * (rows * 12 + 4))
    lines = [
        "version: 1",
        f"name: pile{n}",
        f"world: {{width: {width}, height: {height}, fps: 60, gravity: [0, 980],"
        " restitution: 0.3, friction: 0.3}",
        f"model: stepped\nticks: {ticks}\nobjects:",
    ]
    for i in range(n):
        x, y = 4 + (i % cols) * 12, 4 + (i // cols) * 12
        lines.append(
            f"  - {{shape: box, size: [8, 8], position: [{x}, {y}], velocity: "
            f"[{(37 * i) % 21 - 10}, 0], mass: 1, restitution: 0.3, friction: 0.3}}"
        )
    lines.append("output: {frames: none, gif: false, events: false}")
    return "\n".join(lines) + "\n"


def _compile_scenes(scenarios: Path, bench: bool = True) -> int:
    """In the prebuild's child process: run every scene compiled, as `collide2d run` does;
    returns the number of kernel files in the store."""
    from collide2d.runner.bench.scenes import standard_scene
    from collide2d.runner.command.main import main as command

    with tempfile.TemporaryDirectory() as out:
        scenes = [(f"pile {n}", pile_scene(n, ticks)) for n, ticks in PILE_TICKS.items()]
        scenes += [
            (f"standard {model} {n}", standard_scene(n, model, ticks=STANDARD_TICKS))
            for model in ("paper", "stepped", "exact")
            for n in STANDARD_N
        ]
        scenes += [(path.stem, path) for path in sorted(scenarios.glob("*.yaml"))]
        commands = []
        for done, (name, source) in enumerate(scenes):
            if isinstance(source, str):
                path = Path(out) / f"scene{done}.yaml"
                path.write_text(source, encoding="utf-8")
                source = path
            runs = str(Path(out) / "runs")
            commands.append((name, ["run", str(source), "--out", runs, "--jit", "on", "--quiet"]))
        if bench:
            quick = ["bench", "--quick", "--scenarios", str(scenarios), "--out", out, "--quiet"]
            commands.append(("bench --quick", quick))
        for done, (name, argv) in enumerate(commands, 1):
            began = time.perf_counter()
            status = command(argv)
            if status not in (0, 1 if argv[0] == "bench" else 0):  # bench: 1, a target missed
                raise SystemExit(f"collide2d {' '.join(argv)} ended with exit {status}")
            took = time.perf_counter() - began
            print(f"[{done}/{len(commands)}] {name}: {took:.1f} s", flush=True)
    from numba.core.registry import cpu_target

    magic = cpu_target.target_context.codegen().magic_tuple()
    files = sum(
        name.endswith(".nbc") for _, _, names in os.walk(kernelstore.STORE) for name in names
    )
    print(f"wrote {kernelstore.write_manifest(magic, files)}", flush=True)
    return files


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m collide2d.runner.prebuild",
        description="Compile the kernels a wheel ships, for a generic CPU, into the package's "
        "engine/compiled-kernels/.",
    )
    parser.add_argument(
        "--scenarios", type=Path, default=Path("scenarios"), help="the bundled scenarios' folder"
    )
    parser.add_argument(
        "--no-bench",
        action="store_true",
        help="leave out `collide2d bench --quick` (its kernels then compile on its first run)",
    )
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not args.scenarios.is_dir():
        parser.error(f"{args.scenarios}: no such folder (run from the project's folder)")
    if args.child:
        _compile_scenes(args.scenarios, bench=not args.no_bench)
        return 0
    shutil.rmtree(kernelstore.STORE, ignore_errors=True)
    os.makedirs(kernelstore.STORE)
    env = dict(os.environ, NUMBA_CPU_NAME="generic", COLLIDE2D_JIT="on")
    env[kernelstore.BUILDING] = "1"
    env.pop("NUMBA_CPU_FEATURES", None)
    env.pop("NUMBA_DISABLE_JIT", None)
    command = [sys.executable, "-m", "collide2d.runner.prebuild", "--child"]
    command += ["--no-bench"] if args.no_bench else []
    began = time.perf_counter()
    status = subprocess.call([*command, "--scenarios", str(args.scenarios)], env=env)
    if status:
        shutil.rmtree(kernelstore.STORE, ignore_errors=True)
        print(f"prebuild failed (exit {status}): the store is left empty", file=sys.stderr)
        return 1
    print(f"compiled the kernel store in {time.perf_counter() - began:.0f} s: {kernelstore.STORE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
