"""Frame budgets: the byte bounds hold for any picture, and a run's frames never pass the limits.

The bounds are checked against what the writers really put on disk, for flat pictures and for
noise (the worst case of every compressor), at sizes and scales drawn by hypothesis; then through
`collide2d run`: a limit equal to a run's bound lets it through and its files stay under it, one
byte less refuses it before anything is written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from collide2d.runner.command.main import main
from collide2d.runner.output import budget
from collide2d.runner.output import files as outputs
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import load

SCENE = """version: 1
name: tiny
world: {{width: {w}, height: {h}, fps: {fps}}}
ticks: {ticks}
objects:
  - {{shape: box, size: 1, position: [0, 0], velocity: [10, 0], color: red}}
output: {{frames: {frames}}}
"""


def picture(rng, w: int, h: int, colours: int, noise: bool) -> np.ndarray:
    if noise:
        return rng.integers(0, colours, (h, w)).astype(np.uint8)
    return np.zeros((h, w), np.uint8)


@settings(max_examples=40, deadline=None)
@given(
    w=st.integers(1, 120),
    h=st.integers(1, 90),
    scale=st.integers(1, 3),
    noise=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
def test_a_png_never_passes_its_bound(w, h, scale, noise, seed):
    rng = np.random.default_rng(seed)
    rgb = rng.integers(0, 256, (h, w, 3)).astype(np.uint8) if noise else np.zeros((h, w, 3), "u1")
    assert len(outputs.encode_png(rgb, scale)) <= budget.png_bytes_bound(w * scale, h * scale)


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    w=st.integers(1, 100),
    h=st.integers(1, 80),
    colours=st.sampled_from([1, 2, 7, 256]),
    frames=st.integers(1, 6),
    fps=st.sampled_from([1, 10, 60, 1000]),
    noise=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
def test_a_gif_never_passes_its_bound(tmp_path, w, h, colours, frames, fps, noise, seed):
    rng = np.random.default_rng(seed)
    palette = rng.integers(0, 256, (colours, 3)).astype(np.uint8)
    path = tmp_path / "a.gif"
    with outputs.GifWriter(path, palette, w, h, fps, frames) as gif:
        for _ in range(frames):
            gif.add(picture(rng, w, h, colours, noise))
        shown = gif.schedule.count
    bound = budget.GIF_FIXED_BYTES + shown * budget.gif_frame_bytes_bound(w, h)
    assert path.stat().st_size <= bound


def scene(tmp_path: Path, *, w=1, h=1, fps=10, ticks=20, frames="none") -> Path:
    path = tmp_path / "tiny.yaml"
    path.write_text(SCENE.format(w=w, h=h, fps=fps, ticks=ticks, frames=frames))
    return path


def frame_bytes(folder: Path) -> int:
    files = list((folder / "frames").glob("*.png")) + [folder / "animation.gif"]
    return sum(p.stat().st_size for p in files if p.exists())


@pytest.mark.parametrize(
    ("scene_kw", "flags"),
    [
        ({"w": 1, "h": 1, "ticks": 300}, ["--png"]),
        (
            {"w": 31, "h": 17, "ticks": 40, "fps": 60, "frames": "{every: 3}"},
            ["--png", "--scale", "2"],
        ),
        ({"w": 64, "h": 48, "ticks": 25, "fps": 1000}, ["--no-png"]),
    ],
)
def test_output_bytes_on_disk_stay_within_the_limit_that_lets_a_run_through(
    tmp_path, capsys, scene_kw, flags
):
    path = scene(tmp_path, **scene_kw)
    sc = load(path)
    scale = int(flags[flags.index("--scale") + 1]) if "--scale" in flags else 1
    plan = budget.plan_frames(
        sc, png="--png" in flags, gif=True, scale=scale, limits=Limits(max_output_bytes=2**62)
    )
    out = tmp_path / "out"
    flags = [*flags, "--no-events"]  # the frames alone: the event log takes the rest of a limit
    limit = ["--max-output-bytes", str(plan.bytes_bound - 1)]
    assert main(["run", str(path), "--out", str(out), "--quiet", *flags, *limit]) == 2
    assert "past the output limit" in capsys.readouterr().err and not out.exists()
    limit = ["--max-output-bytes", str(plan.bytes_bound)]
    assert main(["run", str(path), "--out", str(out), "--quiet", *flags, *limit]) == 0
    assert 0 < frame_bytes(out / "tiny") <= plan.bytes_bound


def test_tiny_frame_files_count_their_overheads(tmp_path, capsys):
    """Found by hardening: 20,001 PNGs of a 1x1 world passed a limit of 80,004 bytes (3 bytes of
    pixels each) and wrote 2.6 MB."""
    path = scene(tmp_path, ticks=20_000)
    out = tmp_path / "out"
    argv = ["run", str(path), "--out", str(out), "--png", "--no-gif", "--max-output-bytes", "80004"]
    assert main(argv) == 2
    assert "past the output limit of 80,004 bytes" in capsys.readouterr().err
    assert not out.exists()


def test_max_frames_holds_for_png_frames_a_scenario_does_not_name(tmp_path, capsys):
    """Found by hardening: `--png` on a scenario with `frames: none` wrote every frame whatever
    --max-frames said."""
    path = scene(tmp_path, ticks=30)
    out = tmp_path / "out"
    argv = ["run", str(path), "--out", str(out), "--png", "--no-gif", "--max-frames", "30"]
    assert main(argv) == 2
    assert "31 PNG frames, past the limit of 30" in capsys.readouterr().err
    assert main([*argv[:-1], "31"]) == 0
    assert len(list((out / "tiny" / "frames").glob("*.png"))) == 31


def test_max_frames_counts_the_frames_a_gif_shows(tmp_path, capsys):
    # 1000 fps for 99 ticks: the GIF shows 50 frames a second, 5 of the 100
    path = scene(tmp_path, w=8, h=8, fps=1000, ticks=99)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet", "--max-frames", "4"]) == 2
    assert "5 GIF frames, past the limit of 4" in capsys.readouterr().err
    assert main(["run", str(path), "--out", str(out), "--quiet", "--max-frames", "5"]) == 0


DENSE = """version: 1
name: dense
world: {width: 24, height: 24, fps: 60}
ticks: 600
generate:
  - {count: 60, shape: box, size: 1, speed: 40, seed: 3}
