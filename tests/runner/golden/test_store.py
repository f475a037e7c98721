"""Tests of runner/golden/store.py: whole reads, atomic writes, torn goldens, CI, the root."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from collide2d.runner.golden import golden_files, serialize
from collide2d.runner.golden import store as st
from collide2d.runner.golden.store import (
    GoldenMissing,
    GoldenStore,
    GoldenUnreadable,
    WritesRefused,
)

from . import synthetic


def _files(tmp_path, **changes):
    scn = synthetic.load(synthetic.write(tmp_path / "scn.yaml", synthetic.spec(**changes)))
    run = synthetic.simulate(scn, keep_frames=scn.golden.frames)
    return golden_files(scn, run), run


def _snapshot(folder):
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_write_then_read_gives_the_results_back(tmp_path):
    files, run = _files(tmp_path)
    store = GoldenStore(tmp_path)
    written = store.write("demo", files)
    assert written == sorted(files)
    assert _snapshot(store.folder("demo")) == files
    g = store.read("demo")
    assert g.events == serialize.event_dicts(run.events)
    assert np.array_equal(g.final[:, :2], run.final_pos)
    assert np.array_equal(g.final[:, 2:], run.final_vel)
    assert sorted(g.frames) == [0, 4]
    assert all(np.array_equal(g.frames[k], run.frames[k]) for k in (0, 4))


def test_rewriting_the_same_files_changes_nothing(tmp_path):
    files, _ = _files(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", files)
    stamps = {p: p.stat().st_mtime_ns for p in store.folder("demo").rglob("*")}
    assert store.write("demo", dict(files)) == []
    assert {p: p.stat().st_mtime_ns for p in store.folder("demo").rglob("*")} == stamps


class _FailOn:
    """Wrap `func` so that its call number `n` raises OSError (the other calls go through)."""

    def __init__(self, func, n):
        self.func, self.n, self.calls = func, n, 0

    def __call__(self, *args):
        self.calls += 1
        if self.calls == self.n:
            raise OSError("disk full (simulated)")
        return self.func(*args)


def _old_and_new(tmp_path):
    old, _ = _files(tmp_path)
    new, _ = _files(
        tmp_path,
        events=[[2, 0.2, 0, 1, -1, 1, -1, -1]],
        final=[[1.0, 2.0, 10.0, 0.0]],
        pixels=[[0, 2, 2, 9, 9, 9], [4, 3, 3, 1, 2, 3]],
    )
    assert all(old[k] != new[k] for k in old)
    return old, new


def _entries(store):
    """The entries of goldens/: temporaries left behind show up here."""
    return sorted(os.listdir(store.dir))


@pytest.mark.parametrize("fail_at", [1, 2, 4, 5])
def test_a_write_failing_midway_leaves_the_old_golden_whole(tmp_path, monkeypatch, fail_at):
    old, new = _old_and_new(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", old)
    monkeypatch.setattr(st, "_write_new", _FailOn(st._write_new, fail_at))
    with pytest.raises(OSError, match="simulated"):
        store.write("demo", new)
    assert _snapshot(store.folder("demo")) == old  # byte for byte
    assert _entries(store) == ["demo"]  # and no temporary left
    store.read("demo")


@pytest.mark.parametrize("fail_at", [1, 2])
def test_a_rename_failing_puts_the_old_golden_back(tmp_path, monkeypatch, fail_at):
    old, new = _old_and_new(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", old)
    monkeypatch.setattr(st.os, "rename", _FailOn(os.rename, fail_at))
    with pytest.raises(OSError, match="simulated"):
        store.write("demo", new)
    assert _snapshot(store.folder("demo")) == old
    assert _entries(store) == ["demo"]
    store.read("demo")


def test_the_new_golden_is_whole_before_it_is_renamed_into_place(tmp_path, monkeypatch):
    old, new = _old_and_new(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", old)
    seen, real_rename = [], os.rename

    def rename(src, dst):
        if os.path.basename(dst) == "demo":
            seen.append(_snapshot(Path(src)))
        real_rename(src, dst)

    monkeypatch.setattr(st.os, "rename", rename)
    store.write("demo", new)
    assert seen == [new]


class _Killed(BaseException):
    """The process dies here: this call and every later one do nothing."""


# What a write does to the disk; a kill may come at any one of these calls.
_EFFECTS = [
    (os, "mkdir"),
    (os, "open"),
    (os, "write"),
    (os, "fsync"),
    (os, "rename"),
    (os, "replace"),
    (os, "unlink"),
    (os, "rmdir"),
    (shutil, "rmtree"),
]


class _Killer:
    """Count the calls of _EFFECTS; the call number `at` and every later one raise _Killed."""

    def __init__(self, monkeypatch, at):
        self.at, self.calls = at, 0
        for module, name in _EFFECTS:
            monkeypatch.setattr(module, name, self._wrap(getattr(module, name)))

    def _wrap(self, func):
        def call(*args, **kwargs):
            self.calls += 1
            if self.calls >= self.at:
                raise _Killed
            return func(*args, **kwargs)

        return call


def test_a_kill_at_any_step_of_a_write_leaves_one_golden_whole(tmp_path, monkeypatch):
    old, new = _old_and_new(tmp_path)
    # Flushing to disk stays a step a kill may hit, but costs nothing here (the test is about
    # what a rename order leaves, and runs some forty writes).
    monkeypatch.setattr(os, "fsync", lambda fd: None)
    at, outcomes = 0, set()
    while True:
        at += 1
        store = GoldenStore(tmp_path / f"k{at}")
        store.write("demo", old)
        with monkeypatch.context() as m:
            killer = _Killer(m, at)
            try:
                store.write("demo", new)
            except _Killed:
                pass
        if killer.calls < at:  # the write finished before call number `at`
            break
        # What a check reads now: the old golden or the new one, whole.
        read = store.read("demo").files
        assert read in (old, new), f"kill at call {at}"
        if (store.dir / "demo").exists():
            assert _snapshot(store.folder("demo")) in (old, new), f"kill at call {at}"
        outcomes.add("new" if read == new else "old")
        # The next write tidies up and succeeds.
        store.write("demo", new)
        assert _snapshot(store.folder("demo")) == new
        assert _entries(store) == ["demo"], f"kill at call {at}"
    assert at > 10 and outcomes == {"old", "new"}


def test_a_kill_between_the_two_renames_is_recovered(tmp_path, monkeypatch):
    old, new = _old_and_new(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", old)
    with monkeypatch.context() as m:
        # The old golden goes aside, then the process dies before the new one is renamed in.
        m.setattr(st.os, "rename", _KillAfter(os.rename, 1))
        with pytest.raises(_Killed):
            store.write("demo", new)
    assert not (store.dir / "demo").exists()
    (aside,) = [e for e in _entries(store) if e.endswith(".old.tmp")]
    assert store.read("demo").files == old  # read from where the old golden waits
    assert _snapshot(store.dir / aside) == old
    assert len(_entries(store)) == 2  # the old golden aside and the new one never renamed in
    store.recover("demo")
    assert _entries(store) == ["demo"]
    assert _snapshot(store.folder("demo")) == old


class _KillAfter:
    """Let `n` calls of `func` through; the next one raises _Killed."""

    def __init__(self, func, n):
        self.func, self.n, self.calls = func, n, 0

    def __call__(self, *args, **kwargs):
        self.calls += 1
        if self.calls > self.n:
            raise _Killed
        return self.func(*args, **kwargs)


def test_a_first_write_failing_leaves_no_golden(tmp_path, monkeypatch):
    files, _ = _files(tmp_path)
    store = GoldenStore(tmp_path)
    monkeypatch.setattr(st, "_write_new", _FailOn(st._write_new, 3))
    with pytest.raises(OSError):
        store.write("demo", files)
    with pytest.raises(GoldenMissing):
        store.read("demo")
    assert _entries(store) == []


def test_cleanup_removes_only_our_own_dead_temporaries(tmp_path):
    files, _ = _files(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", files)
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "keep.txt").write_bytes(b"outside")
    code = "import os; print(os.getpid())"
    dead = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    dead_pid = int(dead.stdout)
    ours = [f".demo.{dead_pid}.0123abcd.new.tmp", f".demo.{dead_pid}.0123abcd.old.tmp"]
    theirs = [
        f".demo.{os.getppid()}.0123abcd.new.tmp",  # a live process's write in progress
        f".other.{dead_pid}.0123abcd.new.tmp",  # another golden's
        f".demo.{dead_pid}.0123abcd.tmp",  # not our pattern
        "notes.tmp",
    ]
    for entry in ours + theirs:
        (store.dir / entry).mkdir()
        (store.dir / entry / "x.tmp").write_bytes(b"x")
    link = store.dir / f".demo.{dead_pid}.89abcdef.old.tmp"
    link.symlink_to(outside, target_is_directory=True)
    new, _ = _files(tmp_path, final=[[9.0, 9.0, 0.0, 0.0]])
    store.write("demo", new)
    left = set(_entries(store))
    assert not left & set(ours)
    assert set(theirs) <= left and link.is_symlink()
    assert _snapshot(outside) == {"keep.txt": b"outside"}


def test_a_golden_torn_between_renames_is_unreadable(tmp_path):
    old, new = _old_and_new(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", old)
    (store.folder("demo") / serialize.EVENTS_FILE).write_bytes(new[serialize.EVENTS_FILE])
    with pytest.raises(GoldenUnreadable, match=r"events\.jsonl does not match manifest\.json"):
        store.read("demo")


def test_png_pixels_are_checked_but_not_png_bytes(tmp_path):
    files, run = _files(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", files)
    png = store.folder("demo") / serialize.frame_file(4)
    from PIL import Image

    Image.fromarray(run.frames[4]).save(png, format="PNG", compress_level=0)
    assert png.read_bytes() != files[serialize.frame_file(4)]
    store.read("demo")  # the same pixels: still the golden
    edited = run.frames[4].copy()
    edited[0, 0] = (1, 1, 1)
    Image.fromarray(edited).save(png, format="PNG")
    with pytest.raises(GoldenUnreadable, match=r"frame_000004\.png does not match"):
        store.read("demo")


def test_missing_and_unreadable_goldens(tmp_path):
    files, _ = _files(tmp_path)
    store = GoldenStore(tmp_path)
    with pytest.raises(GoldenMissing, match="no golden for demo"):
        store.read("demo")
    store.folder("demo").mkdir(parents=True)
    with pytest.raises(GoldenMissing, match="has no manifest.json"):
        store.read("demo")
    store.write("demo", files)
    (store.folder("demo") / serialize.frame_file(0)).unlink()
    with pytest.raises(GoldenUnreadable, match="frame_000000.png is missing"):
        store.read("demo")
    manifest = store.folder("demo") / serialize.MANIFEST_FILE
    manifest.write_text(manifest.read_text().replace('"format": 1', '"format": 99'))
    with pytest.raises(GoldenUnreadable, match="format 99"):
        store.read("demo")
    manifest.write_text("{")
    with pytest.raises(GoldenUnreadable, match="not JSON"):
        store.read("demo")


def test_stale_frames_and_leftover_temporaries_are_removed(tmp_path):
    files, _ = _files(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("demo", files)
    folder = store.folder("demo")
    leftover = folder / serialize.FRAMES_DIR / ".frame_000004.png.999.tmp"
    leftover.write_bytes(b"half")
    fewer, _ = _files(tmp_path, golden={**synthetic.BASE["golden"], "frames": [4]})
    store.write("demo", fewer)
    assert not leftover.exists()
    assert not (folder / serialize.frame_file(0)).exists()
    assert sorted(store.read("demo").frames) == [4]


@pytest.mark.parametrize(
    "value, active",
    [
        (None, False),
        ("", False),
        ("0", False),
        ("false", False),
        ("No", False),
        ("true", True),
        ("1", True),
        ("yes", True),
    ],
)
def test_ci_truth_table(value, active):
    env = {} if value is None else {"CI": value}
    assert st.ci_active(env) is active


def test_nothing_is_written_in_ci(tmp_path, monkeypatch):
    files, _ = _files(tmp_path)
    store = GoldenStore(tmp_path)
    store.write("keep", files)
    monkeypatch.setenv("CI", "true")
    with pytest.raises(WritesRefused, match="CI is set"):
        store.write("demo", files)
    with pytest.raises(WritesRefused):
        store.remove("keep")
    assert store.names() == ["keep"]


def test_names_unused_and_remove(tmp_path):
    files, _ = _files(tmp_path)
    store = GoldenStore(tmp_path)
    assert store.names() == []
    for name in ("b", "a", "c"):
        store.write(name, files)
    (store.dir / ".hidden").mkdir()
    assert store.names() == ["a", "b", "c"]
    assert store.unused(["b", "zzz"]) == ["a", "c"]
    store.remove("a")
    assert store.names() == ["b", "c"]


@pytest.mark.parametrize("name", ["../x", ".hidden", "A", "a/b", "", ".."])
def test_names_cannot_leave_goldens(tmp_path, name):
    with pytest.raises(st.GoldenError):
        GoldenStore(tmp_path).folder(name)


def test_file_paths_cannot_leave_the_golden(tmp_path):
    files, _ = _files(tmp_path)
    with pytest.raises(ValueError):
        GoldenStore(tmp_path).write("demo", {**files, "../escape.txt": b"x"})
    assert not (tmp_path / "goldens" / "escape.txt").exists()


def test_find_root_walks_up_to_scenarios(tmp_path):
    (tmp_path / "scenarios").mkdir()
    deep = tmp_path / "a" / "b"
    deep.mkdir(parents=True)
    assert st.find_root(deep) == tmp_path.resolve()
    with pytest.raises(st.GoldenError, match="no scenarios/ folder"):
        st.find_root(tmp_path.parent / "nowhere-with-scenarios")


def test_scenario_files_are_sorted_yaml(tmp_path):
    folder = tmp_path / "scenarios"
    folder.mkdir()
    for name in ("b.yaml", "a.yml", "c.txt", "a.yaml"):
        (folder / name).write_text("{}")
    assert [p.name for p in st.scenario_files(tmp_path)] == ["a.yaml", "a.yml", "b.yaml"]
