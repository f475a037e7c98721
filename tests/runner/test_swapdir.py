"""Tests of runner/output/swap.py: temporary names, leftovers, the swap, recovery, no link
followed."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from collide2d.runner.output import swap


def _folder(path, text):
    path.mkdir()
    (path / "file.txt").write_text(text)
    return path


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_temporary_names_carry_the_pid_and_the_kind():
    pid = os.getpid()
    assert re.fullmatch(
        rf"\.demo\.{pid}\.[0-9a-f]{{8}}\.new\.tmp", swap.temp_name("demo", "new")
    )
    assert re.fullmatch(rf"\.a\.png\.{pid}\.[0-9a-f]{{8}}\.tmp", swap.temp_name("a.png"))
    assert swap.temp_name("demo", "new") != swap.temp_name("demo", "new")


def test_a_temporary_folder_is_made_or_only_named(tmp_path):
    made = swap.make_temp(tmp_path, "demo", "run")
    named = swap.temp_path(tmp_path, "demo", "old")
    assert made.is_dir() and made.name.endswith(".run.tmp")
    assert not os.path.lexists(named) and named.name.endswith(".old.tmp")


def test_leftovers_are_real_folders_of_that_name_and_kind(tmp_path):
    pid = _dead_pid()
    ours = [f".demo.{pid}.0123abcd.run.tmp", f".demo.{pid}.0123abcd.old.tmp"]
    others = [
        f".demo.{pid}.0123abcd.new.tmp",  # a kind not asked for
        f".other.{pid}.0123abcd.old.tmp",  # another name
        f".demo.x.{pid}.0123abcd.old.tmp",  # another name, sharing the prefix
        f".demo.{pid}.0123abc.old.tmp",  # seven hex digits
        f".demo.{pid}.0123abcd.tmp",  # no kind
    ]
    for name in ours + others:
        (tmp_path / name).mkdir()
    (tmp_path / f".demo.{pid}.89abcdef.old.tmp").symlink_to(tmp_path / ours[0])
    (tmp_path / f".demo.{pid}.456789ab.run.tmp").write_text("a file, not a folder")
    found = swap.leftovers(tmp_path, "demo", ("run", "old"))
    assert found == sorted((tmp_path / n, pid, n.split(".")[-2]) for n in ours)
    assert swap.leftovers(tmp_path / "missing", "demo", ("old",)) == []


def test_a_swap_replaces_the_folder_whole_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "demo"
    swap.swap_in(_folder(tmp_path / "first", "one"), target)
    assert (target / "file.txt").read_text() == "one"
    for atomic in (False, True):
        swap.swap_in(_folder(tmp_path / "next", f"atomic={atomic}"), target, atomic=atomic)
        assert (target / "file.txt").read_text() == f"atomic={atomic}"
        assert os.listdir(tmp_path) == ["demo"]


def test_a_swap_whose_second_rename_fails_puts_the_old_folder_back(tmp_path, monkeypatch):
    target = _folder(tmp_path / "demo", "old")
    new = _folder(tmp_path / "new", "new")
    real_rename, calls = os.rename, []

    def rename(src, dst):
        calls.append(dst)
        if len(calls) == 2:
            raise OSError("disk full (simulated)")
        real_rename(src, dst)

    monkeypatch.setattr(os, "rename", rename)
    with pytest.raises(OSError, match="simulated"):
        swap.swap_in(new, target)
    assert (target / "file.txt").read_text() == "old"
    assert os.listdir(tmp_path) == ["demo"]  # the new folder removed, nothing aside


def test_recovery_puts_the_newest_old_folder_back_when_the_target_is_missing(tmp_path):
    target = tmp_path / "demo"
    older = _folder(swap.temp_path(tmp_path, "demo", "old"), "older")
    newer = _folder(swap.temp_path(tmp_path, "demo", "old"), "newer")
    os.utime(older, ns=(1, 1))
    _folder(swap.temp_path(tmp_path, "demo", "new"), "half built")
    found = swap.leftovers(tmp_path, "demo", ("new", "old"))
    assert swap.newest_aside(found) == newer
    swap.recover(target, found)
    assert (target / "file.txt").read_text() == "newer"
    assert os.listdir(tmp_path) == ["demo"]
    # With the target in place every leftover goes.
    _folder(swap.temp_path(tmp_path, "demo", "old"), "stale")
    swap.recover(target, swap.leftovers(tmp_path, "demo", ("old",)))
    assert (target / "file.txt").read_text() == "newer"
    assert os.listdir(tmp_path) == ["demo"]


def test_removing_a_tree_never_follows_a_link(tmp_path):
    outside = _folder(tmp_path / "outside", "keep")
    tree = tmp_path / "tree"
    tree.mkdir()
    (tree / "link").symlink_to(outside)
    swap.remove_tree(tmp_path / "missing")
    (tmp_path / "top").symlink_to(outside)
    swap.remove_tree(tmp_path / "top")  # a link is not a folder of ours: left alone
    assert (tmp_path / "top").is_symlink()
    swap.remove_tree(tree)
    assert not tree.exists()
    assert (outside / "file.txt").read_text() == "keep"


def test_alive_and_fsync_of_a_folder(tmp_path):
    assert swap.alive(os.getpid())
    assert not swap.alive(_dead_pid())
    swap.fsync_dir(tmp_path)
    swap.fsync_dir(tmp_path / "missing")  # nothing to flush, no error


def test_abandon_removes_what_this_process_was_writing_but_a_folder_moved_aside(
    tmp_path, monkeypatch
):
    """A process ended before its writes are done (runner.interrupt): its staging folders and
    temporary files go, an old folder a cut swap left aside stays for `recover`, and so does
    what another process left."""
    monkeypatch.setattr(swap, "_made_in", set())
    target = _folder(tmp_path / "demo", "the old run")
    stage = swap.make_temp(tmp_path, "demo", "run")
    (stage / "events.jsonl").write_text("half a log")
    swap.temp_beside(tmp_path / "final.csv").write_text("half a file")
    aside = _folder(swap.temp_path(tmp_path, "other", swap.OLD), "an old run aside")
    theirs = _folder(tmp_path / f".demo.{_dead_pid()}.0123abcd.run.tmp", "another's")
    assert swap.abandon() == [target]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["demo", aside.name, theirs.name])
    assert (target / "file.txt").read_text() == "the old run"
