"""Tests for runner.output.files: atomic writes, PNG, GIF schedule and stream, events, CSV, JSON."""

from __future__ import annotations

import io
import json
import math
import os
import signal
import struct
import subprocess
import sys
import textwrap
import zlib
from fractions import Fraction

import imageio.v3 as iio
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image, ImageSequence

from collide2d.engine.events import (
    AXIS_X,
    EV_PAIR,
    EV_WALL,
    SIDE_LEFT,
    empty_events,
    format_event,
)
from collide2d.runner.output import files

PALETTE = np.array(
    [[0, 0, 0], [255, 0, 0], [0, 255, 0], [1, 2, 3], [250, 128, 7]],
    np.uint8,
)


def listing(folder) -> list[str]:
    return sorted(os.listdir(folder))


def random_frames(n, h, w, k=None, seed=0) -> np.ndarray:
    k = len(PALETTE) if k is None else k
    return np.random.default_rng(seed).integers(0, k, size=(n, h, w)).astype(np.uint8)


def write_gif(path, frames, fps, palette=PALETTE, scale=1):
    n, h, w = frames.shape
    with files.GifWriter(path, palette, w, h, fps, n, scale=scale) as gif:
        for f in frames:
            gif.add(f)
    return gif


def round_half_up(x: Fraction) -> int:
    return math.floor(x + Fraction(1, 2))


# ------------------------------------------------------------------ atomic files


