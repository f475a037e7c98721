"""What a user waits for, through the installed `collide2d` command, in one run.

- the bundled demo's first run (`collide2d run`, an empty kernel cache each time);
- `collide2d check` of the project's scenarios from an empty kernel cache;
- a run of a small scenario with the kernels cached (`scenarios/tunnelling_1fps.yaml`);

each with `--jit auto` (the default) and `--jit on` (every kernel compiled, as before the lanes),
interleaved, medians with the spread; every command runs from an empty temporary folder (`check`
with `--root` this repository), Python's bytecode cached there as an installation has it
(collide2d.runner.bench.targets.user_env). `--python PY` runs another installation's collide2d
(a fresh virtualenv holding a wheel, say); `--modes auto,off` compares other modes, `--root DIR`
checks another project's scenarios, `--check-only` times the cold check alone. Usage:

    python benchmarks/first_run.py [--repeats 3] [--warm-repeats 9] [--python PY]
        [--modes auto,on] [--root DIR] [--check-only]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from collide2d.runner.bench.targets import user_env

ROOT = Path(__file__).resolve().parents[1]
COMMAND = [sys.executable, "-m", "collide2d"]


def timed(args: list[str], cache: Path, cwd: Path) -> float:
    env = dict(user_env(str(cwd / "pycache")), NUMBA_CACHE_DIR=str(cache))
    env.pop("COLLIDE2D_JIT", None)
    env.pop("PYTHONPATH", None)
    began = time.perf_counter()
    done = subprocess.run([*COMMAND, *args], cwd=cwd, env=env, capture_output=True, text=True)
    took = time.perf_counter() - began
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed ({done.returncode}):\n{done.stderr}")
    return took


def cold(args: list[str], work: Path, cwd: Path) -> float:
    cache = work / "cache"
    shutil.rmtree(cache, ignore_errors=True)
    return timed(args, cache, cwd)


def shown(times: list[float]) -> str:
    return f"{statistics.median(times):6.2f} s  (min {min(times):.2f}, max {max(times):.2f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="cold runs of each (default 3)")
    parser.add_argument("--warm-repeats", type=int, default=9, help="warm runs (default 9)")
    parser.add_argument("--python", default=sys.executable, help="the Python to run collide2d")
    parser.add_argument(
        "--modes", default="auto,on", help="--jit modes compared, comma-separated (default auto,on)"
    )
    parser.add_argument(
        "--root", type=Path, default=ROOT, help="the project `check` runs (default: this one)"
    )
    parser.add_argument("--check-only", action="store_true", help="only the cold `check`")
    args = parser.parse_args()
    modes = args.modes.split(",")
    COMMAND[0] = args.python
    results: dict[str, list[float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        out = str(work / "out")
        small = str(ROOT / "scenarios" / "tunnelling_1fps.yaml")
        root = str(args.root.resolve())
        for _ in range(args.repeats):
            for mode in modes:
                if not args.check_only:
                    demo = cold(["run", "--out", out, "--quiet", "--jit", mode], work, work)
                    results.setdefault(f"demo, empty cache, --jit {mode}", []).append(demo)
                check = cold(["check", "--root", root, "--quiet", "--jit", mode], work, work)
                results.setdefault(f"check, empty cache, --jit {mode}", []).append(check)
        warm = work / "warm"
        for mode in modes if not args.check_only else ():  # fill the cache first
            timed(["run", small, "--out", out, "--quiet", "--jit", mode], warm, work)
        for _ in range(args.warm_repeats if not args.check_only else 0):
            for mode in modes:
                took = timed(["run", small, "--out", out, "--quiet", "--jit", mode], warm, work)
                results.setdefault(f"small run, cached, --jit {mode}", []).append(took)
    load = os.getloadavg()[0]
    print(f"# collide2d first-run times, wall, {args.python} (load average {load:.1f} at the end)")
    for name, times in results.items():
        print(f"{name:<34} {shown(times)}")


if __name__ == "__main__":
    main()
