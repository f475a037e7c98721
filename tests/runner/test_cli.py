"""The `collide2d` command line: one test per option of `run`, exit codes, located errors, and
nothing written for a refused scenario."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from interrupt import STARTED, interrupted

from collide2d.runner.command.main import demo_path, main

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"
TUNNEL = str(SCENARIOS / "tunnelling_10fps.yaml")


def run(args):
    return main(["run", *map(str, args)])


def files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}


def test_no_argument_runs_the_bundled_demo_and_writes_its_gif(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert run([]) == 0
    folder = tmp_path / "out" / "paper_fifty_boxes"
    gif = iio.imread(folder / "animation.gif", index=None)
    assert gif.shape[0] == 101  # frames 0..100 at 10 fps
    assert "paper_fifty_boxes" in capsys.readouterr().out


def test_the_bundled_demo_is_the_scenario_in_the_corpus():
    assert Path(demo_path()).read_bytes() == (SCENARIOS / "paper_fifty_boxes.yaml").read_bytes()


def test_out_names_the_folder(tmp_path):
    assert run([TUNNEL, "--out", tmp_path / "elsewhere", "--quiet"]) == 0
    assert (tmp_path / "elsewhere" / "tunnelling_10fps" / "final.csv").is_file()


def test_gif_and_no_gif(tmp_path):
    run([TUNNEL, "--out", tmp_path, "--no-gif", "--quiet"])
    assert not (tmp_path / "tunnelling_10fps" / "animation.gif").exists()
    run([TUNNEL, "--out", tmp_path, "--gif", "--quiet"])
    assert (tmp_path / "tunnelling_10fps" / "animation.gif").is_file()


def test_png_writes_the_scenarios_frames_and_no_png_none(tmp_path):
    run([TUNNEL, "--out", tmp_path, "--png", "--quiet"])
    frames = sorted(p.name for p in (tmp_path / "tunnelling_10fps" / "frames").iterdir())
    assert frames == [f"frame_{k:06d}.png" for k in range(0, 121, 10)]  # output.frames every 10
    run([TUNNEL, "--out", tmp_path, "--no-png", "--quiet"])
    assert list((tmp_path / "tunnelling_10fps" / "frames").glob("*.png")) == []


def test_png_on_a_scenario_that_asks_for_no_frames_writes_them_all(tmp_path):
    src = (SCENARIOS / "tunnelling_1fps.yaml").read_text().replace("frames: all", "frames: none")
    path = tmp_path / "t1.yaml"
    path.write_text(src)
    run([path, "--out", tmp_path, "--png", "--quiet"])
    assert len(list((tmp_path / "t1" / "frames").glob("*.png"))) == 13


def test_events_and_no_events(tmp_path):
    run([TUNNEL, "--out", tmp_path, "--no-events", "--quiet"])
    assert not (tmp_path / "tunnelling_10fps" / "events.jsonl").exists()
    run([TUNNEL, "--out", tmp_path, "--events", "--quiet"])
    lines = (tmp_path / "tunnelling_10fps" / "events.jsonl").read_text().splitlines()
    first = json.loads(lines[0])
    assert first == {
        "tick": 51,
        "t": 5.1,
        "type": "pair",
        "a": 0,
        "a_name": "left",  # the scenario names its objects
        "b": 1,
        "b_name": "right",
        "axis": "x",
        "xdiff": 2,
        "ydiff": 10,
    }


def test_fps_changes_the_outcome_tunnelling_at_1_fps(tmp_path):
    run([TUNNEL, "--out", tmp_path, "--fps", "1", "--ticks", "12", "--quiet"])
    summary = json.loads((tmp_path / "tunnelling_10fps" / "summary.json").read_text())
    assert summary["fps"] == 1 and summary["ticks"] == 12
    assert summary["events"]["pair"] == 0


def test_ticks_sets_the_length(tmp_path):
    run([TUNNEL, "--out", tmp_path, "--ticks", "30", "--quiet"])
    summary = json.loads((tmp_path / "tunnelling_10fps" / "summary.json").read_text())
    assert summary["ticks"] == 30
    rows = (tmp_path / "tunnelling_10fps" / "final.csv").read_text().splitlines()
    assert rows[0] == "id,x,y,vx,vy,name"  # the scenario names its objects
    assert rows[1].split(",") == ["0", "130", "115", "10", "0", "left"]  # id 0 at 100 + 30 px


def test_model_is_checked_again_under_the_new_model(tmp_path, capsys):
    src = tmp_path / "floaty.yaml"
    src.write_text(
        "version: 1\nmodel: stepped\nticks: 5\nobjects:\n"
        "  - {shape: box, size: 10, position: [10.5, 20], velocity: [3, 0]}\n"
    )
    assert run([src, "--out", tmp_path / "ok", "--quiet"]) == 0
    assert run([src, "--out", tmp_path / "no", "--model", "paper", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{src}:5:") and "--model paper" in err and "error:" in err
    assert not (tmp_path / "no").exists()


def test_scale_enlarges_png_and_gif(tmp_path):
    run([TUNNEL, "--out", tmp_path, "--png", "--scale", "3", "--quiet"])
    png = iio.imread(tmp_path / "tunnelling_10fps" / "frames" / "frame_000000.png")
    assert png.shape == (720, 960, 3)
    gif = iio.imread(tmp_path / "tunnelling_10fps" / "animation.gif", index=0)
    assert gif.shape[:2] == (720, 960)


def test_quiet_prints_nothing(tmp_path, capsys):
    run([TUNNEL, "--out", tmp_path, "--quiet"])
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""


@pytest.mark.parametrize(
    "flag, value, needle",
    [
        ("--max-objects", 1, "objects"),
        ("--max-ticks", 10, "ticks"),
        ("--max-side", 100, "side"),
        ("--max-output-bytes", 1000, "output"),
    ],
)
def test_limits_refuse_with_exit_2_and_write_nothing(tmp_path, capsys, flag, value, needle):
    code = run([TUNNEL, "--out", tmp_path, flag, value, "--quiet"])
    assert code == 2
    err = capsys.readouterr().err
    assert "error:" in err and needle in err
    assert files(tmp_path) == set()


def test_a_bad_scenario_is_refused_with_its_location_and_nothing_written(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "version: 1\nworld: {width: 100, height: 100}\nobjects:\n"
        "  - {shape: box, size: 10, position: [0, 0], velocty: [1, 0]}\n"
    )
    out = tmp_path / "out"
    assert run([bad, "--out", out]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{bad}:4:")
    assert "velocity" in err  # the near spelling
    assert not out.exists()


def test_unknown_option_is_a_usage_error():
    with pytest.raises(SystemExit) as exc:
        main(["run", "--frobnicate"])
    assert exc.value.code == 2


def test_same_scenario_same_bytes(tmp_path):
    for name in ("a", "b"):
        run([SCENARIOS / "shapes_showcase.yaml", "--out", tmp_path / name, "--png", "--quiet"])
    a, b = tmp_path / "a" / "shapes_showcase", tmp_path / "b" / "shapes_showcase"
    assert files(a) == files(b)
    for rel in files(a) - {"summary.json"}:
        assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
    # all but how the run went (docs/outputs.md): its two timings, and its kernels' lanes (the
    # second run in one process goes on compiled once the first has compiled them)
    for key in ("run_time_s", "compile_time_s", "kernels"):
        sa.pop(key), sb.pop(key)
    assert sa == sb


def test_python_dash_m_runner_is_the_same_command(tmp_path):
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "runner",
            "run",
            TUNNEL,
            "--out",
            str(tmp_path),
            "--quiet",
            "--no-gif",
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "tunnelling_10fps" / "final.csv").is_file()


def test_a_rerun_with_fewer_outputs_leaves_only_its_own(tmp_path):
    run([TUNNEL, "--out", tmp_path, "--png", "--quiet"])
    run([TUNNEL, "--out", tmp_path, "--no-png", "--no-gif", "--no-events", "--quiet"])
    assert files(tmp_path / "tunnelling_10fps") == {"final.csv", "summary.json"}


def test_output_folder_that_is_a_link_is_refused(tmp_path, capsys):
    target = tmp_path / "outside"
    target.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "tunnelling_10fps").symlink_to(target, target_is_directory=True)
    assert run([TUNNEL, "--out", out, "--quiet"]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert list(target.iterdir()) == []


@pytest.mark.parametrize("path", sorted(SCENARIOS.glob("*.yaml")), ids=lambda p: p.stem)
def test_every_scenario_runs_end_to_end(tmp_path, path):
    assert run([path, "--out", tmp_path, "--png", "--quiet"]) == 0
    folder = next(tmp_path.iterdir())
    summary = json.loads((folder / "summary.json").read_text())
    # the columns id, x, y, vx, vy (and name when the scenario names objects)
    final = np.loadtxt(folder / "final.csv", delimiter=",", skiprows=1, ndmin=2, usecols=range(5))
    assert final.shape[0] == summary["objects"]
    assert np.isfinite(final).all()
    assert (folder / "animation.gif").is_file() and list((folder / "frames").glob("*.png"))


# ----------------------------------------------------------------------------- runaways

GALPERIN = ROOT / "tests" / "runner" / "data" / "galperin_pi.yaml"


def test_galperin_billiard_counts_pi_to_seven_digits_from_the_command_line(tmp_path):
    """Mass ratio 10^12: 3,141,592 collisions, about 1.57 million in each of two ticks, past the
    default cap: the scenario raises it in its model options; counted with no event log."""
    out = subprocess.run(
        [sys.executable, "-m", "collide2d", "run", str(GALPERIN), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    folder = tmp_path / "galperin-pi"
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["events"]["wall"] + summary["events"]["pair"] == 3_141_592
    assert "1,570,796 wall and 1,570,796 pair events" in out.stdout
    assert not (folder / "events.jsonl").exists()


def galperin_small(tmp_path, model_line):
    text = GALPERIN.read_text().replace("mass: 1e12", "mass: 1e6")
    text = text.replace("model: {kind: exact, max_events_per_tick: 4000000}", model_line)
    path = tmp_path / "g.yaml"
    path.write_text(text)
    return path


def test_the_cap_comes_from_the_command_line_over_the_scenario(tmp_path, capsys):
    """3141 collisions, 1,571 of them in tick 9: a cap of 1,000 stops the run, from the
    scenario's model options or from --max-events-per-tick, which wins."""
    capped = galperin_small(tmp_path, "model: {kind: exact, max_events_per_tick: 1000}")
    assert run([capped, "--out", tmp_path / "a", "--quiet"]) == 2
    assert "tick 9 needed more than 1000 events" in capsys.readouterr().err
    assert run([capped, "--out", tmp_path / "b", "--quiet", "--max-events-per-tick", "2000"]) == 0
    summary = json.loads((tmp_path / "b" / "galperin-pi" / "summary.json").read_text())
    assert summary["events"]["wall"] + summary["events"]["pair"] == 3141
    free = galperin_small(tmp_path, "model: exact")
    assert run([free, "--out", tmp_path / "c", "--quiet", "--max-events-per-tick", "1500"]) == 2
    assert "tick 9 needed more than 1500 events" in capsys.readouterr().err


