"""Tests of runner/golden/serialize.py: texts that read back exactly, pixel hashes, manifest."""

from __future__ import annotations

import io
import json
import struct
import zlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from PIL import Image

from collide2d.engine.events import EVENT_DTYPE, event_dict, format_event
from collide2d.runner.golden import serialize

from . import synthetic


def _events():
    ev = np.zeros(3, EVENT_DTYPE)
    ev[0] = (6, 0.6, 1, 0, 1, 0, 2, 10)
    ev[1] = (9, 0.9, 0, 3, -1, 0, -1, -1)
    ev[2] = (9, 0.9123456789, 1, 2, 5, 2, -1, -1)
    return ev


def test_events_jsonl_is_the_events_log_and_reads_back():
    ev = _events()
    data = serialize.events_jsonl(ev)
    assert data.decode().splitlines() == [format_event(r) for r in ev]
    assert data.endswith(b"\n")
    assert data.decode().splitlines()[0] == (
        '{"tick": 6, "t": 0.6, "type": "pair", "a": 0, "b": 1, "axis": "x", '
        '"xdiff": 2, "ydiff": 10}'
    )
    assert serialize.parse_events(data) == [event_dict(r) for r in ev] == serialize.event_dicts(ev)
    assert serialize.events_jsonl(np.zeros(0, EVENT_DTYPE)) == b""


def test_parse_events_names_a_bad_line():
    try:
        serialize.parse_events(b'{"tick": 1}\nnot json\n')
    except ValueError as exc:
        assert "line 2" in str(exc)
    else:
        raise AssertionError("a bad line was accepted")


finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(finite, finite, finite, finite), max_size=6))
def test_final_csv_reads_back_every_float64_exactly(rows):
    state = np.array(rows, dtype=np.float64).reshape(-1, 4)
    data = serialize.final_csv(state[:, :2], state[:, 2:])
    lines = data.decode().splitlines()
    assert lines[0] == "id,x,y,vx,vy" and len(lines) == len(rows) + 1
    back = serialize.parse_final(data)
    assert back.shape == state.shape
    assert np.array_equal(back, state)  # exact, not approximately


def test_final_csv_writes_whole_numbers_as_integers():
    data = serialize.final_csv(np.array([[100.0, 115.0]]), np.array([[-10.0, 0.5]]))
    assert data == b"id,x,y,vx,vy\n0,100,115,-10,0.5\n"


def _png(rgb, level):
    buf = io.BytesIO()
    Image.fromarray(rgb, "RGB").save(buf, format="PNG", compress_level=level)
    return buf.getvalue()


@settings(max_examples=20, deadline=None)
@given(arrays(np.uint8, st.tuples(st.integers(1, 9), st.integers(1, 9), st.just(3))))
def test_pixel_hash_is_of_decoded_pixels_not_png_bytes(rgb):
    a, b = _png(rgb, 0), _png(rgb, 9)
    assert serialize.pixel_sha256(serialize.decode_png(a)) == serialize.pixel_sha256(
        serialize.decode_png(b)
    )
    assert serialize.pixel_sha256(
        serialize.decode_png(serialize.png_bytes(rgb))
    ) == serialize.pixel_sha256(rgb)


def test_pixel_hash_covers_width_and_height():
    flat = np.arange(18, dtype=np.uint8)
    assert serialize.pixel_sha256(flat.reshape(2, 3, 3)) != serialize.pixel_sha256(
        flat.reshape(3, 2, 3)
    )
    one = np.zeros((2, 3, 3), np.uint8)
    two = one.copy()
    two[1, 2, 2] = 1
    assert serialize.pixel_sha256(one) != serialize.pixel_sha256(two)


def _chunks(png: bytes) -> list[str]:
    out, i = [], 8
    while i < len(png):
        (length,) = struct.unpack(">I", png[i : i + 4])
        kind = png[i + 4 : i + 8]
        (crc,) = struct.unpack(">I", png[i + 8 + length : i + 12 + length])
        assert crc == zlib.crc32(png[i + 4 : i + 8 + length])
        out.append(kind.decode())
        i += 12 + length
    return out


def test_png_is_deterministic_rgb_without_metadata():
    rgb = np.zeros((6, 8, 3), np.uint8)
    rgb[2, 3] = (255, 0, 0)
    data = serialize.png_bytes(rgb)
    assert data == serialize.png_bytes(rgb.copy())
    assert set(_chunks(data)) <= {"IHDR", "IDAT", "IEND"}
    with Image.open(io.BytesIO(data)) as im:
        assert im.mode == "RGB" and im.size == (8, 6)
    assert np.array_equal(serialize.decode_png(data), rgb)


def test_manifest_has_a_format_version_hashes_and_no_timestamps(tmp_path):
    scn = synthetic.load(synthetic.write(tmp_path / "demo.yaml", synthetic.spec()))
    run = synthetic.simulate(scn, keep_frames=(4, 0))
    events, final = (
        serialize.events_jsonl(run.events),
        serialize.final_csv(run.final_pos, run.final_vel),
    )
    m = serialize.manifest(scn, events, final, run.frames)
    assert m["format"] == serialize.FORMAT_VERSION
    assert (m["scenario"], m["model"], m["ticks"]) == ("demo", "paper", 4)
    assert m["events"]["count"] == 2 and m["final"]["objects"] == 2
    assert [f["frame"] for f in m["frames"]] == [0, 4]
    assert m["frames"][1]["pixels_sha256"] == serialize.pixel_sha256(run.frames[4])
    assert m["frames"][1]["file"] == "frames/frame_000004.png"
    text = serialize.manifest_bytes(m).decode()
    assert (
        serialize.manifest_bytes(serialize.manifest(scn, events, final, dict(run.frames)))
        == text.encode()
    )
    keys = json.dumps(m).lower()
    for word in ("time", "date", "created", "host", "user"):
        assert word not in keys


@pytest.mark.parametrize(
    "text, depth",
    [
        (b"1", 0),
        (b'{"a": [1, {"b": []}]}', 4),
        (b'{"a": "[[[[{{{{"}', 1),  # brackets inside a string do not nest
        (b'{"a": "\\"[[[["}', 1),  # nor after an escaped quote
        (b"[" * 100_000, 100_000),
    ],
)
def test_json_depth_counts_nesting_outside_strings(text, depth):
    assert serialize.json_depth(text) == depth


@pytest.mark.parametrize(
    "text, message",
    [
        (b"[" * 40 + b"]" * 40, "nested 40 levels deep, past 32"),
        (b'{"t": 1e999}', "not finite"),
        (b'{"t": -Infinity}', "-Infinity is not a number a golden holds"),
        (b'{"id": 9223372036854775808}', "an integer past 64 bits"),
        (b'{"id": ' + b"1" * 100_000 + b"}", "an integer past 64 bits"),
        (b"\xff", "not UTF-8"),
        (b"{", "not JSON"),
    ],
)
def test_load_json_refuses_what_no_golden_holds(text, message):
    with pytest.raises(ValueError, match=message):
        serialize.load_json(text)


def test_load_json_keeps_the_extremes_a_golden_may_hold():
    obj = serialize.load_json(b'{"id": -9223372036854775807, "t": 1.7976931348623157e308}')
    assert obj == {"id": -(2**63) + 1, "t": 1.7976931348623157e308}


@pytest.mark.parametrize("rel", ["../x", "/abs", "a/../b", "a//b", "./a", "a\\b", "c:x", "", 3])
def test_check_rel_refuses_paths_that_leave(rel):
    with pytest.raises(ValueError, match="not a plain relative path"):
        serialize.check_rel(rel)
