"""Benchmark of `collide2d sweep` on Dask: the same sweep on 1 and 2 local workers and through a
local `dask scheduler`, against the runs done one after another in this process.

    python benchmarks/sweep_scaling.py [--runs 200] [--ticks 1000] [--repeats 3]

The sweep is RUNS runs of scenarios/paper_fifty_boxes.yaml at TICKS ticks (seeds 1..RUNS), each
run as a sweep worker does it (`runner.sweep.worker.run_one`: the per-tick checked run, then the
timed run). Figures, medians of REPEATS, clusters started and warmed up (every kernel loaded in
every worker) before timing, one cluster at a time, the serial runs timed between them,
reported as medians and as the fastest of the repeats:

- serial: the runs one after another in this process, no Dask;
- local N: `driver.run_sweep` on an embedded LocalCluster of N processes (N = 1, 2);
- scheduler: the same on a `dask scheduler` with two `dask worker` processes on 127.0.0.1;
- overhead per run: (local 1 - serial) / RUNS, what Dask adds to each run on one worker, and
  the scheduling alone: RUNS tasks that do nothing, per task;
- speed-up: local 1 / local 2.

Measure on a quiet machine: other work on the cores shows directly in the ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "paper_fifty_boxes.yaml"


def _runs(n: int, ticks: int):
    from collide2d.runner.sweep.matrix import expand, parse_set

    return expand([str(SCENARIO)], [parse_set(f"ticks={ticks}")], tuple(range(1, n + 1)))


def _first_run_s(scenario) -> float:
    from collide2d.runner.sweep.worker import run_one

    began = time.perf_counter()
    run_one(scenario)
    return time.perf_counter() - began


def _warm(client, runs) -> float:
    """Every worker runs one run first (imports done, kernels loaded); the slowest, in seconds."""
    return max(client.run(_first_run_s, runs[0].scenario).values())


def _nothing(i: int) -> int:
    return i


def _empty_s(client, n: int) -> float:
    """Seconds for n tasks that do nothing: the scheduling alone."""
    began = time.perf_counter()
    client.gather(client.map(_nothing, range(n), pure=False))
    return time.perf_counter() - began


def _sweep_s(client, runs) -> float:
    from collide2d.runner.sweep import driver

    began = time.perf_counter()
    figures, _pos, complete = driver.run_sweep(client, runs)
    assert complete and len(figures) == len(runs)
    return time.perf_counter() - began


def _scheduler_cluster(folder: Path, workers: int):
    """(address, processes) of a `dask scheduler` and `workers` `dask worker`s on 127.0.0.1."""
    dask = str(Path(sys.executable).parent / "dask")
    info = folder / "scheduler.json"
    procs = [
        subprocess.Popen(
            [dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(info)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
        )
    ]  # fmt: skip
    deadline = time.monotonic() + 60
    while not info.is_file():
        if time.monotonic() > deadline:
            raise TimeoutError("dask scheduler did not start")
        time.sleep(0.1)
    time.sleep(0.2)
    address = json.loads(info.read_text())["address"]
    for i in range(workers):
        procs.append(
            subprocess.Popen(
                [dask, "worker", address, "--host", "127.0.0.1", "--nthreads", "1",
                 "--no-dashboard", "--name", f"w{i}"],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
            )
        )  # fmt: skip
    return address, procs


def _stop(procs) -> None:
    for p in reversed(procs):
        os.killpg(p.pid, signal.SIGTERM)
        p.wait(timeout=30)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--ticks", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    from distributed import Client

    from collide2d.runner.sweep import cluster
    from collide2d.runner.sweep.worker import run_one

    began = time.perf_counter()
    runs = _runs(args.runs, args.ticks)
    matrix_s = time.perf_counter() - began
    run_one(runs[0].scenario)  # kernels loaded here too
    times: dict[str, list[float]] = {"serial": []}

    def serial() -> None:
        began = time.perf_counter()
        for r in runs:
            run_one(r.scenario)
        times["serial"].append(time.perf_counter() - began)

    first: list[float] = []

    def measure(name: str, client) -> None:
        first.append(_warm(client, runs))
        for _ in range(args.repeats):
            times.setdefault(name, []).append(_sweep_s(client, runs))
            times.setdefault(f"empty {name}", []).append(_empty_s(client, len(runs)))
        serial()  # between the setups, so that a busy spell shows in both

    # one cluster at a time: a second embedded cluster in this process slows the first's runs
    serial()
    for n in (1, 2):
        with cluster.connect(workers=n) as client:
            measure(f"local {n}", client)
    with tempfile.TemporaryDirectory() as folder:
        address, procs = _scheduler_cluster(Path(folder), 2)
        try:
            with Client(address, timeout=60) as client:
                client.wait_for_workers(2, timeout=60)
                measure("scheduler 2", client)
        finally:
            _stop(procs)
    print(
        f"{args.runs} runs of {SCENARIO.stem} at {args.ticks} ticks, {args.repeats} repeats, "
        f"{os.cpu_count()} cores (on a busy machine the fastest repeat is nearer the cost)"
    )
    print(f"matrix (load and check every run):  {matrix_s:8.3f} s")
    print(f"a fresh worker's first run:         {statistics.median(first):8.3f} s (median)")
    for way in (statistics.median, min):
        figures = {name: way(t) for name, t in times.items()}
        serial_s = figures.pop("serial")
        one, two = figures["local 1"], figures["local 2"]
        print(f"-- {way.__name__}")
        print(f"serial, in this process:            {serial_s:8.3f} s")
        for name, seconds in figures.items():
            if not name.startswith("empty"):
                print(f"{name + ' worker(s):':36s}{seconds:8.3f} s")
        for name, seconds in figures.items():
            if name.startswith("empty"):
                label = f"scheduling per task, {name[6:]}:"
                print(f"{label:36s}{seconds / args.runs * 1e3:8.2f} ms")
        print(f"speed-up, 2 workers over 1:         {one / two:8.2f} x")
        print(f"speed-up, scheduler 2 over local 1: {one / figures['scheduler 2']:8.2f} x")
        print(f"Dask overhead per run (1 worker):   {(one - serial_s) / args.runs * 1e3:8.2f} ms")
        print(f"per run, serial:                    {serial_s / args.runs * 1e3:8.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
