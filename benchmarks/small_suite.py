"""Write a project of a small suite of scenarios, as a user's CI checks it: SUITE's 20 scenarios
(2 to 500 bodies, 50 to 1,000 ticks, every model, boxes and circles, frames kept for the goldens),
a `[tool.collide2d]` table, and its goldens blessed. The cold-CI figure of `--jit auto` is
`python benchmarks/first_run.py --root DIR --check-only --modes auto,off,on` on it. Usage:

    python benchmarks/small_suite.py DIR
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

# (name, model, shape, bodies, ticks): a mix of what a project's regression suite holds, a few
# bodies over many ticks for most, a few gases; 202,500 object-ticks in all.
SUITE = (
    ("pair_head_on", "paper", "box", 2, 200),
    ("pair_glancing", "exact", "circle", 2, 300),
    ("wall_corner", "paper", "box", 3, 400),
    ("three_in_a_row", "exact", "box", 3, 500),
    ("stepped_pair", "stepped", "box", 2, 1000),
    ("heavy_light", "exact", "box", 4, 600),
    ("circles_few", "exact", "circle", 6, 400),
    ("boxes_few", "paper", "box", 8, 1000),
    ("stepped_few", "stepped", "circle", 10, 500),
    ("boxes_20", "paper", "box", 20, 500),
    ("circles_20", "exact", "circle", 20, 500),
    ("stepped_30", "stepped", "box", 30, 300),
    ("boxes_50", "paper", "box", 50, 300),
    ("circles_50", "exact", "circle", 50, 200),
    ("stepped_80", "stepped", "circle", 80, 150),
    ("boxes_100", "paper", "box", 100, 200),
    ("gas_200", "exact", "circle", 200, 100),
    ("gas_300", "paper", "box", 300, 100),
    ("stepped_gas_300", "stepped", "box", 300, 60),
    ("gas_500", "paper", "box", 500, 50),
)


def scenario(model: str, shape: str, n: int, ticks: int, seed: int) -> str:
    side = int(40 * (n**0.5)) + 80
    size = "diameter: 8" if shape == "circle" else "size: 8"
    exact = "{kind: exact, geometry: exact}" if model == "exact" else model
    return (
        "version: 1\n"
        f"world: {{width: {side}, height: {side * 3 // 4}, fps: 30}}\n"
        f"model: {exact}\n"
        f"ticks: {ticks}\n"
        "generate:\n"
        f"  - {{count: {n}, shape: {shape}, {size}, speed: {{min: 20, max: 80}}, seed: {seed}}}\n"
        f"output: {{frames: [0, {ticks // 2}, {ticks}], gif: false, events: true}}\n"
    )


def main() -> None:
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    root = Path(sys.argv[1])
    (root / "scenarios").mkdir(parents=True, exist_ok=True)
    (root / "pyproject.toml").write_text('[project]\nname = "suite"\n\n[tool.collide2d]\n')
    total = 0
    for seed, (name, model, shape, n, ticks) in enumerate(SUITE, 1):
        (root / "scenarios" / f"{name}.yaml").write_text(scenario(model, shape, n, ticks, seed))
        total += n * ticks
    subprocess.run(
        [sys.executable, "-m", "collide2d", "bless", "--root", str(root), "--quiet"]
        + ["--jit", "off"],
        check=True,
    )
    print(f"{root}: {len(SUITE)} scenarios, {total:,} object-ticks, goldens blessed")


if __name__ == "__main__":
    main()
