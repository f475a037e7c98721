"""Ctrl-C ends every command within a second, whatever it is running (docs/command-line.md,
"Progress and Ctrl-C"): a compiled chunk of ticks that runs on, a model plugin's advance() that
never gives control back, numba compiling kernels; and a run called from Python (a test of the
project's own suite) hands the Ctrl-C back to its caller, so that pytest stops too.

Each command is started in a process group of its own, as a terminal starts it, and gets SIGINT
once a line it prints (or a file it writes) says it is where the test wants it.
"""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import sys
import textwrap
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import pytest
from interrupt import STARTED

from collide2d.runner.command.main import main

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "boxflip"
SECOND = 1.5  # "within a second", with room for a busy machine
GIVE_UP_S = 10.0  # a command still running this long after Ctrl-C is killed: the test failed
READY_S = 120.0  # the most a command may take to get where the test wants it (a cold cache)
PYTEST_S = 5.0  # a pytest session, which has more to do on its way out (see its test)

SCENE = """version: 1
name: long
world: {width: 200, height: 100, fps: 100}
model: MODEL
ticks: TICKS
objects:
  - {shape: box, size: 10, position: [50, 50], velocity: [30, 7]}
  - {shape: box, size: 10, position: [150, 50], velocity: [-20, -9]}
output: {frames: none, gif: false, events: EVENTS}
"""
LONG = 2_000_000_000


def scene(
    tmp_path: Path, model: str = "paper", ticks: int = LONG, name: str = "long", events=True
) -> Path:
    path = tmp_path / f"{name}.yaml"
    text = SCENE.replace("MODEL", model).replace("TICKS", str(ticks))
    path.write_text(text.replace("EVENTS", "true" if events else "false"))
    return path


def ticking(out: Path, name: str = "long"):
    """Whether a run into OUT is under way: its first chunk's events are in its staging folder."""
    return lambda _err: any(p.stat().st_size for p in out.glob(f".{name}.*.run.tmp/*"))


def previous_run(out: Path, name: str = "long") -> Path:
    """OUT/NAME as a previous run left it (the files a run writes, with text of their own)."""
    folder = out / name
    folder.mkdir(parents=True)
    (folder / "final.csv").write_text("the previous run\n")
    (folder / "summary.json").write_text('{"previous": true}\n')
    return folder


def leftovers(out: Path) -> list[str]:
    """What a run leaves in OUT beside the run folders: staging folders, temporaries, locks."""
    return sorted(p.name for p in out.iterdir() if p.name.startswith("."))


def plugin(tmp_path: Path, source: str) -> dict:
    """The environment of a process that has the model `stuck` of `source` (module stuck.py) and
    the example plugin installed, as `pip install` of a plugin would leave them."""
    site = tmp_path / "site"
    info = site / "stuck_plugin-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: stuck-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[collide2d.models]\nstuck = stuck:Stuck\n")
    (site / "stuck.py").write_text(textwrap.dedent(source))
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(EXAMPLE)])}


@dataclass
class Stopped:
    """A command that got Ctrl-C: seconds from the signal to its end, exit status, output."""

    took: float
    returncode: int
    out: str
    err: str


def _pump(stream, lines: queue.Queue) -> None:
    for line in stream:
        lines.put((stream, line))


def interrupted(cmd, *, when, env=None, started="foreground", cwd=ROOT, after_s=0.0) -> Stopped:
    """Run `cmd` in a group of its own; once `when(stderr_so_far)` is true (and `after_s` more
    seconds), send SIGINT to the group as a terminal's Ctrl-C does, and time how long the command
    takes to end."""
    proc = subprocess.Popen(
        [*STARTED[started], *map(str, cmd)],
        cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL, text=True, start_new_session=True,
    )  # fmt: skip
    lines: queue.Queue = queue.Queue()
    readers = [
        threading.Thread(target=_pump, args=(s, lines), daemon=True)
        for s in (proc.stdout, proc.stderr)
    ]
    for reader in readers:
        reader.start()
    said = {proc.stdout: [], proc.stderr: []}
    try:
        deadline = time.monotonic() + READY_S
        while not when("".join(said[proc.stderr])):
            assert time.monotonic() < deadline, f"never ready: {said[proc.stderr]}"
            assert proc.poll() is None, f"ended before Ctrl-C: {said[proc.stderr]}"
            try:
                stream, line = lines.get(timeout=0.05)
                said[stream].append(line)
            except queue.Empty:
                pass
        time.sleep(after_s)
        sent = time.monotonic()
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=GIVE_UP_S)
        except subprocess.TimeoutExpired:
            pytest.fail(f"still running {GIVE_UP_S:.0f} s after Ctrl-C: {said[proc.stderr]}")
        took = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    for reader in readers:
        reader.join(timeout=5)
    while not lines.empty():
        stream, line = lines.get()
        said[stream].append(line)
    return Stopped(took, proc.returncode, "".join(said[proc.stdout]), "".join(said[proc.stderr]))


