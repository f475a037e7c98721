"""The kernel store's A/B: a first run with the kernels the wheel ships, and without them.

The gravity pile of the docs (runner/prebuild.py: N boxes of 8 px dropping in rows and settling,
300 ticks) at 1,000 and 10,000 boxes, through the installed `collide2d run`, each command from an
empty numba cache (NUMBA_CACHE_DIR a fresh folder) and an empty folder: with the store (as a
wheel built after the prebuild ships it) and without (`COLLIDE2D_KERNEL_STORE=off`, every kernel
compiled on the spot, as before the store), under `--jit auto` (the default) and `--jit on`. Then
the pile's run time warm, its kernels from the store (compiled for a generic CPU) against its
kernels compiled for this machine's CPU (numba's own cache), and whether both write the same
`final.csv`. Wall seconds, medians of `--repeats` runs (the cold runs without the store, a minute
each, `--cold-repeats`). The store must have been built for these sources first:

    python -m collide2d.runner.prebuild
    python benchmarks/kernel_store.py [--sizes 1000,10000] [--repeats 3] [--cold-repeats 1]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from collide2d.engine import kernelstore
from collide2d.runner.bench.targets import user_env
from collide2d.runner.prebuild import pile_scene

TICKS = 300


def run(scene: Path, mode: str, cache: Path, out: Path, store: bool) -> tuple[float, dict, str]:
    """One `collide2d run`: (wall seconds, summary.json, digest of final.csv)."""
    env = dict(user_env(str(out.parent / "pycache")), NUMBA_CACHE_DIR=str(cache))
    for name in ("COLLIDE2D_JIT", "PYTHONPATH", kernelstore.SWITCH):
        env.pop(name, None)
    if not store:
        env[kernelstore.SWITCH] = "off"
    shutil.rmtree(out, ignore_errors=True)
    command = [sys.executable, "-m", "collide2d", "run", str(scene), "--out", str(out)]
    began = time.perf_counter()
    done = subprocess.run([*command, "--jit", mode], env=env, capture_output=True, text=True)
    took = time.perf_counter() - began
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    (folder,) = [p for p in out.iterdir() if p.is_dir()]
    summary = json.loads((folder / "summary.json").read_text())
    final = hashlib.sha256((folder / "final.csv").read_bytes()).hexdigest()[:12]
    return took, summary, final


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1000,10000", help="pile sizes (default 1000,10000)")
    parser.add_argument("--repeats", type=int, default=3, help="runs of each (default 3)")
    parser.add_argument("--cold-repeats", type=int, default=1, help="cold runs without the store")
    args = parser.parse_args()
    if not kernelstore.available():
        raise SystemExit("no kernel store for these sources: python -m collide2d.runner.prebuild")
    work = Path(tempfile.mkdtemp(prefix="kernel-store-"))
    print("| pile | lane | empty cache, store | empty cache, no store | compile s (no store) |")
    print("|---|---|---|---|---|")
    warm_rows = []
    try:
        for n in (int(s) for s in args.sizes.split(",")):
            scene = work / f"pile{n}.yaml"
            scene.write_text(pile_scene(n, TICKS), encoding="utf-8")
            host = work / f"host{n}"  # numba's own cache, filled by the first run without store
            for mode in ("auto", "on"):
                timings = {True: [], False: []}
                compile_s = []
                for store, repeats in ((True, args.repeats), (False, args.cold_repeats)):
                    for _ in range(repeats):
                        cache = work / "cache"
                        shutil.rmtree(cache, ignore_errors=True)
                        took, summary, _ = run(scene, mode, cache, work / "out", store)
                        timings[store].append(took)
                        if not store:
                            compile_s.append(summary.get("compile_time_s", 0.0))
                            if mode == "on" and not host.exists():
                                shutil.copytree(cache, host)
                with_store = statistics.median(timings[True])
                without = statistics.median(timings[False])
                print(
                    f"| {n:,} | {mode} | {with_store:.2f} s | {without:.2f} s "
                    f"| {statistics.median(compile_s):.1f} |",
                    flush=True,
                )
            runs = {"store (generic CPU)": [], "numba's cache (this CPU)": []}
            finals = set()
            for _ in range(args.repeats):
                empty = work / "empty"
                shutil.rmtree(empty, ignore_errors=True)
                for name, cache in (
                    ("store (generic CPU)", empty),
                    ("numba's cache (this CPU)", host),
                ):
                    _, summary, final = run(scene, "on", cache, work / "out", True)
                    runs[name].append(summary["run_time_s"])
                    finals.add(final)
            warm_rows.append((n, runs, len(finals) == 1))
        print("\n| pile | run time, kernels from the store | from numba's cache | same final.csv |")
        print("|---|---|---|---|")
        for n, runs, same in warm_rows:
            store_s, host_s = (statistics.median(v) for v in runs.values())
            print(f"| {n:,} | {store_s:.3f} s | {host_s:.3f} s | {'yes' if same else 'NO'} |")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