output: {frames: last, gif: false, events: true}
"""


def test_the_event_log_counts_in_max_output_bytes(tmp_path, capsys):
    """Found by hardening: a 1 MB scenario (many objects in a tight box) wrote 300 MB of events
    a second whatever --max-output-bytes said. The log takes what the frames' bound leaves: a
    limit that holds the frames and the whole log lets the run through, one byte less stops it
    and keeps the previous run as it was."""
    path = tmp_path / "dense.yaml"
    path.write_text(DENSE)
    frames = budget.plan_frames(
        load(path), png=True, gif=False, scale=1, limits=Limits(max_output_bytes=2**62)
    ).bytes_bound
    out = tmp_path / "out"
    argv = ["run", str(path), "--out", str(out), "--quiet", "--png", "--max-output-bytes"]
    assert main([*argv, str(2**62)]) == 0
    log = (out / "dense" / "events.jsonl").read_bytes()
    assert len(log) > 100_000  # a log far larger than the frames

    assert main([*argv, str(frames + len(log))]) == 0
    assert (out / "dense" / "events.jsonl").read_bytes() == log
    before = {p: p.read_bytes() for p in (out / "dense").rglob("*") if p.is_file()}
    capsys.readouterr()

    assert main([*argv, str(frames + len(log) - 1)]) == 2
    err = capsys.readouterr().err
    assert f"{path}:1:1: error: the run stopped at tick " in err
    assert f"its event log would pass the {len(log) - 1:,} bytes" in err
    assert "--max-output-bytes" in err
    after = {p: p.read_bytes() for p in (out / "dense").rglob("*") if p.is_file()}
    assert after == before  # the previous run, whole
    assert sorted(p.name for p in out.iterdir()) == ["dense"]  # no staging folder, no lock left