def test_a_run_stopped_by_the_cap_keeps_its_outputs_so_far_as_ctrl_c_does(tmp_path, capsys):
    """The run stops in tick 9 (1,571 collisions past a cap of 1,000): exit 2 with the error, and
    OUT/NAME holds the run up to the last whole chunk of ticks before it: every frame and event
    of those ticks, the state at its end, a summary saying where and why it stopped; no GIF (an
    animation of part of the run), nothing of the tick that stopped it."""
    capped = galperin_small(tmp_path, "model: {kind: exact, max_events_per_tick: 1000}")
    text = capped.read_text().replace("output: {frames: none, gif: false, events: false}", "")
    capped.write_text(text + "output: {frames: all, gif: true, events: true}\n")
    assert run([capped, "--out", tmp_path, "--quiet"]) == 2
    folder = tmp_path / "galperin-pi"
    err = capsys.readouterr().err
    assert "tick 9 needed more than 1000 events" in err
    summary = json.loads((folder / "summary.json").read_text())
    k = summary["stopped_at_tick"]
    assert f"{folder} holds the run up to tick {k:,} (no GIF)" in err
    assert k == 8 and "tick 9 needed more than 1000 events" in summary["stopped"]  # a chunk a frame
    assert "interrupted_at_tick" not in summary and not (folder / "animation.gif").exists()
    frames = sorted(p.name for p in (folder / "frames").iterdir())
    assert frames == [f"frame_{i:06d}.png" for i in range(k + 1)]
    events = [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]
    assert all(e["tick"] <= k for e in events)
    assert len(events) == summary["events"]["wall"] + summary["events"]["pair"]
    # the final state is the one at tick k: what an uncapped run shows there
    whole = galperin_small(tmp_path, "model: exact")
    whole.write_text(whole.read_text().replace("ticks: 30", f"ticks: {k}"))
    assert run([whole, "--out", tmp_path / "whole", "--quiet"]) == 0
    final = (folder / "final.csv").read_text()
    assert final == (tmp_path / "whole" / "galperin-pi" / "final.csv").read_text()


