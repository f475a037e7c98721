"""The load part of `collide2d bench` (`--part load`): how long a big scene takes to load, and the
memory it takes, before the first tick.

LOAD_N objects of the standard scene (boxes 10x10 px on a 12 px lattice, velocities to three
decimals, four colours) are written four ways into a temporary folder: a YAML list with one flow
mapping per line and the same list in block style as `yaml.safe_dump` writes it (both through the
fast lane, runner.scenario.fastlane), a CSV table (`objects: {file: bodies.csv}`,
runner.scenario.table) and, once, the flow list read by the general path alone (the fast lane turned
off). Each is loaded by `runner.scenario.load.load` in a fresh `python` process that reports the
load's wall time and its peak resident memory (VmHWM on Linux, else `ru_maxrss`) beside that of the
same process before loading (imports done); the median of LOAD_REPEATS processes. Rows are one
figure each.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from collide2d.runner.bench import goals
from collide2d.runner.bench.timing import median

LOAD_N = 100_000
QUICK_LOAD_N = 2_000
LOAD_REPEATS = 5
COLORS = ("red", "white", "blue", "green")

_CHILD = """
import json, resource, sys, time
from collide2d.runner.scenario import load as scenario
from collide2d.runner.scenario import fastlane
def peak_kb():
    # this process's own high-water mark (ru_maxrss may carry the parent's across exec)
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
if sys.argv[2] == "general":
    fastlane.split = lambda text: None
scenario.loads("version: 1\\nobjects: []\\n")
before = peak_kb()
began = time.perf_counter()
s = scenario.load(sys.argv[1])
spent = time.perf_counter() - began
print(json.dumps({"s": spent, "n": s.bodies.n, "before_kb": before, "peak_kb": peak_kb()}))
"""


def write_scenes(folder: Path, n: int) -> dict[str, Path]:
    """The scene of n boxes as a YAML list (flow and block style) and as a CSV table; {kind:
    scenario path}."""
    rng = np.random.default_rng(1)
    cols = max(1, int(np.sqrt(n * 4 / 3 * 4)))
    rows_ = -(-4 * n // cols)
    idx = rng.choice(cols * rows_, n, replace=False)
    x, y = idx % cols * 12, idx // cols * 12
    v = rng.uniform(-100, 100, (n, 2)).round(3)
    head = (
        f"version: 1\nname: load-{n}\nworld: {{width: {cols * 12}, height: {rows_ * 12}, "
        "fps: 60}\nmodel: stepped\nticks: 1\noutput: {frames: none, gif: false, events: false}\n"
    )
    listed = [
        f"  - {{shape: box, size: [10, 10], position: [{x[i]}, {y[i]}], velocity: "
        f"[{v[i, 0]}, {v[i, 1]}], color: {COLORS[i % 4]}}}"
        for i in range(n)
    ]
    (folder / "listed.yaml").write_text(head + "objects:\n" + "\n".join(listed) + "\n")
    blocks = [
        f"- shape: box\n  size:\n  - 10\n  - 10\n  position:\n  - {x[i]}\n  - {y[i]}\n"
        f"  velocity:\n  - {v[i, 0]}\n  - {v[i, 1]}\n  color: {COLORS[i % 4]}\n"
        for i in range(n)
    ]
    (folder / "block.yaml").write_text(head + "objects:\n" + "".join(blocks))
    table = [f"{i},box,10,10,{x[i]},{y[i]},{v[i, 0]},{v[i, 1]},1,{COLORS[i % 4]}" for i in range(n)]
    (folder / "bodies.csv").write_text(
        "id,shape,w,h,x,y,vx,vy,mass,color\n" + "\n".join(table) + "\n"
    )
    (folder / "table.yaml").write_text(head + "objects: {file: bodies.csv}\n")
    return {
        "yaml": folder / "listed.yaml",
        "block": folder / "block.yaml",
        "csv": folder / "table.yaml",
    }


def _child(path: Path, lane: str) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, str(path), lane],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def load(quick: bool, echo, n: int | None = None) -> list[dict]:
    n = n or (QUICK_LOAD_N if quick else LOAD_N)
    repeats = 1 if quick else LOAD_REPEATS
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        paths = write_scenes(Path(tmp), n)
        runs = [
            ("YAML list, fast lane", paths["yaml"], "fast", repeats),
            ("YAML block list, fast lane", paths["block"], "fast", repeats),
            ("CSV table", paths["csv"], "fast", repeats),
            ("YAML list, general path", paths["yaml"], "general", 1),
        ]
        for what, path, lane, times in runs:
            target_s, target_mb = goals.LOAD.get(what, (None, None))
            results = [_child(path, lane) for _ in range(times)]
            assert all(r["n"] == n for r in results)
            seconds = median([r["s"] for r in results])
            peak = median([r["peak_kb"] for r in results]) / 1024
            grown = median([r["peak_kb"] - r["before_kb"] for r in results]) / 1024
            goal = f" (target <= {target_s} s" if target_s else ""
            goal += f", <= {target_mb} MB)" if target_mb else (")" if goal else "")
            rows.append(
                {
                    "part": "load",
                    "scene": f"{n:,} objects: {what}",
                    "how": what,
                    "peak_mb": peak,
                    "n": n,
                    "run_time_s": seconds,
                    "value": seconds,
                    "note": f"s to load{goal}; peak memory {peak:.0f} MB, {grown:.0f} MB of it "
                    f"taken by the load; median of {times}",
                }
            )
            echo(
                f"load     {what:26s} {n:,} objects: {seconds:.3f} s, peak {peak:.0f} MB "
                f"(+{grown:.0f} MB)"
            )
    return rows
