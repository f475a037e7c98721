"""A folder staged beside its target and swapped in whole: the temporary names, the swap, recovery.

A folder TARGET = PARENT/NAME is replaced whole by building the new one in a sibling temporary
folder and swapping it in. Every temporary of NAME is named `.NAME.PID.HEX.KIND.tmp`: the writer's
pid, eight random hex digits, and what it holds (`run` or `new` for a folder being built, `old` for
the folder moved aside during a swap; a temporary file of one name has no KIND). A killed writer's
leftovers are recognised by that exact pattern, only as real folders (never through a link), each
with the pid that left it.

The swap moves the old folder aside under an `old` name and the new one into place with two renames
(or, when asked and where the system offers it, one atomic exchange of the two names: Linux
`renameat2`), flushes the parent folder to disk, and only then removes the old folder. When a rename
fails the old folder is put back and the new one removed. A writer killed between the two renames
leaves the old folder whole under its aside name: `recover` puts it back when TARGET is missing and
removes the other leftovers it is given. A tree is removed only when it is a real folder, and links
inside it are removed, never followed.

A process that must end before its writes are done (Ctrl-C that the command did not answer in
time, runner.interrupt) first calls `stop_renames`, which waits for a swap under way and lets no
other start, then `abandon`, which removes every temporary file and folder of its own (named with
its pid) in the folders it made them in, except an old folder moved aside. What it leaves is what
a finished or failed write leaves: the old folder whole, nothing half written.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import re
import secrets
import shutil
import stat
import threading
from pathlib import Path

TMP_SUFFIX = ".tmp"
OLD = "old"  # the kind of the old folder moved aside during a swap
_AT_FDCWD = -100
_RENAME_EXCHANGE = 2

# The folders this process has made temporaries in (for `abandon`), and the lock held while it
# renames folders (for `stop_renames`).
_made_in: set[str] = set()
_renaming = threading.Lock()


def temp_name(name: str, kind: str = "") -> str:
    """A fresh temporary name for NAME: `.NAME.PID.HEX.KIND.tmp` (`.NAME.PID.HEX.tmp` without
    a kind)."""
    middle = f".{kind}" if kind else ""
    return f".{name}.{os.getpid()}.{secrets.token_hex(4)}{middle}{TMP_SUFFIX}"


def temp_beside(path: Path, kind: str = "") -> Path:
    """A fresh temporary name beside `path` (`temp_name` of its name, in its folder), that
    folder noted for `abandon`."""
    path = Path(path)
    _made_in.add(os.fspath(path.parent))
    return path.with_name(temp_name(path.name, kind))


def temp_path(parent: Path, name: str, kind: str) -> Path:
    """A temporary folder name of ours for PARENT/NAME that nothing holds yet (not created)."""
    while True:
        path = temp_beside(Path(parent) / name, kind)
        if _lstat(path) is None:
            return path


def make_temp(parent: Path, name: str, kind: str) -> Path:
    """A new empty temporary folder of ours for PARENT/NAME."""
    while True:
        path = temp_beside(Path(parent) / name, kind)
        try:
            os.mkdir(path)
            return path
        except FileExistsError:
            continue


def leftovers(parent: Path, name: str, kinds) -> list[tuple[Path, int, str]]:
    """(path, pid, kind) of the temporary folders of NAME in PARENT whose kind is in `kinds`,
    sorted; real folders only (a link with such a name is not one)."""
    pattern = re.compile(
        rf"\.{re.escape(name)}\.(?P<pid>\d+)\.[0-9a-f]{{8}}\.(?P<kind>[a-z]+){re.escape(TMP_SUFFIX)}"
    )
    try:
        entries = list(os.scandir(parent))
    except FileNotFoundError:
        return []
    out = []
    for entry in entries:
        m = pattern.fullmatch(entry.name)
        if m and m["kind"] in kinds and entry.is_dir(follow_symlinks=False):
            out.append((Path(entry.path), int(m["pid"]), m["kind"]))
    return sorted(out)


def newest_aside(found) -> Path | None:
    """The most recently moved old folder among `found` (from `leftovers`), or None."""
    aside = [path for path, _pid, kind in found if kind == OLD]
    return max(aside, key=_mtime) if aside else None


def recover(target: Path, found) -> None:
    """Undo what killed swaps of TARGET left: put the newest old folder aside among `found` back
    when TARGET is missing, then remove the rest of `found`."""
    with _renaming:
        back = newest_aside(found) if _lstat(target) is None else None
        if back is not None:
            os.rename(back, target)
    for path, _pid, _kind in found:
        if path != back:
            remove_tree(path)


def alive(pid: int) -> bool:
    """True when process `pid` runs (POSIX); elsewhere every other process counts as gone."""
    if os.name != "posix":
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return False
    return True


def exchange(a: Path, b: Path) -> bool:
    """Swap the names a and b in one atomic step; False when the system cannot."""
    libc = ctypes.CDLL(None, use_errno=True)
    renameat2 = getattr(libc, "renameat2", None)
    if renameat2 is None:
        return False
    done = renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if done == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(code, os.strerror(code), str(b))


def swap_in(new: Path, target: Path, *, atomic: bool = False) -> None:
    """Put the complete folder `new` at `target` and remove the folder it replaces.

    atomic: swap the two names in one step where the system can (else two renames).
    When a rename fails the old folder is put back (if it can be) and `new` is removed.
    """
    with _renaming:
        _swap_in(new, target, atomic)


def _swap_in(new: Path, target: Path, atomic: bool) -> None:
    parent, aside = Path(target).parent, None
    try:
        if _lstat(target) is not None:
            if atomic and exchange(new, target):
                fsync_dir(parent)
                remove_tree(new)  # now the old folder
                return
            aside = temp_path(parent, Path(target).name, OLD)
            os.rename(target, aside)
        os.rename(new, target)
    except BaseException:
        if aside is not None and _lstat(target) is None and _lstat(aside) is not None:
            try:
                os.rename(aside, target)
            except OSError:
                pass  # left aside whole, where `recover` finds it
        remove_tree(new)
        raise
    fsync_dir(parent)
    if aside is not None:
        remove_tree(aside)


def stop_renames(timeout: float) -> bool:
    """Wait up to `timeout` seconds for a swap under way to end, and let no other start in this
    process (for good: it is about to end); False when the swap did not end in time."""
    return _renaming.acquire(timeout=timeout)


def abandon() -> list[Path]:
    """Remove the temporary files and folders of this process (its pid in their names) from every
    folder it made one in, but an old folder moved aside (a swap cut between its two renames:
    `recover` puts it back); returns the targets of the folders removed (PARENT/NAME of each
    `.NAME.PID.HEX.KIND.tmp`), which are as they were before this process wrote them."""
    ours = re.compile(
        rf"\.(?P<name>.+)\.{os.getpid()}\.[0-9a-f]{{8}}"
        rf"(?:\.(?P<kind>[a-z]+))?{re.escape(TMP_SUFFIX)}"
    )
    undone = []
    for parent in sorted(_made_in):
        try:
            entries = list(os.scandir(parent))
        except OSError:  # gone with a staging folder removed before it
            continue
        for entry in sorted(entries, key=lambda e: e.name):
            m = ours.fullmatch(entry.name)
            if m is None or m["kind"] == OLD:
                continue
            if entry.is_dir(follow_symlinks=False):
                remove_tree(Path(entry.path))
                undone.append(Path(parent) / m["name"])
            else:
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)
    return undone


def fsync_dir(path: Path) -> None:
    """Flush a folder's entries to disk (where the platform allows opening a folder)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def remove_tree(path: Path) -> None:
    """Remove the temporary folder `path` of ours: links inside are removed, never followed;
    nothing is done unless `path` itself is a real folder."""
    st = _lstat(path)
    if st is not None and stat.S_ISDIR(st.st_mode):
        shutil.rmtree(path, ignore_errors=True)


def _lstat(path):
    try:
        return os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None


def _mtime(path: Path) -> int:
    st = _lstat(path)
    return st.st_mtime_ns if st is not None else 0
