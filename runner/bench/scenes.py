"""The scenes of `collide2d bench`: the standard scene built in code, and the scenario files.

The standard scene: boxes of STANDARD_SIZE_PX covering STANDARD_COVERAGE of a world of aspect
STANDARD_ASPECT, speeds STANDARD_SPEEDS px/s in random directions, at STANDARD_FPS, seeded; as
scenario text, so it runs through the same loader and `collide2d run` as any scenario. The other
parts read scenario files (`NEEDED_SCENARIOS`) from the project's scenarios/ folder, or the folder
given with `--scenarios`; where neither holds them (an installed wheel), from the copies the package
ships (`PACKAGED_SCENARIOS`).
"""

from __future__ import annotations

import math
from pathlib import Path

# The standard scene (the issue's): boxes of STANDARD_SIZE_PX covering STANDARD_COVERAGE of a world
# of aspect STANDARD_ASPECT, speeds STANDARD_SPEEDS px/s in random directions, at STANDARD_FPS.
STANDARD_SIZE_PX = 10
STANDARD_COVERAGE = 0.05
STANDARD_ASPECT = 4 / 3
STANDARD_SPEEDS = (10, 100)
STANDARD_FPS = 60
STANDARD_SEED = 1

# The benchmark scenarios of the error part; the section IV demo (skips, targets); the small
# scenario timed through `collide2d run` (targets).
BENCH_SCENARIOS = (
    "bench_tunnelling",
    "bench_dense_gas",
    "bench_mass_ratio_chain",
    "bench_fast_small",
)
DEMO_SCENARIO = "paper_fifty_boxes"
SMALL_SCENARIO = "tunnelling_1fps"
# The scenario files the parts read (besides the standard scene, built here).
NEEDED_SCENARIOS = (*BENCH_SCENARIOS, DEMO_SCENARIO, SMALL_SCENARIO)
# Where they are unless `--scenarios` says otherwise: the project's scenarios/ folder, next to the
# runner package.
PROJECT_SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
# Copies of NEEDED_SCENARIOS shipped in the package (tests keep them equal to the project's), for
# a bench run where no project folder holds them (collide2d installed from a wheel).
PACKAGED_SCENARIOS = Path(__file__).resolve().parents[1] / "data"


def standard_world(n: int) -> tuple[int, int]:
    """(width, height) px of the standard scene's 4:3 world where n boxes cover 5 % of it."""
    area = n * STANDARD_SIZE_PX**2 / STANDARD_COVERAGE
    width = round(math.sqrt(area * STANDARD_ASPECT))
    return width, round(width / STANDARD_ASPECT)


def standard_scene(n: int, model: str, ticks: int = 1) -> str:
    """The standard scene with n boxes under `model`, as scenario text."""
    width, height = standard_world(n)
    lo, hi = STANDARD_SPEEDS
    return (
        "version: 1\n"
        f"name: standard-{n}\n"
        f"description: The standard scene of collide2d bench, {n} boxes.\n"
        f"world: {{width: {width}, height: {height}, fps: {STANDARD_FPS}}}\n"
        f"model: {model}\n"
        f"ticks: {ticks}\n"
        "generate:\n"
        f"  - {{count: {n}, shape: box, size: {STANDARD_SIZE_PX}, "
        f"speed: {{min: {lo}, max: {hi}}}, seed: {STANDARD_SEED}}}\n"
        "output: {frames: none, gif: false, events: false}\n"
    )


def chain_scene(ticks: int = 1) -> str:
    """The two-body chain of the exact part, as scenario text: boxes of masses 1 and 3 bouncing
    between each other and the walls of a 320x240 world at 1e5 px/s, 10 fps."""
    return (
        "version: 1\n"
        "name: two-body-chain\n"
        "description: The two-body chain of collide2d bench, many events per tick.\n"
        "world: {width: 320, height: 240, fps: 10}\n"
        "model: exact\n"
        f"ticks: {ticks}\n"
        "objects:\n"
        "  - {shape: box, size: 10, position: [50, 115], velocity: [100000, 0], mass: 1}\n"
        "  - {shape: box, size: 10, position: [200, 115], velocity: [-150000, 0], mass: 3}\n"
        "output: {frames: none, gif: false, events: false}\n"
    )