def saying(text: str):
    return lambda err: text in err


# The first chunk of ticks of a run is one call of the model: made a billion ticks long here, as a
# scene whose ticks turn costly all at once (a pile landing) makes one call far longer than the
# quarter of a second the chunks aim at. The kernels are loaded by a short run first, and no event
# is logged (the paper model's kernel comes back to Python to grow its event log), so that the
# call is the compiled kernel itself, all of it, when Ctrl-C comes.
LONG_CHUNK = """
import sys
from collide2d.runner import run
from collide2d.runner.command.main import main

warm, out, *command = sys.argv[1:]
assert main(["run", warm, "--out", out, "--quiet", "--jit", "on"]) == 0
run.FIRST_CHUNK_TICKS = 10**9
made = run.make_model

def make_model(scenario):
    model = made(scenario)
    advance = model.advance

    def advancing(ticks, log=True):
        print(f"advancing {ticks} ticks", file=sys.stderr, flush=True)
        return advance(ticks, log)

    model.advance = advancing
    return model

run.make_model = make_model
sys.argv = ["collide2d", *command]
sys.exit(main())
"""


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
@pytest.mark.parametrize("started", sorted(STARTED))
def test_a_compiled_chunk_that_runs_on_is_cut_within_a_second(tmp_path, started):
    out = tmp_path / "out"
    before = previous_run(out)
    warm = scene(tmp_path, ticks=20, name="warm")
    long = scene(tmp_path, events=False)
    cmd = [sys.executable, "-c", LONG_CHUNK, warm, tmp_path / "warm", "run", long]
    cmd += ["--out", out, "--jit", "on", "--quiet", "--max-ticks", LONG]
    # the line is printed just before the call: a moment later, the kernel runs
    stop = interrupted(cmd, when=saying("advancing 1000000000 ticks"), started=started, after_s=0.5)
    assert stop.returncode == 130, stop.err
    assert stop.took < SECOND, f"ended {stop.took:.2f} s after Ctrl-C"
    assert "did not stop within" in stop.err and f"{before} is as it was" in stop.err, stop.err
    assert "Traceback" not in stop.err
    assert (before / "final.csv").read_text() == "the previous run\n"  # the previous run, whole
    assert sorted(p.name for p in before.iterdir()) == ["final.csv", "summary.json"]
    assert leftovers(out) == []


LOOPS = """
import sys
from boxflip import BoxFlip

class Stuck(BoxFlip):
    def advance(self, ticks, log=True):
        if self.tick > 0:
            print(f"stuck at tick {self.tick}", file=sys.stderr, flush=True)
            while True:
                pass
        return super().advance(ticks, log)
"""


def test_a_plugin_that_never_returns_is_stopped_at_once_keeping_the_run_so_far(tmp_path):
    """Ctrl-C inside a model's advance() stops the run there: the outputs are the run up to the
    last whole chunk of ticks, as at the end of a chunk."""
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "collide2d", "run", scene(tmp_path, model="stuck")]
    cmd += ["--out", out, "--max-ticks", LONG]
    stop = interrupted(cmd, when=saying("stuck at tick"), env=plugin(tmp_path, LOOPS))
    assert stop.returncode == 130, stop.err
    assert stop.took < SECOND, f"ended {stop.took:.2f} s after Ctrl-C"
    tick = int(stop.err.split("stuck at tick ")[1].split()[0])
    assert f"interrupted at tick {tick:,} of {LONG:,}; {out / 'long'} holds the run so far" in (
        stop.err
    )
    summary = json.loads((out / "long" / "summary.json").read_text())
    assert summary["interrupted_at_tick"] == tick
    events = [json.loads(x) for x in (out / "long" / "events.jsonl").read_text().splitlines()]
    assert all(e["tick"] <= tick for e in events)
    assert leftovers(out) == []


# A plugin that takes Ctrl-C's KeyboardInterrupt for itself and goes on (a bare `except:` in a
# retry loop), or that sits in C code that holds on to it.
SWALLOWS = """
import sys
from boxflip import BoxFlip

class Stuck(BoxFlip):
    def advance(self, ticks, log=True):
        said = self.tick == 0
        while not said:
            try:
                print(f"stuck at tick {self.tick}", file=sys.stderr, flush=True)
                said = True
                while True:
                    pass
            except BaseException:
                pass
        while self.tick > 0:
            try:
                while True:
                    pass
            except BaseException:
                pass
        return super().advance(ticks, log)
"""