def test_atomic_path_replaces_on_success(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with files.atomic_path(target) as tmp:
        assert tmp.parent == tmp_path and tmp != target
        tmp.write_text("new")
        assert target.read_text() == "old"  # nothing visible before the block ends
    assert target.read_text() == "new"
    assert listing(tmp_path) == ["out.txt"]


def test_atomic_path_keeps_old_file_on_error(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError, match="boom"), files.atomic_path(target) as tmp:
        tmp.write_text("half of the new")
        raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert listing(tmp_path) == ["out.txt"]


def test_atomic_file_gets_ordinary_permissions(tmp_path):
    (tmp_path / "plain").write_text("x")
    files.atomic_write_text(tmp_path / "atomic", "x")
    mode = os.stat(tmp_path / "atomic").st_mode & 0o777
    assert mode == os.stat(tmp_path / "plain").st_mode & 0o777


def test_atomic_write_bytes_and_text(tmp_path):
    files.atomic_write_bytes(tmp_path / "b", b"\x00\x01")
    files.atomic_write_text(tmp_path / "t", "é\nz\n")
    assert (tmp_path / "b").read_bytes() == b"\x00\x01"
    assert (tmp_path / "t").read_bytes() == "é\nz\n".encode()


def test_killed_gif_writer_leaves_old_gif_whole(tmp_path):
    target = tmp_path / "animation.gif"
    write_gif(target, random_frames(4, 6, 8, seed=1), fps=10)
    old = target.read_bytes()
    script = textwrap.dedent(
        f"""
        import os, signal, numpy as np
        from collide2d.runner.output import files
        pal = np.array({PALETTE.tolist()}, np.uint8)
        g = files.GifWriter({str(target)!r}, pal, 8, 6, 10, 50)
        for i in range(20):
            g.add(np.full((6, 8), i % 5, np.uint8))
        os.kill(os.getpid(), signal.SIGKILL)
        """
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, timeout=120)
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()
    assert target.read_bytes() == old
    leftovers = [n for n in listing(tmp_path) if n != "animation.gif"]
    assert len(leftovers) == 1 and os.path.getsize(tmp_path / leftovers[0]) > len(old) // 2
    assert files.final_name(leftovers[0]) == "animation.gif"  # clearly a temporary of it


# ------------------------------------------------------------------ PNG


def png_chunks(data: bytes) -> list[bytes]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    kinds, at = [], 8
    while at < len(data):
        (length,) = struct.unpack(">I", data[at : at + 4])
        kind = data[at + 4 : at + 8]
        crc = struct.unpack(">I", data[at + 8 + length : at + 12 + length])[0]
        assert zlib.crc32(data[at + 4 : at + 8 + length]) == crc
        kinds.append(kind)
        at += 12 + length
    return kinds


@settings(max_examples=20, deadline=None)
@given(st.integers(1, 9), st.integers(1, 9), st.integers(1, 3), st.integers(0, 2**31))
def test_png_decodes_to_the_same_pixels(h, w, scale, seed):
    rgb = np.random.default_rng(seed).integers(0, 256, size=(h, w, 3)).astype(np.uint8)
    data = files.encode_png(rgb, scale=scale)
    img = Image.open(io.BytesIO(data))
    assert img.mode == "RGB"
    got = np.asarray(img)
    assert got.shape == (h * scale, w * scale, 3)
    ys, xs = np.mgrid[0 : h * scale, 0 : w * scale]
    assert np.array_equal(got, rgb[ys // scale, xs // scale])
    assert data == files.encode_png(rgb.copy(), scale=scale)


def test_png_has_no_metadata():
    rgb = np.zeros((3, 4, 3), np.uint8)
    assert png_chunks(files.encode_png(rgb)) == [b"IHDR", b"IDAT", b"IEND"]


def test_png_rejects_bad_input():
    with pytest.raises(ValueError):
        files.encode_png(np.zeros((3, 4), np.uint8))
    with pytest.raises(ValueError):
        files.encode_png(np.zeros((3, 4, 3), np.float64))
    with pytest.raises(ValueError):
        files.encode_png(np.zeros((3, 4, 3), np.uint8), scale=0)


def test_write_png(tmp_path):
    rgb = PALETTE[random_frames(1, 5, 7)[0]]
    files.write_png(tmp_path / "f.png", rgb, scale=2)
    assert np.array_equal(iio.imread(tmp_path / "f.png")[::2, ::2], rgb)
    assert listing(tmp_path) == ["f.png"]


# ------------------------------------------------------------------ GIF schedule

FPS_TABLE = (1, 3, 7, 10, 30, 50, 60, 144)
N_TABLE = (1, 2, 3, 10, 49, 61, 62, 145, 1000, 1_000_003)


def gif_schedule(n_frames: int, fps: int):
    """`outputs.GifSchedule` written out: (kept frames, delays in cs, note)."""
    sched = files.GifSchedule(n_frames, fps)
    kept = np.array([sched.kept(j) for j in range(sched.count)], dtype=np.int64)
    delays = np.array([sched.delay_cs(j) for j in range(sched.count)], dtype=np.int64)
    return kept, delays, sched.note


@pytest.mark.parametrize("fps", FPS_TABLE)
@pytest.mark.parametrize("n", N_TABLE)
def test_gif_schedule_truth_table(fps, n):
    kept, delays, note = gif_schedule(n, fps)
    assert kept.dtype == np.int64 and delays.dtype == np.int64
    assert len(kept) == len(delays) >= 1
    assert kept[0] == 0 and np.all(np.diff(kept) > 0) and kept[-1] < n
    assert np.all(delays >= 2)
    total = round_half_up(Fraction(100 * n, fps))
    # exact to the centisecond (a whole animation under 2 cs cannot be shown shorter than 2 cs)
    assert int(delays.sum()) == max(total, 2)
    starts = np.concatenate([[0], np.cumsum(delays)[:-1]])
    true_start = [Fraction(100 * int(i), fps) for i in kept[:: max(1, len(kept) // 500)]]
    err = [abs(s - t) for s, t in zip(starts[:: max(1, len(kept) // 500)], true_start, strict=True)]
    if fps <= 50:
        assert np.array_equal(kept, np.arange(n))
        assert note is None
        assert set(delays.tolist()) <= {100 // fps, -(-100 // fps)}
        assert max(err) <= Fraction(1, 2)  # each frame starts at its time rounded
    else:
        gaps = np.diff(kept)
        if len(gaps):
            assert set(gaps.tolist()) <= {fps // 50, -(-fps // 50)}  # evenly spread
        # at most 50 kept frames start within any one second of the run
        secs = kept // fps
        assert np.bincount(secs).max() <= 50
        assert max(err) < 2  # a kept frame is shown less than 2 cs before its time
        if len(kept) < n:
            assert note == (
                f"GIF shows 50 of {fps} frames per second "
                "(delays under 2 cs are stretched by browsers)"
            )


def test_gif_schedule_known_rows():
    # 3 fps: frames due at 0, 33.3, 66.7 cs, end at 100 cs -> starts 0, 33, 67, 100
    assert gif_schedule(3, 3)[1].tolist() == [33, 34, 33]
    # 7 fps: due at 100*i/7 = 0, 14.3, 28.6, 42.9, 57.1, 71.4, 85.7, 100 -> rounded starts
    # 0, 14, 29, 43, 57, 71, 86, 100
    assert gif_schedule(7, 7)[1].tolist() == [14, 15, 14, 14, 14, 15, 14]
    # 60 fps, 61 frames (one second and a frame, 101.7 cs -> 102): one frame per 2 cs slot,
    # slots 0..50, the first frame of each is ceil(slot * 60 / 50)
    kept, delays, note = gif_schedule(61, 60)
    assert kept.tolist() == [-(-m * 60 // 50) for m in range(51)]
    assert delays.tolist() == [2] * 51
    assert note is not None
    # 60 fps, 62 frames: 103.3 cs -> 103; the last slot would last 1 cs and merges into the one
    # before, which lasts 3 cs
    kept, delays, _ = gif_schedule(62, 60)
    assert len(kept) == 51 and delays.tolist() == [2] * 50 + [3]
    assert gif_schedule(0, 10)[0].size == 0


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 3000), st.integers(1, 500))
def test_gif_schedule_properties(n, fps):
    kept, delays, _ = gif_schedule(n, fps)
    assert np.all(delays >= 2)
    assert int(delays.sum()) == max(round_half_up(Fraction(100 * n, fps)), 2)
    assert len(kept) <= n and np.all(np.diff(kept) >= 1)


# ------------------------------------------------------------------ GIF writer


def read_gif(path):
    img = Image.open(path)
    frames, durations = [], []
    for fr in ImageSequence.Iterator(img):
        frames.append(np.asarray(fr.convert("RGB")))
        durations.append(fr.info["duration"])
    return img.info, np.stack(frames), durations


@pytest.mark.parametrize("fps", [10, 7, 60])
@pytest.mark.parametrize("scale", [1, 2])
def test_gif_reads_back_exactly(tmp_path, fps, scale):
    frames = random_frames(23, 6, 9)
    path = tmp_path / "animation.gif"
    gif = write_gif(path, frames, fps, scale=scale)
    kept, delays, _ = gif_schedule(23, fps)
    info, got, durations = read_gif(path)
    assert info["loop"] == 0
    assert len(got) == len(kept)
    ys, xs = np.mgrid[0 : 6 * scale, 0 : 9 * scale]
    assert np.array_equal(got, PALETTE[frames[kept][:, ys // scale, xs // scale]])
    assert durations == [10 * int(d) for d in delays]
    assert sum(durations) == 10 * round_half_up(Fraction(2300, fps))
    assert gif.note is None if fps <= 50 else gif.note.startswith("GIF shows 50 of 60")
    # imageio reads the same pictures
    assert np.array_equal(iio.imread(path, index=None)[..., :3], got)
    assert listing(tmp_path) == ["animation.gif"]


def test_gif_is_deterministic(tmp_path):
    frames = random_frames(9, 7, 5, seed=3)
    write_gif(tmp_path / "a.gif", frames, 30)
    write_gif(tmp_path / "b.gif", frames.copy(), 30)
    assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()


@pytest.mark.parametrize(
    "palette",
    [
        np.array([[9, 8, 7]], np.uint8),  # background only
        np.array([[0, 0, 0], [255, 255, 255], [0, 0, 0], [255, 255, 255]], np.uint8),  # repeats
        np.random.default_rng(4).integers(0, 256, size=(256, 3)).astype(np.uint8),
    ],
)
def test_gif_keeps_exact_colours_of_any_palette(tmp_path, palette):
    frames = random_frames(3, 16, 16, k=len(palette), seed=5)
    write_gif(tmp_path / "p.gif", frames, 10, palette=palette)
    _, got, _ = read_gif(tmp_path / "p.gif")
    assert np.array_equal(got, palette[frames])


def test_gif_streams_to_disk(tmp_path):
    n, h, w = 12, 20, 30
    frames = random_frames(n, h, w, seed=6)
    gif = files.GifWriter(tmp_path / "s.gif", PALETTE, w, h, 10, n)
    sizes = []
    for f in frames:
        gif.add(f)
        (tmp,) = [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
        sizes.append(tmp.stat().st_size)
    # each frame is on disk as soon as it is added (random pixels do not compress to nothing)
    assert all(b - a > h * w // 4 for a, b in zip(sizes, sizes[1:], strict=False))
    assert not (tmp_path / "s.gif").exists()
    gif.close()
    assert listing(tmp_path) == ["s.gif"]


def test_gif_aborted_midway_leaves_old_gif(tmp_path):
    path = tmp_path / "animation.gif"
    write_gif(path, random_frames(5, 6, 8, seed=7), 10)
    old = path.read_bytes()
    with pytest.raises(KeyError):
        with files.GifWriter(path, PALETTE, 8, 6, 10, 40) as gif:
            for f in random_frames(10, 6, 8, seed=8):
                gif.add(f)
            raise KeyError("interrupted")
    assert path.read_bytes() == old
    assert listing(tmp_path) == ["animation.gif"]


def test_gif_refuses_missing_extra_and_bad_frames(tmp_path):
    path = tmp_path / "g.gif"
    path.write_bytes(b"old")
    gif = files.GifWriter(path, PALETTE, 4, 3, 10, 3)
    gif.add(np.zeros((3, 4), np.uint8))
    with pytest.raises(ValueError, match="announced"):
        gif.close()
    assert path.read_bytes() == b"old" and listing(tmp_path) == ["g.gif"]

    gif = files.GifWriter(path, PALETTE, 4, 3, 10, 1)
    with pytest.raises(ValueError, match="palette"):
        gif.add(np.full((3, 4), len(PALETTE), np.uint8))
    with pytest.raises(ValueError):
        gif.add(np.zeros((4, 3), np.uint8))
    gif.abort()
    gif = files.GifWriter(path, PALETTE, 4, 3, 10, 1)
    gif.add(np.zeros((3, 4), np.uint8))
    with pytest.raises(ValueError, match="more than"):
        gif.add(np.zeros((3, 4), np.uint8))
    gif.close()
    assert listing(tmp_path) == ["g.gif"] and path.read_bytes()[:6] == b"GIF89a"


# ------------------------------------------------------------------ events, CSV, JSON


def pair_and_wall_events() -> np.ndarray:
    ev = empty_events(2)
    ev[0] = (6, 0.6, EV_PAIR, 0, 1, AXIS_X, 2, 10)
    ev[1] = (9, 0.9, EV_WALL, 3, -1, SIDE_LEFT, -1, -1)
    return ev


def test_events_lines_are_the_spec_lines(tmp_path):
    path = tmp_path / "events.jsonl"
    ev = pair_and_wall_events()
    with files.EventsWriter(path) as log:
        log.write(ev[:1])
        log.write(empty_events(0))
        assert not path.exists()
        log.write(ev[1:])
    assert path.read_text() == (
        '{"tick": 6, "t": 0.6, "type": "pair", "a": 0, "b": 1, "axis": "x", '
        '"xdiff": 2, "ydiff": 10}\n'
        '{"tick": 9, "t": 0.9, "type": "wall", "id": 3, "side": "left"}\n'
    )
    assert log.count == 2
    assert listing(tmp_path) == ["events.jsonl"]


def test_events_writer_abort_keeps_old_log(tmp_path):
    path = tmp_path / "events.jsonl"
    path.write_text("old\n")
    with pytest.raises(RuntimeError), files.EventsWriter(path) as log:
        log.write(pair_and_wall_events())
        raise RuntimeError
    assert path.read_text() == "old\n"
    assert listing(tmp_path) == ["events.jsonl"]


def test_events_writer_never_passes_its_bound(tmp_path):
    path = tmp_path / "events.jsonl"
    path.write_text("old\n")
    ev = pair_and_wall_events()
    whole = sum(len(format_event(r)) + 1 for r in ev)
    with files.EventsWriter(path, max_bytes=whole) as log:
        log.write(ev)
    assert log.bytes == whole == len(path.read_bytes())
    path.write_text("old\n")
    log = files.EventsWriter(path, max_bytes=whole - 1)
    with pytest.raises(files.LogFull) as caught, log:
        log.write(ev[:1])
        log.write(ev[1:])
    assert (caught.value.tick, caught.value.limit) == (9, whole - 1)  # the wall event's tick
    assert log.bytes < whole - 1 and log.count == 1
    assert path.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["events.jsonl"]


def test_empty_events_log_is_an_empty_file(tmp_path):
    with files.EventsWriter(tmp_path / "e.jsonl"):
        pass
    assert (tmp_path / "e.jsonl").read_bytes() == b""


def test_final_csv(tmp_path):
    pos = np.array([[1.0, 2.5], [300.0, -0.125]])
    vel = np.array([[-3.0, 0.1], [0.0, 1e-20]])
    files.write_final_csv(tmp_path / "final.csv", pos, vel)
    assert (tmp_path / "final.csv").read_text() == (
        "id,x,y,vx,vy\n0,1,2.5,-3,0.1\n1,300,-0.125,0,1e-20\n"
    )
    with pytest.raises(ValueError):
        files.final_csv_text(pos, vel[:1])


def test_write_json_keeps_key_order(tmp_path):
    path = tmp_path / "summary.json"
    obj = {"name": "demo", "b": [1, 2], "a": {"z": 1.5, "y": None}}
    files.write_json(path, obj)
    text = path.read_text()
    assert text == json.dumps(obj, indent=2) + "\n"
    assert text.index('"name"') < text.index('"b"') < text.index('"a"')
    assert text.index('"z"') < text.index('"y"')
    assert json.loads(text) == obj


def test_write_json_refuses_nan_and_keeps_old_file(tmp_path):
    path = tmp_path / "summary.json"
    path.write_text("{}\n")
    with pytest.raises(ValueError):
        files.write_json(path, {"energy": float("nan")})
    assert path.read_text() == "{}\n"
    assert listing(tmp_path) == ["summary.json"]
