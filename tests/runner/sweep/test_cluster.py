"""Sweeps and checks on process clusters as users start them: `collide2d sweep --workers 2`, and
a cluster of `dask scheduler` and two `dask worker` processes on 127.0.0.1, one of them killed
mid-sweep; every process started here is ended here."""

from __future__ import annotations

import io
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from interrupt import STARTED, interrupted

from collide2d.runner.sweep import driver, plan, results
from collide2d.runner.sweep.matrix import parse_set
from collide2d.runner.sweep.worker import run_one

distributed = pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[3]
SCENARIOS = ROOT / "scenarios"
FIFTY = str(SCENARIOS / "paper_fifty_boxes.yaml")
BIN = Path(sys.executable).parent
START_S = 60  # the longest a scheduler or worker may take to come up on a busy machine
SWEEP_S = 300  # the longest the sweep with a worker killed may take


def _cli(*args, cwd=ROOT, timeout=240):
    return subprocess.run(
        [str(BIN / "collide2d"), *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        stdin=subprocess.DEVNULL,
    )


def _without_wall_time(text: str) -> list[str]:
    return [line.rsplit(",", 1)[0] for line in text.splitlines()]


def test_sweep_on_the_default_local_cluster_matches_an_in_process_one(tmp_path, client):
    sweep_file = tmp_path / "matrix.yaml"
    sweep_file.write_text(
        f"sweep: 1\nscenarios: [{FIFTY}]\nset:\n  model: [exact, paper]\n  ticks: 40\nseeds: 1-2\n"
    )
    out = tmp_path / "out"
    done = _cli("sweep", str(sweep_file), "--workers", "2", "--out", str(out), "--quiet")
    assert done.returncode == 0, done.stderr
    assert done.stdout == "" and done.stderr == ""
    written = (out / "sweep" / "results.csv").read_text()
    axes = [parse_set("model=exact,paper"), parse_set("ticks=40")]
    table, _ = driver.run_sweep(client, plan.check([FIFTY], axes, (1, 2)))
    buf = io.StringIO()
    results.write_csv(buf, table.plan.columns, table.rows())
    mine = buf.getvalue()
    assert _without_wall_time(written) == _without_wall_time(mine)
    assert json.loads((out / "sweep" / "sweep.json").read_text())["complete"] is True


def test_a_sweep_prints_a_line_for_each_run_as_it_finishes(tmp_path):
    out = tmp_path / "out"
    done = _cli("sweep", FIFTY, "--set", "model=paper,stepped", "--set", "ticks=10", "--seeds",
                "1-2", "--workers", "1", "--out", str(out))
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    runs = [line for line in lines if line.startswith("sweep: [")]
    assert [line.split("]")[0] for line in runs] == [f"sweep: [{k}/4" for k in range(1, 5)]
    told = {line.split("] ", 1)[1].split(":")[0] for line in runs}
    assert told == {
        f"paper_fifty_boxes model={model} ticks=10 seed={seed}"
        for model in ("paper", "stepped") for seed in (1, 2)
    }
    assert all(": ok, " in line and "pair event" in line for line in runs)
    assert lines[-1].startswith("sweep: 4 runs -> ")


def test_check_on_a_cluster_says_what_a_local_check_says(tmp_path):
    root = tmp_path / "project"
    (root / "scenarios").mkdir(parents=True)
    for name in ("fig2_case1", "tunnelling_1fps"):
        shutil.copy(SCENARIOS / f"{name}.yaml", root / "scenarios")
        shutil.copytree(ROOT / "goldens" / name, root / "goldens" / name)
    # a golden that no longer matches: the cluster must report it as the local check does
    final = root / "goldens" / "tunnelling_1fps" / "final.csv"
    final.write_text(final.read_text().replace("0,220,115", "0,221,115", 1))
    local = _cli("check", "--root", str(root))
    remote = _cli("check", "--root", str(root), "--workers", "1")
    assert local.returncode == remote.returncode == 1
    assert remote.stdout == local.stdout
    assert local.stdout.startswith("ok      fig2_case1\n")
    assert "1 passed, 1 failed" in local.stdout


def _group_ends(pgid: int, within_s: float = 30.0) -> bool:
    """True once no process of the group is left (killing what is left after within_s)."""
    deadline = time.monotonic() + within_s
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    os.killpg(pgid, signal.SIGKILL)
    return False


def _start(*args, log: Path):
    return subprocess.Popen(
        [str(BIN / "dask"), *args],
        stdout=log.open("w"),
        stderr=subprocess.STDOUT,
        stdin=subprocess.DEVNULL,
        cwd=ROOT,
        start_new_session=True,
    )


def _stop(proc) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)


