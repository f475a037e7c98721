"""Tests of the goldens against a hostile tree (docs/goldens.md#confinement-and-hostile-goldens):
links, escaping paths, bombs.

`check`, `bless` and `check --report` on a project of synthetic scenarios whose goldens/ or report
folder hold symbolic links, manifests naming paths outside the golden, and golden files built to
hurt a reader (deep JSON, numbers past range, a frame that is not a PNG, PNG bombs). Each must give
a clear result — a refusal naming the path, or that scenario failing as unreadable — never a
traceback, never a change outside the project, and the other scenarios are still checked.
"""

from __future__ import annotations

import json
import struct
import time
import tracemalloc
import zlib

import pytest

from collide2d.runner.golden import cli, serialize

from . import synthetic


def _run(*argv, simulate=synthetic.simulate):
    return cli.main(list(argv), load=synthetic.load, simulate=simulate)


def _snapshot(folder):
    """Every entry below `folder` (links not followed): relative path -> bytes, or the link's
    target, or None for a folder."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if p.is_symlink():
            out[rel] = ("link", str(p.readlink()))
        elif p.is_dir():
            out[rel] = None
        else:
            out[rel] = p.read_bytes()
    return out


@pytest.fixture
def two(tree, capsys):
    """The tree with a second scenario `other`, both blessed."""
    synthetic.write(tree / "scenarios" / "other.yaml", synthetic.spec(name="other"))
    assert _run("bless") == 0
    capsys.readouterr()
    return tree


@pytest.fixture
def outside(tmp_path_factory):
    """A folder outside the project, with files a leak would touch (a golden's worth of them,
    and temporaries an over-eager clean-up would remove)."""
    folder = tmp_path_factory.mktemp("outside")
    (folder / "frames").mkdir()
    (folder / "frames" / "frame_000004.png").write_bytes(b"not yours")
    (folder / "manifest.json").write_bytes(b"{}")
    (folder / "keep.tmp").write_bytes(b"a temporary that is not ours")
    (folder / "deep").mkdir()
    (folder / ".x.1.tmp").write_bytes(b"hidden")
    (folder / "deep" / "y.tmp").write_bytes(b"nested")
    return folder


def _expect_clean(capsys, code, expected_code):
    out, err = capsys.readouterr()
    assert code == expected_code, out + err
    assert "Traceback" not in out + err
    return out, err


# ---------------------------------------------------------------------------------- links


def test_a_golden_folder_linked_elsewhere_is_refused(two, outside, capsys):
    golden = two / "goldens" / "demo"
    for p in sorted(golden.rglob("*"), reverse=True):
        p.rmdir() if p.is_dir() else p.unlink()
    golden.rmdir()
    golden.symlink_to(outside, target_is_directory=True)
    before = _snapshot(outside)
    out, err = _expect_clean(capsys, _run("bless"), 2)
    assert "goldens/demo is a symbolic link" in err
    assert "unchanged other: no change" in " ".join(out.split())  # the other one still blessed
    out, _ = _expect_clean(capsys, _run("check"), 1)
    assert "UNREADABLE demo" in out and "goldens/demo is a symbolic link" in out
    assert "ok      other" in out
    stale = two / "goldens" / "stale"  # no scenario uses it: --prune would remove it
    stale.symlink_to(outside, target_is_directory=True)
    _, err = _expect_clean(capsys, _run("bless", "--prune", "other"), 2)
    assert "goldens/stale is a symbolic link" in err
    assert _snapshot(outside) == before
    assert golden.is_symlink() and stale.is_symlink()


@pytest.mark.parametrize(
    "rel", [serialize.frame_file(4), serialize.MANIFEST_FILE, serialize.EVENTS_FILE]
)
def test_a_file_linked_elsewhere_inside_a_golden_is_refused(two, outside, capsys, rel):
    target = two / "goldens" / "demo" / rel
    copy = outside / "copy"
    copy.write_bytes(target.read_bytes())  # the same bytes: only the link is wrong
    target.unlink()
    target.symlink_to(copy)
    before = _snapshot(outside)
    out, _ = _expect_clean(capsys, _run("check"), 1)
    assert "UNREADABLE demo" in out and f"goldens/demo/{rel} is a symbolic link" in out
    assert "ok      other" in out
    _, err = _expect_clean(capsys, _run("bless"), 2)
    assert f"goldens/demo/{rel} is a symbolic link" in err
    assert _snapshot(outside) == before
    assert target.is_symlink()


def test_a_linked_goldens_folder_is_refused(two, outside, capsys):
    (two / "goldens").rename(two / "real-goldens")
    (two / "goldens").symlink_to(two / "real-goldens", target_is_directory=True)
    for argv in (["check"], ["bless"], ["bless", "--prune"]):
        _, err = _expect_clean(capsys, _run(*argv), 2)
        assert "goldens is a symbolic link" in err


@pytest.mark.parametrize("entry", [None, "demo", "index.html", "summary.json"])
def test_a_linked_report_folder_or_entry_is_refused(two, outside, capsys, entry):
    synthetic.write(
        two / "scenarios" / "demo.yaml",
        synthetic.spec(pixels=synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]]),
    )
    rep = two / "rep"
    if entry is None:
        rep.symlink_to(outside, target_is_directory=True)
    else:
        rep.mkdir()
        link = rep / entry
        if entry == "demo":
            link.symlink_to(outside, target_is_directory=True)
        else:
            link.symlink_to(outside / "keep.tmp")
    before = _snapshot(outside)
    _, err = _expect_clean(capsys, _run("check", "--report", "rep"), 2)
    shown = "rep" if entry is None else f"rep/{entry}"
    assert f"{shown} is a symbolic link" in err
    assert _snapshot(outside) == before


def test_a_report_link_appearing_during_the_check_is_refused(two, outside, capsys, monkeypatch):
    synthetic.write(
        two / "scenarios" / "demo.yaml",
        synthetic.spec(pixels=synthetic.BASE["pixels"] + [[4, 6, 1, 0, 0, 9]]),
    )
    real = synthetic.simulate

    def simulate(scenario, **kwargs):  # the link appears after the checks before the run
        link = two / "rep" / scenario.name
        if not link.is_symlink():
            link.parent.mkdir(exist_ok=True)
            link.symlink_to(outside, target_is_directory=True)
        return real(scenario, **kwargs)

    before = _snapshot(outside)
    _, err = _expect_clean(capsys, _run("check", "--report", "rep", simulate=simulate), 2)
    assert "rep/demo is a symbolic link" in err
    assert _snapshot(outside) == before


# ---------------------------------------------------------------------------------- manifests


def _manifest(tree, name="demo"):
    return tree / "goldens" / name / serialize.MANIFEST_FILE


def _edit_manifest(tree, change, name="demo"):
    path = _manifest(tree, name)
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data, indent=2) + "\n")


def _forge(tree, rel, data: bytes, name="demo"):
    """Replace a golden file and give the manifest its hash (so only its content is wrong)."""
    (tree / "goldens" / name / rel).write_bytes(data)

    def change(m):
        for key in ("events", "final"):
            if m[key]["file"] == rel:
                m[key]["sha256"] = serialize.sha256_bytes(data)

    _edit_manifest(tree, change, name)


@pytest.mark.parametrize(
    "key, path",
    [
        ("events", "../other/events.jsonl"),
        ("final", "/etc/hostname"),
        ("frame", "frames/../../other/frames/frame_000004.png"),
        ("frame", "/tmp/frame_000004.png"),
    ],
)
def test_manifest_paths_leaving_the_golden_are_refused(two, capsys, key, path):
    def change(m):
        if key == "frame":
            m["frames"][1]["file"] = path
        else:
            m[key]["file"] = path

    _edit_manifest(two, change)
    out, _ = _expect_clean(capsys, _run("check"), 1)
    assert "UNREADABLE demo" in out
    assert f"the path {json.dumps(path)} is not a plain relative path inside the golden" in out
    assert "ok      other" in out


# ---------------------------------------------------------------------------------- hostile


def _png(width, height, *, bit_depth=8, color=2, idat=None) -> bytes:
    """A PNG from its chunks: IHDR as given; IDAT `idat` (default: all-zero rows, compressed)."""

    def chunk(kind, body):
        crc = zlib.crc32(kind + body) & 0xFFFFFFFF
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", crc)

    if idat is None:
        row = 1 + (width * bit_depth * (3 if color == 2 else 1) + 7) // 8
        comp = zlib.compressobj(9)
        idat = b"".join(comp.compress(bytes(row)) for _ in range(height)) + comp.flush()
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, color, 0, 0, 0)
    return (
        serialize.PNG_SIGNATURE + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")
    )


def _set_frame_size(tree, w, h):
    def change(m):
        m["frames"][1]["width"], m["frames"][1]["height"] = w, h

    _edit_manifest(tree, change)


def _deep_manifest(tree):
    _manifest(tree).write_bytes(b"[" * 100_000)


def _in_manifest(text):
    def spoil(tree):
        m = _manifest(tree)
        m.write_text(m.read_text().replace('"frame": 4', f'"frame": {text}'))

    spoil.__name__ = f"_frame_{text[:6]}_in_manifest"
    return spoil


def _deep_event(tree):
    _forge(tree, serialize.EVENTS_FILE, b'{"tick": ' + b"[" * 50_000 + b"]" * 50_000 + b"}\n")


def _inf_event(tree):
    _forge(tree, serialize.EVENTS_FILE, b'{"tick": 2, "t": 1e999, "type": "wall", "id": 1}\n')


def _long_int_event(tree):
    _forge(tree, serialize.EVENTS_FILE, b'{"tick": ' + b"9" * 5000 + b', "t": 0.2}\n')


def _big_int_event(tree):
    _forge(tree, serialize.EVENTS_FILE, b'{"tick": ' + b"9" * 40 + b', "t": 0.2}\n')


def _nan_event(tree):
    _forge(tree, serialize.EVENTS_FILE, b'{"tick": 2, "t": NaN}\n')


def _inf_final(tree):
    _forge(tree, serialize.FINAL_FILE, b"id,x,y,vx,vy\n0,1e999,2,10,0\n1,5.5,3,-10,2.5\n")


def _long_number_final(tree):
    _forge(
        tree, serialize.FINAL_FILE, b"id,x,y,vx,vy\n0," + b"9" * 400 + b",2,10,0\n1,5.5,3,-10,2.5\n"
    )


def _not_a_png(tree):
    (tree / "goldens" / "demo" / serialize.frame_file(4)).write_bytes(b"GIF89a" + bytes(100))


def _truncated_png(tree):
    path = tree / "goldens" / "demo" / serialize.frame_file(4)
    path.write_bytes(path.read_bytes()[:40])


def _bomb_header(tree):
    # A few hundred bytes whose header claims 100000 x 100000 pixels (30 GB of RGB).
    (tree / "goldens" / "demo" / serialize.frame_file(4)).write_bytes(
        _png(100_000, 100_000, idat=zlib.compress(bytes(1000)))
    )


def _bomb_header_and_manifest(tree):
    _bomb_header(tree)
    _set_frame_size(tree, 100_000, 100_000)


_BOMB_SIDE = 9000  # 81 M pixels: under Pillow's own bomb limit, 243 MB once decoded to RGB


def _bomb_valid(tree):
    # A whole, valid 1-bit PNG of 9000 x 9000 pixels in about 10 kB, and a manifest that agrees.
    (tree / "goldens" / "demo" / serialize.frame_file(4)).write_bytes(
        _png(_BOMB_SIDE, _BOMB_SIDE, bit_depth=1, color=0)
    )
    _set_frame_size(tree, _BOMB_SIDE, _BOMB_SIDE)


HOSTILE = [
    (_deep_manifest, "nested 100000 levels deep, past 32"),
    (_in_manifest("1e999"), "manifest.json: a number is out of range (not finite)"),
    (_in_manifest("9" * 30), "manifest.json: a number is out of range (an integer past 64 bits)"),
    (_in_manifest("9" * 5000), "manifest.json: a number is out of range"),
    (_in_manifest("4.5"), "manifest.json: frames[1].frame must be an integer"),
    (_in_manifest('"4"'), "manifest.json: frames[1].frame must be an integer"),
    (_deep_event, "line 1: an event is one flat JSON object"),
    (_inf_event, "line 1: a number is out of range (not finite)"),
    (_long_int_event, "line 1: a number is out of range"),
    (_big_int_event, "line 1: a number is out of range (an integer past 64 bits)"),
    (_nan_event, "line 1: NaN is not a number a golden holds"),
    (_inf_final, "line 2: a number is out of range (not finite)"),
    (_long_number_final, "line 2: a number is out of range (not finite)"),
    (_not_a_png, "frame_000004.png: not a PNG file"),
    (_truncated_png, "frame_000004.png: damaged PNG"),
    (_bomb_header, "the PNG is 100000x100000, the manifest says 8x6"),
    (_bomb_header_and_manifest, "the PNG claims 100000x100000 pixels, past the 16777216"),
    (_bomb_valid, f"the PNG claims {_BOMB_SIDE}x{_BOMB_SIDE} pixels, past the 16777216"),
]


@pytest.mark.parametrize("spoil, message", HOSTILE, ids=[f.__name__[1:] for f, _ in HOSTILE])
def test_a_hostile_golden_fails_its_scenario_clearly(two, capsys, spoil, message):
    spoil(two)
    tracemalloc.start()
    start = time.perf_counter()
    code = _run("check", "demo")
    took = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    out, _ = _expect_clean(capsys, code, 1)
    assert out.startswith("UNREADABLE demo (scenarios/demo.yaml)")
    assert message in out
    assert "to accept this run as the golden: collide2d bless scenarios/demo.yaml" in out
    # Refused from the header and bounds: no picture is decoded, nothing big is built.
    assert peak < 30 * 1024 * 1024 and took < 2.0, (peak, took)
    # The other scenario is still checked, and a bless replaces the hostile golden.
    out, _ = _expect_clean(capsys, _run("check"), 1)
    assert "ok      other" in out and out.rstrip().endswith("1 passed, 1 failed")
    out, _ = _expect_clean(capsys, _run("bless", "demo"), 0)
    assert out.startswith("updated   demo: replaced an unreadable golden")
    _expect_clean(capsys, _run("check"), 0)


# ---------------------------------------------------------------------------------- errors


def _crashing(name):
    def simulate(scenario, **kwargs):
        if scenario.name == name:
            raise RuntimeError("kaboom\nsecond line")
        return synthetic.simulate(scenario, **kwargs)

    return simulate


@pytest.mark.parametrize("command", ["check", "bless"])
def test_an_unexpected_error_exits_3_naming_the_scenario(two, capsys, command):
    synthetic.write(  # "other" now differs from its golden: still 3, not 1
        two / "scenarios" / "other.yaml",
        synthetic.spec(name="other", final=[[0.0, 0.0, 0.0, 0.0]]),
    )
    code = _run(command, simulate=_crashing("demo"))
    out, err = _expect_clean(capsys, code, 3)
    (line,) = err.splitlines()
    assert line == (
        f"collide2d: unexpected error while {command}ing demo (scenarios/demo.yaml): "
        "RuntimeError: kaboom second line (run with --debug for the traceback)"
    )
    if command == "check":
        assert "FAILED  other" in out
        assert out.rstrip().endswith("0 passed, 1 failed, 1 not checked (errors above)")
    else:
        assert out.startswith("updated   other")


def test_debug_prints_the_traceback(two, capsys):
    code = _run("--debug", "check", simulate=_crashing("demo"))
    out, err = capsys.readouterr()
    assert code == 3
    assert err.startswith("collide2d: unexpected error while checking demo")
    assert "Traceback (most recent call last)" in err and "RuntimeError: kaboom" in err
    assert "ok      other" in out
