"""Where a cold kernel cache's seconds go: each kernel's own compile time, in one process.

Runs the project's scenarios (or the files given) compiled (`--jit on`) from an empty kernel
cache, in one fresh process, and reports the wall time and, per kernel, its specialisations and
the seconds numba spent compiling it, not counting the kernels it calls (those are their own
rows; a caller's time includes linking and optimising their code into its own), then the same
seconds per scenario (a kernel's seconds go to the scenario that compiled it first). The compile
time of the kernels is most of a cold test suite's and of a big scene's first run: this is the
script to run before and after a change that may add to it.

With `--suite`, the same for the test suite instead: plain `pytest` in one process from an empty
kernel cache (the README's test command; extra pytest arguments after `--`), the seconds summed
per test file, so that the tests whose kernels cost the most stand out. Compiles inside the
tests' own subprocesses are not counted; they show in the wall time only.

With `--table runner/data/compile_seconds.json`, it also writes the table `--jit auto` estimates a
run's compile time from (runner.compilecost): each kernel's CPU seconds per specialisation, measured
over the bundled scenarios and the bench's scenes (when no scenario is given), and the
calibration that scales it to the machine it runs on. Run it again after changing a kernel. Usage:

    python benchmarks/compile_time.py [SCENARIO ...] [--top 25] [--table JSON]
    python benchmarks/compile_time.py --suite [--top 25] [-- PYTEST_ARGS ...]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# Sizes of the bench's standard scene the table is measured on (each takes another broad phase).
TABLE_N = (30, 300, 3000)

# `listen(rows, where)` records (kernel, own seconds, where[0]) in rows for every compilation
# from then on: where[0] names what runs (a scenario, a test file).
LISTENER = """
import time


def listen(rows, where):
    from numba.core import event

    stack = []

    class Listen(event.Listener):
        def on_start(self, ev):
            func = ev.data["dispatcher"].py_func
            name = f"{func.__module__}.{func.__qualname__}"
            stack.append([name, time.perf_counter(), time.process_time(), 0.0, 0.0])

        def on_end(self, ev):
            name, began, began_cpu, inner, ours = stack.pop()
            took, cpu = time.perf_counter() - began, time.process_time() - began_cpu
            if stack:
                stack[-1][3] += took
                if name.startswith("collide2d."):
                    stack[-1][4] += cpu
            # own seconds; own CPU seconds with numba's helpers it compiled counted in
            rows.append((name, took - inner, where[0], cpu - ours))

    event.register("numba:compile", Listen())
"""

# Run in a fresh process with an empty cache: the scenarios, compiled.
CHILD = LISTENER + """
import json, sys
from collide2d.runner.command.main import main

from collide2d.runner import compilecost

rows, where = [], ["-"]
listen(rows, where)
out, paths = sys.argv[1], sys.argv[2:]
python_s = [min(compilecost.calibration() for _ in range(5))]
began = time.perf_counter()
for path in paths:
    where[0] = path
    status = main(["run", path, "--out", out, "--jit", "on", "--quiet", "--no-gif", "--no-png"])
    if status:
        raise SystemExit(f"{path}: exit {status}")
wall_s = time.perf_counter() - began
python_s.append(min(compilecost.calibration() for _ in range(5)))
print(json.dumps({"wall_s": wall_s, "rows": rows, "python_s": sum(python_s) / 2}))
"""

# A pytest plugin (module `collide2d_compile_log`): the listener, started once numba is loaded
# (a test may check that numba is not), each test's file as `where`, the rows written at the end.
PLUGIN = LISTENER + """
import json, os
import pytest
from collide2d.engine import jit

rows, where = [], ["(collection)"]
jit.when_loaded(lambda: listen(rows, where))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    where[0] = item.nodeid.split("::")[0]
    yield


def pytest_unconfigure(config):
    with open(os.environ["COLLIDE2D_COMPILE_LOG"], "w") as f:
        json.dump({"rows": rows}, f)
