"""What a user notices on a first run and after: the compile notice and compile time apart from
run time, start-up that loads only the command's modules, `--version`, nothing on stderr when piped,
the tqdm progress bar, no empty frames/ folder, Ctrl-C keeping the run so far, object names in the
outputs, plurals."""

from __future__ import annotations

import fcntl
import io
import json
import os
import pty
import select
import signal
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import numba
import pytest

import collide2d
from collide2d.engine import jit
from collide2d.runner import compilecost, compiling
from collide2d.runner.command.compilenotice import CompileNotice
from collide2d.runner.command.main import main
from collide2d.runner.output import progress

ROOT = Path(__file__).resolve().parents[2]
SMALL = """version: 1
name: small
world: {width: 60, height: 40, fps: FPS}
ticks: TICKS
objects:
  - {name: left, shape: box, size: 6, position: [5, 5], velocity: [20, 0]}
  - {name: right, shape: box, size: 6, position: [40, 5], velocity: [-20, 0]}
  - {shape: box, size: 4, position: [5, 30], velocity: [10, 0]}
output: {frames: [8], gif: true, events: true}
"""


def small(tmp_path: Path, fps: int = 10, ticks: int = 40) -> Path:
    path = tmp_path / "small.yaml"
    path.write_text(SMALL.replace("FPS", str(fps)).replace("TICKS", str(ticks)))
    return path


def cli(*args, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "collide2d", *map(str, args)],
        capture_output=True,
        text=True,
        **kwargs,
    )


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
def test_compile_time_is_counted_once_per_compilation_and_the_watcher_hears_each_kernel():
    heard = []

    class Watcher:
        def begin(self, kernel):
            heard.append(("begin", kernel))

        def compiled(self, kernel):
            heard.append(("compiled", kernel))

        def end(self):
            heard.append(("end",))

    compiling.install(Watcher())
    jit.numba_module()  # numba loaded the engine's way, as a run loads it (the listener with it)
    before = compiling.seconds()

    @numba.njit  # not cached: compiles here
    def inner(x):
        return x + 1

    @numba.njit
    def outer(x):
        return inner(x) * 2

    started = time.perf_counter()
    assert outer(3) == 8
    took = time.perf_counter() - started
    assert 0 < compiling.seconds() - before <= took  # nested compilations counted once
    here = f"{__name__}.test_compile_time_is_counted_once_per_compilation_and_the_watcher_hears"
    name = here + "_each_kernel.<locals>."
    assert heard == [
        ("begin", name + "outer"),
        ("compiled", name + "inner"),
        ("compiled", name + "outer"),
        ("end",),
    ]
    outer(4)  # compiled: nothing more
    assert len(heard) == 4 and compiling.seconds() - before <= took
    compiling.install(None)


def test_summary_reports_compile_time_apart_from_run_time(tmp_path):
    proc = cli("run", small(tmp_path, ticks=10), "--out", tmp_path / "out")
    assert proc.returncode == 0 and proc.stderr == ""
    summary = json.loads((tmp_path / "out" / "small" / "summary.json").read_text())
    assert summary["compile_time_s"] >= 0 and 0 <= summary["run_time_s"] < 60
    assert "10 ticks under paper, 0 wall and 1 pair event in" in proc.stdout