def test_the_cap_is_refused_under_another_model_at_its_place(tmp_path, capsys):
    path = galperin_small(tmp_path, "model: {kind: stepped, max_events_per_tick: 1000}")
    assert run([path, "--out", tmp_path, "--quiet"]) == 2
    err = capsys.readouterr().err
    line = path.read_text().splitlines().index("model: {kind: stepped, max_events_per_tick: 1000}")
    assert err.startswith(f"{path}:{line + 1}:")
    assert "max_events_per_tick applies to the exact model only, not to stepped" in err
    assert not (tmp_path / "galperin-pi").exists()


def test_check_and_bless_take_the_cap(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("CI", raising=False)  # bless writes goldens, which CI never does
    (tmp_path / "scenarios").mkdir()
    galperin_small(tmp_path / "scenarios", "model: exact")
    args = ["--root", str(tmp_path), "--quiet", "--max-events-per-tick", "1000"]
    assert main(["bless", *args]) == 2
    assert "tick 9 needed more than 1000 events" in capsys.readouterr().err
    assert not (tmp_path / "goldens" / "galperin-pi").exists()
    assert main(["bless", *args[:-1], "2000"]) == 0
    assert main(["check", *args[:-1], "2000"]) == 0
    assert main(["check", *args]) == 2


@pytest.mark.parametrize(
    "world, obj, message",
    [
        (
            "{width: 20, height: 20}",
            "{shape: box, size: [20, 5], position: [0, 0], velocity: [3, 1]}",
            "object 0 has no room to move on x: it is as wide as the world",
        ),
        (
            "{width: 1, height: 1}",
            "{shape: box, size: 1, position: [0, 0], velocity: [1, 1]}",
            "object 0 has no room to move on x (and on y)",
        ),
    ],
)
def test_a_wedged_object_is_refused_at_its_place_before_running(
    tmp_path, capsys, world, obj, message
):
    path = tmp_path / "w.yaml"
    path.write_text(f"version: 1\nworld: {world}\nmodel: exact\nobjects:\n  - {obj}\n")
    started = time.perf_counter()
    assert run([path, "--out", tmp_path / "out"]) == 2
    assert time.perf_counter() - started < 2.0
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:5:5: error: ") and message in err
    assert not (tmp_path / "out").exists()


def test_a_wedged_object_between_statics_is_named(tmp_path, capsys):
    path = tmp_path / "w.yaml"
    path.write_text(
        "version: 1\nmodel: exact\nobjects:\n"
        "  - {shape: box, size: 10, position: [0, 0], static: true}\n"
        "  - {name: stuck, shape: box, size: 10, position: [10, 0], velocity: [5, 0]}\n"
        "  - {shape: box, size: 10, position: [20, 0], static: true}\n"
    )
    assert run([path, "--out", tmp_path / "out", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:5:5: error: object 1 (stuck) has no room to move on x: it is ")
    assert "between static object 0 and static object 2" in err
    # the other models run the same scene to its end (no hang, no crash)
    for model in ("paper", "stepped"):
        assert run([path, "--out", tmp_path / model, "--quiet", "--model", model]) == 0


@pytest.mark.parametrize("started", sorted(STARTED))
def test_ctrl_c_stops_any_command_even_started_with_sigint_ignored(tmp_path, started):
    """A command that sets no handler of its own (here `bench`) stops on Ctrl-C with exit 130
    and writes nothing half, also when started as a script's background job, with SIGINT
    ignored, which Python would otherwise keep."""
    first, proc, _, err = interrupted(
        started,
        [sys.executable, "-m", "collide2d", "bench", "--quick", "--part", "error"]
        + ["--out", tmp_path],
        ROOT,
    )
    assert first.startswith("error"), first  # the first progress line: the bench was under way
    assert proc.returncode == 130, err
    assert proc.took_s < 1.5, f"ended {proc.took_s:.2f} s after Ctrl-C"
    assert "interrupted; outputs already written are whole" in err
    assert "Traceback" not in err
    assert not (tmp_path / "bench").exists()


def test_a_ctrl_c_that_stops_a_compiled_kernel_is_an_interrupt_not_a_crash(capsys):
    """numba reports a kernel that Ctrl-C stopped as a chain of SystemErrors caused by the
    KeyboardInterrupt (`bench --part gravity` runs its kernels in this process): exit 130."""
    import argparse

    from collide2d.runner.command import main as cli

    def stopped(args):
        try:
            try:
                raise KeyboardInterrupt
            except KeyboardInterrupt as inner:
                raise SystemError("returned a result with an exception set") from inner
        except SystemError as middle:
            raise SystemError("returned a result with an exception set") from middle

    def broken(args):
        raise SystemError("returned a result with an exception set")

    assert cli._answered(argparse.Namespace(func=stopped)) == 130
    assert "interrupted; outputs already written are whole" in capsys.readouterr().err
    assert cli._answered(argparse.Namespace(func=broken, command="bench")) == 3  # a bug stays one
    assert "unexpected error" in capsys.readouterr().err


def test_a_ctrl_c_that_lands_in_a_finalizer_is_raised_just_after_it():
    """Python swallows an exception raised in `__del__` (numba's compiler frees LLVM objects so,
    while it compiles): a Ctrl-C that lands there still stops the command, a moment later."""
    import os
    import signal

    from collide2d.runner.command import main as cli

    class Freed:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGINT)  # handled at the next bytecode: still in here
            for _ in range(1000):
                pass

    before = signal.getsignal(signal.SIGINT)  # (ignored, when pytest runs as a background job)
    with pytest.raises(KeyboardInterrupt), cli._ctrl_c_answered():
        Freed()  # freed at once, its __del__ sends the signal
        deadline = time.monotonic() + 2.0
        while time.monotonic() < deadline:  # the interrupt comes here, out of the finalizer
            time.sleep(0.001)
    assert signal.getsignal(signal.SIGINT) is before  # the handler there was, back