@pytest.mark.parametrize("started", sorted(STARTED))
def test_a_plugin_that_keeps_ctrl_c_to_itself_is_cut_within_a_second(tmp_path, started):
    out = tmp_path / "out"
    before = previous_run(out)
    cmd = [sys.executable, "-m", "collide2d", "run", scene(tmp_path, model="stuck")]
    cmd += ["--out", out, "--max-ticks", LONG]
    env = plugin(tmp_path, SWALLOWS)
    stop = interrupted(cmd, when=saying("stuck at tick"), env=env, started=started)
    assert stop.returncode == 130, stop.err
    assert stop.took < SECOND, f"ended {stop.took:.2f} s after Ctrl-C"
    assert "did not stop within" in stop.err and f"{before} is as it was" in stop.err, stop.err
    assert (before / "final.csv").read_text() == "the previous run\n"
    assert leftovers(out) == []


def test_check_is_cut_within_a_second_too(tmp_path):
    """`check` raises KeyboardInterrupt where Python runs: a plugin that takes it for itself
    does not hold the command."""
    (tmp_path / "scenarios").mkdir()
    scene(tmp_path / "scenarios", model="stuck", ticks=1000)
    cmd = [sys.executable, "-m", "collide2d", "check"]
    stop = interrupted(cmd, when=saying("stuck at tick"), env=plugin(tmp_path, SWALLOWS),
                       cwd=tmp_path)  # fmt: skip
    assert stop.returncode == 130, stop.err
    assert stop.took < SECOND, f"ended {stop.took:.2f} s after Ctrl-C"
    assert "did not stop within" in stop.err


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
@pytest.mark.parametrize("command", ["run", "check"])
def test_ctrl_c_while_kernels_compile_ends_the_command_within_a_second(tmp_path, command):
    """From an empty kernel cache (a first run), Ctrl-C once numba has cached a kernel: for `run`,
    one of the stepped model's own, compiled in its first call of advance() (the world's and the
    shapes' kernels come before it), with more of them still compiling."""
    cache = tmp_path / "numba"
    cache.mkdir()
    project = tmp_path / "project"
    (project / "scenarios").mkdir(parents=True)
    path = scene(project / "scenarios", model="stepped", ticks=1000)
    cmd = [sys.executable, "-m", "collide2d", command, "--jit", "on"]
    if command == "run":
        cmd += [path, "--out", tmp_path / "out", "--quiet"]
    cached = "stepped*/*.nbi" if command == "run" else "*/*.nbi"  # one folder per package
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "COLLIDE2D_KERNEL_STORE": "off"}
    stop = interrupted(cmd, when=lambda _err: any(cache.glob(cached)), env=env, cwd=project)
    assert stop.returncode == 130, stop.err
    assert stop.took < SECOND, f"ended {stop.took:.2f} s after Ctrl-C"
    assert "Traceback" not in stop.err
    if command == "run":
        assert "interrupted at tick 0 of 1,000" in stop.err  # it was in the first advance()
        assert leftovers(tmp_path / "out") == []


class _SigintAt:
    """A model whose advance() sends this process SIGINT once its tick reaches `at`, as a
    Ctrl-C pressed while a test runs."""

    def __init__(self, model, at: int):
        self.model, self.at = model, at

    def __getattr__(self, name):
        return getattr(self.model, name)

    def advance(self, ticks, log=True):
        if self.model.tick >= self.at:
            os.kill(os.getpid(), signal.SIGINT)
        return self.model.advance(ticks, log)


@pytest.fixture
def sigint_at_tick_32(monkeypatch):
    from collide2d.runner import run

    made = run.make_model
    monkeypatch.setattr(run, "make_model", lambda scenario: _SigintAt(made(scenario), 32))


def test_a_run_called_from_python_hands_ctrl_c_back_to_its_caller(
    tmp_path, sigint_at_tick_32, capsys
):
    """`main([...])` and `collide2d.run(..., out=...)` called from Python keep the run so far, as
    the command does, then raise KeyboardInterrupt: the program (a pytest session) stops too."""
    import collide2d

    path = scene(tmp_path, ticks=100_000)
    with pytest.raises(KeyboardInterrupt):
        main(["run", str(path), "--out", str(tmp_path / "cli"), "--quiet", "--jit", "off"])
    assert "holds the run so far" in capsys.readouterr().err
    summary = json.loads((tmp_path / "cli" / "long" / "summary.json").read_text())
    assert 32 <= summary["interrupted_at_tick"] < 100_000

    with pytest.raises(collide2d.RunInterrupted) as stop:
        collide2d.run(str(path), out=tmp_path / "api")
    assert isinstance(stop.value, KeyboardInterrupt)
    assert stop.value.folder == tmp_path / "api" / "long"
    assert stop.value.summary == json.loads((stop.value.folder / "summary.json").read_text())
    assert 32 <= stop.value.summary["interrupted_at_tick"] < 100_000