"""


def _scenarios(paths: list[str], tmp: Path, env: dict, result: dict) -> tuple[str, list]:
    """Run the scenarios compiled in a child process: (the summary line, the rows); the child's
    whole answer goes into `result`."""
    paths = paths or sorted(str(p) for p in (ROOT / "scenarios").glob("*.yaml"))
    done = subprocess.run(
        [sys.executable, "-c", CHILD, str(tmp / "out"), *paths],
        env=env, capture_output=True, text=True,
    )  # fmt: skip
    if done.returncode:
        raise SystemExit(done.stderr)
    result.update(json.loads(done.stdout.splitlines()[-1]))
    return f"{len(paths)} scenarios, compiled from an empty cache: {result['wall_s']:.1f} s wall", (
        result["rows"]
    )


def _suite(pytest_args: list[str], tmp: Path, env: dict) -> tuple[str, list, int]:
    """Run the test suite in one pytest process with the listener: (the summary line, the rows,
    pytest's exit status)."""
    (tmp / "collide2d_compile_log.py").write_text(PLUGIN)
    log = tmp / "compiles.json"
    env = dict(env, COLLIDE2D_COMPILE_LOG=str(log))
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(tmp), env.get("PYTHONPATH")]))
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
    command += ["-p", "collide2d_compile_log", *pytest_args]
    began = time.perf_counter()
    done = subprocess.run(command, cwd=ROOT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - began
    if not log.exists():
        raise SystemExit(done.stdout + done.stderr)
    lines = done.stdout.strip().splitlines() or ["(no output)"]
    for line in lines + done.stderr.splitlines():  # what failed or was refused, if anything
        if line.startswith(("FAILED", "ERROR")):
            print(line)
    last = lines[-1]
    summary = f"the suite in one process from an empty cache: {wall:.1f} s wall ({last})"
    return summary, json.loads(log.read_text())["rows"], done.returncode


def _table_scenes(tmp: Path) -> list[str]:
    """The scenes the table is measured on: the bundled scenarios, then the bench's standard scene
    under each model at sizes that take each broad phase, and its two-body chain."""
    from collide2d.runner.bench import scenes

    paths = sorted(str(p) for p in (ROOT / "scenarios").glob("*.yaml"))
    texts = [scenes.chain_scene(5)]
    for model in ("paper", "stepped", "exact"):
        texts += [scenes.standard_scene(n, model, 3) for n in TABLE_N]
    for k, text in enumerate(texts):
        path = tmp / f"table_scene_{k}.yaml"
        path.write_text(text)
        paths.append(str(path))
    return paths


def _write_table(path: Path, rows: list, python_s: float) -> None:
    """The table of runner.compilecost: each collide2d kernel's CPU seconds per specialisation
    (its own, with numba's helpers it compiled counted in)."""
    import numba

    seconds: dict[str, list[float]] = {}
    for name, _own, _where, cpu in rows:
        if name.startswith("collide2d."):
            seconds.setdefault(name, []).append(cpu)
    kernels = {name: round(sum(s) / len(s), 4) for name, s in sorted(seconds.items())}
    table = {"python_s": round(python_s, 6), "numba": numba.__version__, "kernels": kernels}
    path.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
    print(f"wrote {path}: {len(kernels)} kernels, calibration {python_s * 1e3:.1f} ms")


def _table(title: str, seconds: dict[str, list[float]], top: int) -> None:
    print(f"{'own s':>7}  {'specs':>5}  {title}")
    ranked = sorted(seconds.items(), key=lambda item: -sum(item[1]))
    for name, times in ranked[:top]:
        print(f"{sum(times):7.2f}  {len(times):5d}  {name}")


def main() -> None:
    from collide2d.runner.command.options import positive_int

    argv = sys.argv[1:]
    pytest_args = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", help="default: every file of scenarios/")
    parser.add_argument("--suite", action="store_true", help="the test suite, not scenarios")
    parser.add_argument("--top", type=positive_int, default=25, help="rows listed (default 25)")
    parser.add_argument(
        "--table", metavar="JSON", type=Path,
        help="also write runner.compilecost's table (from the bundled scenarios and the bench's "
        "scenes when no scenario is given), e.g. runner/data/compile_seconds.json",
    )  # fmt: skip
    args = parser.parse_args(argv)
    if args.suite and args.table:
        parser.error("--table measures scenarios, not the suite")
    if args.suite and args.scenarios:
        parser.error("--suite takes no scenarios (pytest arguments go after --)")
    if pytest_args and not args.suite:
        parser.error("arguments after -- are pytest's: they go with --suite")
    status = 0
    with tempfile.TemporaryDirectory(prefix="collide2d-compile-") as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"))
        env.pop("COLLIDE2D_JIT", None)
        if args.suite:
            summary, rows, status = _suite(pytest_args, Path(tmp), env)
        else:
            paths = args.scenarios or (_table_scenes(Path(tmp)) if args.table else [])
            child: dict = {}
            summary, rows = _scenarios(paths, Path(tmp), env, child)
            if args.table:
                _write_table(args.table, rows, child["python_s"])
    kernels: dict[str, list[float]] = {}
    places: dict[str, list[float]] = {}
    for name, seconds, where, *_ in rows:
        kernels.setdefault(name, []).append(seconds)
        places.setdefault(where, []).append(seconds)
    total = sum(row[1] for row in rows)
    print(f"{summary}, {total:.1f} s compiling {len(rows)} specialisations")
    _table("kernel", kernels, args.top)
    print()
    _table(f"{'test file' if args.suite else 'scenario'} (the kernels it compiled first)", places,
           args.top)  # fmt: skip
    raise SystemExit(status)  # pytest's, when it failed or found nothing to run


if __name__ == "__main__":
    main()