def test_a_terminal_gets_the_compile_notice_unless_quiet(tmp_path, monkeypatch):
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    monkeypatch.setattr(sys, "stderr", Terminal())
    assert main(["run", str(small(tmp_path)), "--out", str(tmp_path / "o")]) == 0
    assert isinstance(compiling._state["watcher"], CompileNotice)
    assert main(["run", str(small(tmp_path)), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    assert compiling._state["watcher"] is None


@pytest.fixture
def cold_table(monkeypatch):
    """compilecost as on the table's machine, with no kernel in the wheel's store."""
    monkeypatch.setattr(compilecost, "speed_factor", lambda: 1.0)
    monkeypatch.setattr(compilecost.kernelstore, "holds", lambda name: False)
    monkeypatch.setitem(compiling._state, "expected", None)  # a lane's, of an earlier test
    return compilecost.table()["kernels"]


def test_the_notice_says_once_what_compiles_and_about_how_long(capsys, cold_table):
    stepped = ("collide2d.engine.models.stepped.", *compilecost.SHARED_KERNELS)
    expected = sum(s for name, s in cold_table.items() if name.startswith(stepped))
    assert expected > 30  # the stepped model and the shared modules, from an empty cache
    drawing = sum(s for name, s in cold_table.items() if name.startswith(compilecost.PICTURE))
    notice = CompileNotice()
    notice.begin("collide2d.engine.models.stepped.step.run")
    notice.end()
    notice.begin("collide2d.engine.models.stepped.settle.run")  # a later burst: said already
    notice.end()
    notice.begin("collide2d.engine.picture.pixels.draw")  # another kind of kernel
    notice.end()
    said = [line for line in capsys.readouterr().err.splitlines() if "first run" in line]
    assert said == [
        f"compiling the stepped model's kernels, first run only: about {expected:.0f} s "
        "(numba caches them for later runs) …",
        f"compiling the drawing kernels, first run only: about {drawing:.0f} s "
        "(numba caches them for later runs) …",
    ]
    run = "collide2d.engine.models.stepped.step.run"
    compiling.expect(12.4, {run})  # a run's lane switching to compiled knows what it called
    lane = CompileNotice()
    lane.begin(run)
    lane.end()
    assert "stepped model's kernels, first run only: about 12 s" in capsys.readouterr().err
    compiling.expect(0.0, {run})  # a lane whose kernels were all cached: not of this burst
    lane = CompileNotice()
    lane.begin("collide2d.engine.models.stepped.settle.run")
    lane.end()
    assert f"stepped model's kernels, first run only: about {expected:.0f} s" in (
        capsys.readouterr().err)
    CompileNotice().begin("")  # another process's (a sweep's worker), or a plugin's kernels
    assert capsys.readouterr().err == (
        "compiling kernels, first run only (numba caches them for later runs) …\n"
    )


def test_the_notice_bar_counts_the_kernels_compiled_against_the_estimate(cold_table):
    notice = CompileNotice()
    notice.begin("collide2d.engine.models.exact.model._run")
    bar = notice.bar
    assert bar is not None and bar.bar.total == round(compilecost.burst(
        "collide2d.engine.models.exact.model._run")[1])
    notice.compiled("collide2d.engine.models.exact.apply.rest_on")
    notice.compiled("collide2d.engine.models.exact.apply._settle")
    table = cold_table
    assert bar.done == round(table["collide2d.engine.models.exact.apply.rest_on"]
                             + table["collide2d.engine.models.exact.apply._settle"])
    for _ in range(200):  # more than expected: the bar stays short of full until the end
        notice.compiled("collide2d.engine.models.exact.model._run")
    assert bar.done == bar.bar.total - 1
    notice.end()
    assert notice.bar is None and bar not in progress._open
    notice.begin("boxflip.model.step")  # a plugin's kernels: no estimate, no bar
    assert notice.bar is None


def test_run_loads_only_the_modules_of_its_command(tmp_path):
    code = (
        "import sys, numpy\nby_numpy = set(sys.modules)\n"  # numpy < 2 imports numpy.ma itself
        "from collide2d.runner.command.main import main\n"
        f"assert main(['run', {str(small(tmp_path))!r}, '--out', {str(tmp_path / 'o')!r},"
        " '--quiet']) == 0\n"
        "print(sorted(m for m in sys.modules if m.startswith(('collide2d.runner.golden', "
        "'collide2d.runner.stress', 'collide2d.runner.bench', "
        "'collide2d.runner.command.newproject', "
        "'collide2d.engine.models.exact', 'collide2d.engine.models.stepped'))"
        " or m in {'numpy.ma', 'importlib.metadata'} - by_numpy))\n"
    )  # a run of a paper scene loads neither of the other models, nor what only costs start-up
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
    code = (
        "import sys\nfrom collide2d.runner.command.main import main\nmain(['config'])\n"
        "print('numba' in sys.modules)"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path
    )
    assert proc.stdout.splitlines()[-1] == "False"


def test_version(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out == f"collide2d {collide2d.__version__}\n"


def test_nothing_on_stderr_when_piped_even_the_gif_note(tmp_path):
    proc = cli("run", small(tmp_path, fps=200, ticks=40), "--out", tmp_path / "out")
    assert proc.returncode == 0
    assert proc.stderr == ""  # the GIF drops frames above 50 fps: a note only a terminal sees


def test_no_empty_frames_folder(tmp_path):
    # frame 8 is asked for, but --ticks makes the run 5 ticks long: no PNG, no frames/
    args = ["run", str(small(tmp_path)), "--out", str(tmp_path / "o"), "--ticks", "5"]
    assert main([*args, "--quiet"]) == 0
    folder = tmp_path / "o" / "small"
    assert (folder / "final.csv").is_file() and not (folder / "frames").exists()
    assert main([*args, "--quiet", "--png"]) == 0  # every frame, then
    assert len(list((folder / "frames").iterdir())) == 6


def test_names_appear_in_final_csv_and_events(tmp_path):
    assert main(["run", str(small(tmp_path)), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    folder = tmp_path / "o" / "small"
    rows = (folder / "final.csv").read_text().splitlines()
    assert rows[0] == "id,x,y,vx,vy,name"
    assert [r.split(",")[-1] for r in rows[1:]] == ["left", "right", ""]
    events = [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]
    pair = next(e for e in events if e["type"] == "pair")
    assert list(pair)[:7] == ["tick", "t", "type", "a", "a_name", "b", "b_name"]
    assert (pair["a_name"], pair["b_name"]) == ("left", "right")


def test_ctrl_c_keeps_the_run_so_far(tmp_path):
    path = small(tmp_path, fps=1000, ticks=1_000_000_000)
    text = path.read_text().replace("gif: true", "gif: false").replace("[8]", "none")
    path.write_text(text + "golden: {frames: [0]}\n")
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "collide2d",
            "run",
            str(path),
            "--out",
            str(out),
            "--max-ticks",
            "1000000000",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    # the run is ticking: the first chunk's events are in the staging folder (kernels compiled)
    while not any(p.stat().st_size for p in tmp_path.glob("out/.small.*.run.tmp/*")):
        assert time.monotonic() < deadline and proc.poll() is None
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    said, err = proc.communicate(timeout=120)
    assert proc.returncode == 130
    assert "interrupted at tick" in err and "holds the run so far" in err
    summary = json.loads((out / "small" / "summary.json").read_text())
    stopped = summary["interrupted_at_tick"]
    assert 0 < stopped < 1_000_000_000
    assert f"small: {stopped:,} of 1,000,000,000 ticks under" in said  # the ticks run
    events = [
        json.loads(line) for line in (out / "small" / "events.jsonl").read_text().splitlines()
    ]
    assert events and all(e["tick"] <= stopped for e in events)
    assert summary["events"]["wall"] + summary["events"]["pair"] == len(events)
    assert not (out / "small" / "animation.gif").exists()


DENSE = """version: 1
name: dense
world: {width: 700, height: 500, fps: 60}
model: stepped
ticks: 1000000
generate:
  - {count: 4000, shape: box, size: 5, speed: {min: 50, max: 200}, seed: 3}
output: {frames: none, gif: false, events: true}
"""


def test_ctrl_c_stops_a_dense_run_within_a_second_keeping_the_run_so_far(tmp_path):
    # a tick of 4,000 boxes takes about half a millisecond: a model call of tens of thousands of
    # ticks would hold Ctrl-C for half a minute; calls of about a quarter of a second do not, when
    # the quarter counts the writing of their many events too (which takes longer than the ticks)
    path = tmp_path / "dense.yaml"
    path.write_text(DENSE)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "collide2d", "run", str(path), "--out", str(out), "--quiet",
         "--jit", "on"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not any(p.stat().st_size for p in tmp_path.glob("out/.dense.*.run.tmp/*")):
            assert time.monotonic() < deadline and proc.poll() is None
            time.sleep(0.05)
        time.sleep(1.0)  # well into the run, past its first short calls
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=60)
        took = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130
    summary = json.loads((out / "dense" / "summary.json").read_text())
    assert 0 < summary["interrupted_at_tick"] < 1_000_000
    assert took < 1.5, f"the run went on {took:.1f} s after Ctrl-C"


def read_all(fd: int) -> bytes:
    """Everything waiting on fd: one read may return only part of what a terminal holds."""
    chunks = []
    while select.select([fd], [], [], 0.5)[0]:
        data = os.read(fd, 100_000)
        if not data:
            break
        chunks.append(data)
    return b"".join(chunks)


def test_the_progress_bar_fits_the_terminal_and_redraws_in_place(monkeypatch):
    monkeypatch.setattr(progress, "SHOW_AFTER_S", 0)
    monkeypatch.setattr(progress, "REDRAW_S", 0)
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 40, 0, 0))
    with os.fdopen(follower, "w") as stream:
        bar = progress.Progress(1000, "demo", stream)
        for done in range(0, 1001, 250):
            bar.update(done)
        bar.close()
        stream.flush()
        text = read_all(leader).decode()
    os.close(leader)
    draws = [d for d in text.split("\r") if d.strip()]
    assert "\n" not in text and len(draws) >= 4  # redrawn in place
    assert all(len(d) <= 40 for d in draws)  # within the terminal's 40 columns
    assert "demo" in draws[0] and "1000/1000" in "".join(draws)


def test_plurals(tmp_path, capsys):
    path = small(tmp_path, ticks=1)
    path.write_text(path.read_text().replace("[8]", "[1]"))
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 0
    assert "small: 1 tick under paper, 0 wall and 0 pair events" in capsys.readouterr().out
    assert main(["validate", str(path)]) == 0
    assert capsys.readouterr().out.endswith("ok (3 objects, model paper, 1 tick)\n")