def test_a_worker_killed_mid_sweep_loses_no_row(tmp_path):
    addr_file = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(
            _start(
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(addr_file),
                log=tmp_path / "scheduler.log",
            )
        )
        deadline = time.monotonic() + START_S
        while not addr_file.is_file():
            assert time.monotonic() < deadline, (tmp_path / "scheduler.log").read_text()
            time.sleep(0.1)
        time.sleep(0.2)  # the file is written whole before the scheduler listens
        address = json.loads(addr_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        workers = {}
        for name in ("a", "b"):
            workers[name] = _start(
                "worker",
                address,
                "--host",
                "127.0.0.1",
                "--nthreads",
                "1",
                "--no-nanny",
                "--no-dashboard",
                "--name",
                name,
                log=tmp_path / f"worker-{name}.log",
            )
            procs.append(workers[name])
        checked = plan.check([FIFTY], [parse_set("ticks=4000")], tuple(range(1, 9)))
        killed = []

        def kill_a_busy_worker(run, row):
            if killed:
                return
            busy = [addr for addr, keys in client.processing().items() if keys]
            names = {a: w["name"] for a, w in client.scheduler_info()["workers"].items()}
            victim = names[busy[0]] if busy else "a"
            workers[victim].send_signal(signal.SIGKILL)
            killed.append((victim, bool(busy)))

        # were both workers to die the sweep would wait for ever: past SWEEP_S the whole cluster
        # is killed, and the sweep fails instead of hanging
        fired = []
        watchdog = threading.Timer(SWEEP_S, lambda: fired.append([p.kill() for p in procs]))
        watchdog.start()
        try:
            with distributed.Client(address, timeout=START_S) as client:
                client.wait_for_workers(2, timeout=START_S)
                table, complete = driver.run_sweep(client, checked, on_row=kill_a_busy_worker)
        finally:
            watchdog.cancel()
        assert not fired, f"the sweep took more than {SWEEP_S} s; the cluster was killed"
        ((victim, busy),) = killed  # a worker with a run in hand, killed while rows were missing
        assert busy and workers[victim].wait(timeout=30) == -signal.SIGKILL
        assert complete and table.done == len(checked)
        for run in checked.runs():
            want, _pos = run_one(checked.scenario(run))
            got = table.row(run)
            assert got["status"] == "ok"
            assert {k: v for k, v in got.items() if k in want and k != "run_time_s"} == {
                k: v for k, v in want.items() if k != "run_time_s"
            }
    finally:
        for proc in reversed(procs):
            _stop(proc)


@pytest.mark.parametrize("started", sorted(STARTED))
def test_ctrl_c_writes_the_rows_done_marked_incomplete(tmp_path, started):
    out = tmp_path / "out"
    first, proc, out_text, err_text = interrupted(
        started,
        [BIN / "collide2d", "sweep", FIFTY, "--set", "ticks=20000", "--seeds", "1-40",
         "--workers", "2", "--out", out],
        ROOT,
        wait_s=1.5,
    )  # fmt: skip
    assert first == "sweep: 40 runs on 2 local workers\n"  # printed once the cluster is up
    assert proc.returncode == 130, f"stdout: {out_text!r}; stderr: {err_text!r}"
    assert proc.took_s < 1.5, f"ended {proc.took_s:.2f} s after Ctrl-C"  # the cluster not awaited
    assert _group_ends(proc.pid), "a worker process outlived the sweep"
    assert "Traceback" not in err_text and "KeyboardInterrupt" not in err_text
    status = json.loads((out / "sweep" / "sweep.json").read_text())
    assert status["complete"] is False and status["done"] < 40
    rows = (out / "sweep" / "results.csv").read_text().splitlines()[1:]
    assert len(rows) == status["done"] == len({r.split(",")[1] for r in rows})
    assert f"cancelled; {status['done']} of 40 runs written, marked incomplete" in err_text
