"""The jit part of `collide2d bench`: `collide2d run` under `--jit on`, `off` and `auto`, each from
an empty kernel cache, wall time, on the bundled scenarios, the bench's scenes and a grid of sizes.

Each run is a fresh process (`python -m collide2d run FILE --jit MODE --quiet`, the scenario's own
outputs) with its own empty NUMBA_CACHE_DIR, as a CI job starts, and Python's bytecode cached as
an installation has it (targets.user_env). The scenes: every scenario of the scenarios folder, the
bench's standard scene (STANDARD: N boxes under each model) and two-body chain, and GRID, scenes of
10 to 5,000 bodies over 10 to 100,000 ticks. `on` and `auto` run whole; `off` is stopped once it has
taken as long as the slower of them (it can no longer be the faster lane: the row says "> s").
Each row: the three wall times, the lane `auto` took (the summary's `kernels`) and `auto` over the
faster of `on` and `off`, against AUTO_WITHIN. `--quick` runs QUICK_SCENES only.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from collide2d.runner.bench import scenes
from collide2d.runner.bench.targets import user_env

# `auto`'s wall time at most this many times the faster of `on` and `off`, on every scene.
AUTO_WITHIN = 1.5
MODES = ("on", "auto", "off")
# The standard scene: (N, model, ticks).
STANDARD = ((1_000, "paper", 120), (1_000, "stepped", 120), (1_000, "exact", 120))
CHAIN_TICKS = 20
# (bodies, ticks, model) of the grid: a generated gas (the standard scene's boxes and density).
GRID = (
    (10, 10, "paper"),
    (10, 100_000, "paper"),
    (100, 10_000, "exact"),
    (500, 1_000, "stepped"),
    (1_000, 1_000, "paper"),
    (5_000, 10, "exact"),
    (5_000, 1_000, "paper"),
)
QUICK_SCENES = ("tunnelling_1fps", "grid-10x10-paper")  # --quick: seconds, for tests


def scene_files(folder: Path, tmp: Path, quick: bool) -> list[tuple[str, Path, int, int]]:
    """(name, file, bodies, ticks) of each scene, the built ones written into `tmp`."""
    from collide2d.runner.scenario.load import load

    found = []
    for path in sorted(folder.glob("*.yaml")):
        scenario = load(path)
        found.append((path.stem, path, scenario.bodies.n, scenario.ticks))
    built = [(f"standard-{n}-{m}", n, t, m) for n, m, t in STANDARD]
    built += [(f"grid-{n}x{t}-{m}", n, t, m) for n, t, m in GRID]
    for name, n, ticks, model in built:
        text = scenes.standard_scene(n, model, ticks)
        path = tmp / f"{name}.yaml"
        path.write_text(text.replace(f"name: standard-{n}\n", f"name: {name}\n"))
        found.append((name, path, n, ticks))
    path = tmp / "two-body-chain.yaml"
    path.write_text(scenes.chain_scene(CHAIN_TICKS))
    found.append(("two-body-chain", path, 2, CHAIN_TICKS))
    if quick:
        found = [f for f in found if f[0] in QUICK_SCENES]
    return found


def run_cold(path: Path, mode: str, tmp: Path, limit: float | None = None) -> tuple[float, str]:
    """(wall s, the summary's `kernels`) of `collide2d run PATH --jit MODE` from an empty kernel
    cache; (limit, "stopped") when it passes `limit` seconds."""
    with tempfile.TemporaryDirectory(prefix="cache-", dir=tmp) as cache:
        env = user_env(str(tmp / "pycache"))
        env["NUMBA_CACHE_DIR"] = cache
        env.pop("COLLIDE2D_JIT", None)
        env.pop("NUMBA_DISABLE_JIT", None)
        out = tmp / f"out-{mode}"
        cmd = [sys.executable, "-m", "collide2d", "run", str(path), "--quiet", "--out", str(out)]
        cmd += ["--jit", mode]
        began = time.perf_counter()
        try:
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=env, timeout=limit)
        except subprocess.TimeoutExpired:
            return float(limit), "stopped"
        wall = time.perf_counter() - began
    summaries = sorted(out.glob("*/summary.json"), key=os.path.getmtime)
    kernels = json.loads(summaries[-1].read_text()).get("kernels", "") if summaries else ""
    return wall, kernels


def coldstart(quick: bool, echo, folder: Path = scenes.PROJECT_SCENARIOS) -> list[dict]:
    """One row per scene: wall s of each lane from an empty cache, and auto / the faster."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="collide2d-jit-") as name:
        tmp = Path(name)
        run_cold(folder / f"{scenes.SMALL_SCENARIO}.yaml", "off", tmp)  # bytecode cached
        for scene, path, n, ticks in scene_files(folder, tmp, quick):
            on, on_lane = run_cold(path, "on", tmp)
            auto, auto_lane = run_cold(path, "auto", tmp)
            off, off_lane = run_cold(path, "off", tmp, limit=max(on, auto) + 1.0)
            stopped = off_lane == "stopped"
            best = on if stopped else min(on, off)
            ratio = auto / best
            rows.append({
                "part": "jit",
                "scene": scene,
                "n": n,
                "ticks": ticks,
                "on_s": on,
                "off_s": off,
                "off_stopped": stopped,
                "auto_s": auto,
                "ratio": ratio,
                "note": auto_lane,
                "target": f"<= {AUTO_WITHIN:g}",
                "met": ratio <= AUTO_WITHIN,
            })  # fmt: skip
            shown = f"> {off:.1f}" if stopped else f"{off:.1f}"
            echo(f"jit      {scene:32s} on {on:6.1f} s  off {shown:>7} s  auto {auto:6.1f} s "
                 f"({auto_lane})  auto/faster {ratio:.2f}")  # fmt: skip
    return rows


def markdown(rows: list[dict]) -> list[str]:
    """bench.md's section of the jit part."""
    from collide2d.runner.bench.report import _table

    lines = ["## Compiled, interpreted or auto, from an empty kernel cache", ""]
    lines.append(
        "`collide2d run FILE --jit MODE`, each in a fresh process with an empty NUMBA_CACHE_DIR, "
        "wall seconds; `off` stopped once past the slower of the other two (> s). auto/faster: "
        f"`auto` over the faster of `on` and `off` (target <= {AUTO_WITHIN:g})."
    )
    lines.append("")
    header = ["scene", "bodies", "ticks", "on s", "off s", "auto s", "auto took", "auto/faster"]
    body = []
    for r in rows:
        off = f"> {r['off_s']:.1f}" if r["off_stopped"] else f"{r['off_s']:.2f}"
        body.append([r["scene"], r["n"], r["ticks"], f"{r['on_s']:.2f}", off,
                     f"{r['auto_s']:.2f}", r["note"], f"{r['ratio']:.2f}"])  # fmt: skip
    return lines + _table(header, body) + [""]
