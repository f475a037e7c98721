"""The stepped model against an earlier version of itself, in one process, on the standard scene.

The earlier version's stepped model (the package `engine/models/stepped/`, or before it the
modules `engine/models/stepped*.py` and `engine/stepcontact.py`) is taken from a git revision
(`git show`) into a temporary folder, its imports of its own modules pointed there (each module
one flat file), and both versions step the same
scene in turns: medians of REPEATS timings of about a second each, per body-step, in CPU time of
this process (`--clock cpu`, the default, less sensitive to other jobs on the machine than the
wall clock; with more than one thread use `--clock wall`). Both must end in the same positions
and velocities, to the bit, which is printed too. Usage:

    python benchmarks/stepped_versions.py REV [--threads 1] [--n 1000 --n 100000] [--clock cpu]

REV is any git revision of this repository whose stepped model imports only engine modules that
still exist (`5045bbf`, the model before its split into stage modules, does).
"""

from __future__ import annotations

import argparse
import importlib
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 7


# The files of the stepped model at any revision: its package, or its flat modules of before.
MODEL_FILES = re.compile(r"engine/(models/stepped(/\w+|\w*)|stepcontact)\.py")


def _old_model(rev: str, folder: Path):
    """The Model class of the stepped model at `rev`, its modules copied into `folder`."""
    listing = subprocess.run(
        ["git", "ls-tree", "-r", "--name-only", rev, "engine/"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    ).stdout.split()  # fmt: skip
    flat = {}  # each module's import name at `rev` -> its flat name here, and its path
    for path in filter(MODEL_FILES.fullmatch, listing):
        name = "collide2d." + path[: -len(".py")].replace("/", ".").removesuffix(".__init__")
        flat[name] = ("old_" + name.removeprefix("collide2d.engine.").replace(".", "_"), path)
    names = re.compile("(" + "|".join(map(re.escape, sorted(flat, key=len)[::-1])) + r")\b")
    for new, path in flat.values():
        text = subprocess.run(
            ["git", "show", f"{rev}:{path}"], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout
        (folder / f"{new}.py").write_text(names.sub(lambda m: flat[m[1]][0], text))
    sys.path.insert(0, str(folder))
    return importlib.import_module(flat["collide2d.engine.models.stepped"][0]).Model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("rev")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--n", type=int, action="append")
    parser.add_argument("--clock", choices=("cpu", "wall"), default="cpu")
    args = parser.parse_args()
    import numpy as np

    from collide2d.engine import threads
    from collide2d.engine.models import stepped
    from collide2d.runner.bench.scenes import standard_scene
    from collide2d.runner.scenario.load import loads

    clock = time.process_time if args.clock == "cpu" else time.perf_counter
    threads.set_threads(args.threads)
    with tempfile.TemporaryDirectory(prefix="collide2d-stepped-") as tmp:
        old = _old_model(args.rev, Path(tmp))
        for n in args.n or [1_000, 10_000, 100_000]:
            scene = loads(standard_scene(n, "stepped"))
            runs = {
                args.rev: old(scene.world, scene.bodies),
                "now": stepped.Model(scene.world, scene.bodies),
            }
            for model in runs.values():
                model.advance(3, log=False)  # load the kernels
            ticks = max(3, int(3e6 / n))
            spent = {name: [] for name in runs}
            for r in range(REPEATS):
                for name in runs if r % 2 == 0 else list(runs)[::-1]:
                    began = clock()
                    runs[name].advance(ticks, log=False)
                    spent[name].append((clock() - began) / ticks / n * 1e9)
            a, b = (statistics.median(v) for v in spent.values())
            same = all(
                np.array_equal(getattr(runs[args.rev], f)(), getattr(runs["now"], f)())
                for f in ("positions", "velocities")
            )
            print(
                f"n={n} threads={args.threads} ns/body-step ({args.clock}): {args.rev} {a:.1f}, "
                f"now {b:.1f}, {a / b:.2f}x; same bytes: {same}",
                flush=True,
            )


if __name__ == "__main__":
    main()
