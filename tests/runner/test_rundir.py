"""One run per output folder, whole: the lock, a full disk, and a swap cut at any step.

Each test runs a small scenario into OUT once, then tries to spoil the next run (another writer
holding the lock, a dead one that left it, a disk that fills up at the k-th write, a kill between
the renames of the swap) and checks that OUT/NAME holds one complete run and nothing else is left.
"""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from collide2d.runner.command.main import main
from collide2d.runner.output import files as outputs
from collide2d.runner.output import folder as rundir
from collide2d.runner.output import swap

ROOT = Path(__file__).resolve().parents[2]
SCENE = """version: 1
name: busy
world: {width: 60, height: 40, fps: 10}
ticks: %d
objects:
  - {shape: box, size: 6, position: [5, 5], velocity: [20, 10], color: red}
  - {shape: box, size: 6, position: [40, 20], velocity: [-10, 20], color: lime}
output: {frames: {every: 5}, gif: true, events: true}
"""


def files(folder: Path) -> dict[str, bytes]:
    """Every file under folder by its bytes, summary.json without how this run ran (its run time,
    and whether the kernels were compiled by then: under --jit auto that depends on the machine's
    load)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            data = p.read_bytes()
            if p.name == "summary.json":
                summary = json.loads(data)
                for key in ("run_time_s", "compile_time_s", "kernels"):
                    summary.pop(key, None)
                data = json.dumps(summary, sort_keys=True).encode()
            out[str(p.relative_to(folder))] = data
    return out


@pytest.fixture
def first(tmp_path):
    """(scenario of 20 ticks, one of 30, OUT) with the 20-tick run already in OUT/busy."""
    short, long = tmp_path / "short.yaml", tmp_path / "long.yaml"
    short.write_text(SCENE % 20)
    long.write_text(SCENE % 30)
    out = tmp_path / "out"
    assert main(["run", str(short), "--out", str(out), "--png", "--quiet"]) == 0
    return short, long, out


def test_a_second_run_on_a_held_folder_exits_2_naming_the_holder(first, capsys):
    short, long, out = first
    before = files(out / "busy")
    with rundir.RunLock(out, "busy"):
        assert main(["run", str(long), "--out", str(out), "--png", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"is being written by process {os.getpid()}" in err and err.startswith(f"{long}:")
    assert files(out / "busy") == before
    assert sorted(p.name for p in out.iterdir()) == ["busy"]  # the lock went with its holder
    assert main(["run", str(long), "--out", str(out), "--png", "--quiet"]) == 0  # free again
    assert json.loads((out / "busy" / "summary.json").read_text())["ticks"] == 30


def test_a_dead_writers_lock_is_taken_over(first):
    short, long, out = first
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; from pathlib import Path\n"
            "from collide2d.runner.output import folder as rundir\n"
            "with rundir.RunLock(Path(sys.argv[1]), 'busy'):\n"
            "    print('held', flush=True); time.sleep(60)",
            str(out),
        ],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "held"
        assert main(["run", str(long), "--out", str(out), "--quiet"]) == 2  # alive: refused
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert (out / ".busy.lock").read_text().strip() == str(holder.pid)  # left by the dead
    assert main(["run", str(long), "--out", str(out), "--png", "--quiet"]) == 0
    assert json.loads((out / "busy" / "summary.json").read_text())["ticks"] == 30
    assert sorted(p.name for p in out.iterdir()) == ["busy"]


class Disk:
    """Files the output writers open, as a disk that fills up at the `full_at`-th write (0-based;
    None: never). `paths` records the file each write went to."""

    def __init__(self, monkeypatch, full_at: int | None = None):
        self.full_at = full_at
        self.paths: list[str] = []
        disk = self
        real_init, real_open = outputs._StreamFile.__init__, open

        class File:
            def __init__(self, f, path):
                self.f, self.path = f, path

            def write(self, data):
                disk.paths.append(self.path)
                if len(disk.paths) - 1 == disk.full_at:
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                return self.f.write(data)

            def __getattr__(self, name):
                return getattr(self.f, name)

            def __enter__(self):
                return self

            def __exit__(self, *exc):
                self.f.close()

        def stream_init(self, path):
            real_init(self, path)
            self._file = File(self._file, str(self.path))

        def open_file(path, mode="r", *args, **kw):
            path = Path(path)
            return File(
                real_open(path, mode, *args, **kw),
                str(path.with_name(outputs.final_name(path.name))),
            )

        monkeypatch.setattr(outputs._StreamFile, "__init__", stream_init)
        monkeypatch.setattr(outputs, "open", open_file, raising=False)


def test_a_full_disk_at_any_write_keeps_the_old_run_and_names_the_file(first, capsys):
    short, long, out = first
    before = files(out / "busy")
    with pytest.MonkeyPatch.context() as mp:
        seen = Disk(mp).paths
        assert main(["run", str(long), "--out", str(out), "--png", "--quiet"]) == 0
    assert main(["run", str(short), "--out", str(out), "--png", "--quiet"]) == 0
    assert files(out / "busy") == before
    capsys.readouterr()
    kinds = {Path(p).name.split("_")[0]: k for k, p in enumerate(seen)}  # one write of each file
    assert {"animation.gif", "events.jsonl", "frame", "final.csv", "summary.json"} <= set(kinds)
    for k in sorted(set(kinds.values()) | {len(seen) - 1}):
        with pytest.MonkeyPatch.context() as mp:
            Disk(mp, full_at=k)
            assert main(["run", str(long), "--out", str(out), "--png", "--quiet"]) == 2
        err = capsys.readouterr().err
        inside = seen[k].split(".run.tmp/")[1]  # written in the staging folder, shown as OUT/NAME
        assert err == f"collide2d: error: {out / 'busy' / inside}: No space left on device\n"
        assert files(out / "busy") == before  # the old run, whole
        assert sorted(p.name for p in out.iterdir()) == ["busy"]  # no staging folder, no lock


def test_a_swap_cut_between_its_renames_is_finished_by_the_next_run(first, monkeypatch):
    short, long, out = first
    before = files(out / "busy")
    monkeypatch.setattr(swap, "exchange", lambda a, b: False)  # no atomic exchange here
    renames = [0]
    real_rename = os.rename

    def cut(a, b):
        renames[0] += 1
        if renames[0] >= 2:  # old moved aside, new not yet in: the process dies here
            raise KeyboardInterrupt
        return real_rename(a, b)

    monkeypatch.setattr(os, "rename", cut)
    with pytest.raises(KeyboardInterrupt):
        rundir.swap_in(rundir.new_stage(out, "busy"), out / "busy")
    monkeypatch.setattr(os, "rename", real_rename)
    assert not (out / "busy").exists()
    rundir.clean_leftovers(out, "busy")
    assert files(out / "busy") == before  # put back whole
    assert sorted(p.name for p in out.iterdir()) == ["busy"]
    assert main(["run", str(long), "--out", str(out), "--png", "--quiet"]) == 0
    assert json.loads((out / "busy" / "summary.json").read_text())["ticks"] == 30


def test_the_atomic_exchange_replaces_the_old_run_in_one_step(first, monkeypatch):
    short, long, out = first
    renames = []
    monkeypatch.setattr(os, "rename", lambda a, b: renames.append((a, b)))
    stage = rundir.new_stage(out, "busy")
    (stage / "final.csv").write_text("new\n")
    if not swap.exchange(stage, out / "busy"):
        pytest.skip("this system has no atomic exchange of names")
    assert (out / "busy" / "final.csv").read_text() == "new\n"
    assert (stage / "summary.json").exists()  # the old run, now under the staging name
    assert renames == []