SUITE = """
from collide2d.runner.command.main import main

def test_first():
    assert main(["run", "LONG", "--out", "OUT", "--quiet", "--max-ticks", "MAX"]) == 0

def test_second():
    open("SECOND", "w").close()
"""


def test_pytest_stops_on_ctrl_c_during_a_run_a_test_makes(tmp_path):
    """A test of the suite that runs the command in its own process: Ctrl-C stops the run, the
    test and the session; the next test never starts."""
    second, out = tmp_path / "second-ran", tmp_path / "out"
    test = tmp_path / "test_suite.py"
    text = SUITE.replace("LONG", str(scene(tmp_path))).replace("MAX", str(LONG))
    test.write_text(text.replace("SECOND", str(second)).replace("OUT", str(out)))
    cmd = [sys.executable, "-m", "pytest", "-q", "-s", "-p", "no:cacheprovider", test]
    stop = interrupted(cmd, when=ticking(out), cwd=tmp_path)
    assert stop.returncode == 2, stop.out  # pytest's "interrupted"
    assert not second.exists()
    assert "holds the run so far" in stop.err
    # the run stops within a second; pytest then reports where the interrupt came from (it parses
    # the source of each frame) and Python exits (numba loaded): more seconds on a busy machine
    assert stop.took < PYTEST_S, f"ended {stop.took:.2f} s after Ctrl-C"


KEEPS_IT = """
import sys
import time

def test_first():
    print("first test running", file=sys.stderr, flush=True)
    deadline = time.monotonic() + 1.5
    while time.monotonic() < deadline:
        try:
            time.sleep(0.05)
        except KeyboardInterrupt:
            pass  # a library that keeps Ctrl-C to itself

def test_second():
    open("SECOND", "w").close()
"""


def test_pytest_stops_after_a_test_that_keeps_ctrl_c_to_itself(tmp_path):
    """The project's conftest (tests/conftest.py) ends the session once that test is over."""
    suite, second = tmp_path / "suite", tmp_path / "second-ran"
    suite.mkdir()
    (suite / "conftest.py").write_text((ROOT / "tests" / "conftest.py").read_text())
    (suite / "test_suite.py").write_text(KEEPS_IT.replace("SECOND", str(second)))
    cmd = [sys.executable, "-m", "pytest", "-q", "-s", "-p", "no:cacheprovider", suite]
    stop = interrupted(cmd, when=saying("first test running"), cwd=suite)
    assert stop.returncode == 2, stop.out  # pytest's "interrupted"
    assert not second.exists()
    assert stop.took < PYTEST_S, f"ended {stop.took:.2f} s after Ctrl-C"


DROPS_IT = """
import os
import signal
import time

class Freed:
    def __del__(self):
        os.kill(os.getpid(), signal.SIGINT)  # handled at the next bytecode: still in here
        for _ in range(1000):
            pass

def test_first():
    Freed()  # freed at once: Python drops the KeyboardInterrupt raised in its finalizer
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        time.sleep(0.01)

def test_second():
    open("SECOND", "w").close()
"""


def test_pytest_raises_a_ctrl_c_that_python_dropped_again(tmp_path):
    """A Ctrl-C that lands where Python drops the KeyboardInterrupt (a finalizer; numba's compiler
    also calls Python from ctypes callbacks) is raised again a moment later: the session stops
    at once, not when the test is over."""
    suite, second = tmp_path / "suite", tmp_path / "second-ran"
    suite.mkdir()
    (suite / "conftest.py").write_text((ROOT / "tests" / "conftest.py").read_text())
    (suite / "test_suite.py").write_text(DROPS_IT.replace("SECOND", str(second)))
    began = time.monotonic()
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", suite]
    proc = subprocess.run(cmd, cwd=suite, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stdout  # pytest's "interrupted"
    assert not second.exists()
    assert time.monotonic() - began < 15, "the test ran on"  # its loop lasts 30 s


def test_the_watchdog_exits_with_the_status_of_ctrl_c():
    from collide2d.runner import interrupt
    from collide2d.runner.command import exitcodes

    assert interrupt.EXIT_INTERRUPTED == exitcodes.EXIT_INTERRUPTED == 130
