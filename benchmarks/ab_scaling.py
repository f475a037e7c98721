"""`collide2d bench --part scaling` of two checkouts of this repository, A/B in one run.

Each checkout runs the bench with its own interpreter (its `.venv`), in turns: round r runs A
then B, round r + 1 B then A, so that a drift of the machine's speed shows in both alike. Each
bench row is itself the median of its repeats (steps/s of `collide2d run`, start-up subtracted);
this prints, per model and N, the median over the rounds of each checkout's steps/s and the ratio
B/A (above 1: B is faster). Usage:

    python benchmarks/ab_scaling.py A_DIR B_DIR [--rounds 3] [--model exact] [--n 1000] [--quick]

A_DIR and B_DIR are checkouts with an installed `.venv` (`pip install -e .`); `--model` and `--n`
repeat and go to the bench as they are. Under load the figures are noisy: read the ratios, and
run both in the same invocation.
"""

from __future__ import annotations

import argparse
import csv
import statistics
import subprocess
import tempfile
from pathlib import Path


def bench(checkout: Path, models: list[str], ns: list[int], quick: bool) -> dict:
    """{(model, n): steps/s} of one `collide2d bench --part scaling` of `checkout`."""
    with tempfile.TemporaryDirectory(prefix="collide2d-ab-") as out:
        cmd = [str(checkout / ".venv" / "bin" / "collide2d"), "bench", "--part", "scaling"]
        cmd += ["--quiet", "--out", out]
        cmd += [x for m in models for x in ("--model", m)]
        cmd += [x for n in ns for x in ("--n", str(n))]
        cmd += ["--quick"] if quick else []
        # (exit 1 says a section IV target was missed: the figures are written all the same)
        if subprocess.run(cmd, cwd=checkout).returncode not in (0, 1):
            raise SystemExit(f"the bench of {checkout} failed")
        with open(Path(out) / "bench" / "bench.csv", newline="") as f:
            return {
                (row["model"], int(row["n"])): float(row["steps_per_s"])
                for row in csv.DictReader(f)
                if row["part"] == "scaling"
            }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", type=Path)
    ap.add_argument("b", type=Path)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--model", action="append", default=[])
    ap.add_argument("--n", action="append", type=int, default=[])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    runs = {"A": [], "B": []}
    for r in range(args.rounds):
        order = ("A", "B") if r % 2 == 0 else ("B", "A")
        for which in order:
            checkout = args.a if which == "A" else args.b
            runs[which].append(bench(checkout.resolve(), args.model, args.n, args.quick))
            print(f"round {r + 1} {which}: {runs[which][-1]}", flush=True)
    print(f"\nA = {args.a}\nB = {args.b}\n{args.rounds} rounds, steps/s medians")
    print(f"{'model':8} {'n':>7} {'A':>12} {'B':>12} {'B/A':>6}")
    for key in sorted(runs["A"][0]):
        a = statistics.median(run[key] for run in runs["A"])
        b = statistics.median(run[key] for run in runs["B"])
        print(f"{key[0]:8} {key[1]:>7} {a:>12.1f} {b:>12.1f} {b / a:>6.3f}")


if __name__ == "__main__":
    main()
