"""One run per output folder, whole: the lock, the staging folder and the swap of `OUT/NAME`.

A run of scenario NAME into OUT takes `OUT/.NAME.lock` (an exclusive `flock` on a file holding the
writer's pid; the kernel drops it when the writer dies, so a dead writer's lock is simply taken
over) and writes every file into a fresh sibling folder `OUT/.NAME.PID.XXXXXXXX.run.tmp`. Only when
all of it is written does the staging folder take the place of `OUT/NAME`: in one atomic exchange
of the two names where the system offers one (Linux `renameat2`), else by moving the old folder
aside and the new one in, a step that the next run under the lock finishes if it was cut between
the two renames (the names, the swap and that recovery are `runner.output.swap`'s). So `OUT/NAME`
always holds one complete run, the old or the new. On any failure the staging folder is removed
and the old run stays as it was.

Nothing is followed through a symbolic link: a link at `OUT/NAME` or inside it is refused, and the
old folder is removed only when it holds nothing but the files a run writes, so a file a user put
there is never deleted (the run is refused and names it instead).

A process ended before its run is written (Ctrl-C that it did not answer in time,
runner.interrupt) leaves OUT as a failed run does: `abandon` removes its staging folders and
temporary files (runner.output.swap.abandon) and the lock files it holds.
"""

from __future__ import annotations

import contextlib
import os
import re
import stat
from pathlib import Path

from collide2d.runner.output import swap

try:
    import fcntl
except ImportError:  # pragma: no cover - not on POSIX
    fcntl = None

# The names a run writes in OUT/NAME (and `frames/frame_*.png` below it).
RUN_FILES = ("animation.gif", "events.jsonl", "final.csv", "summary.json", "viewer.html")
FRAME_FILE_RE = re.compile(r"^frame_\d{6,}\.png$")
STAGE = "run"  # the kind of a staging folder: `OUT/.NAME.PID.XXXXXXXX.run.tmp`

_held: set[Path] = set()  # the lock files of the RunLocks this process holds, for `abandon`


class OutputBusy(Exception):
    """Another live process holds the lock of OUT/NAME; str(err) says which."""


class OutputRefused(Exception):
    """OUT/NAME cannot be replaced safely (a link, or files no run writes); str(err) says why."""


class RunLock:
    """The lock of OUT/NAME, held for a `with` block; OutputBusy if a live writer holds it."""

    def __init__(self, root: Path, name: str):
        self.target = Path(root) / name
        self.path = Path(root) / f".{name}.lock"
        self.fd: int | None = None

    def __enter__(self) -> RunLock:
        if fcntl is None:  # pragma: no cover - no flock: one writer is the user's business
            return self
        while True:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o666)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.read(fd, 32).decode("ascii", "replace").strip() or "another process"
                os.close(fd)
                raise OutputBusy(
                    f"{self.target} is being written by process "
                    f"{holder} (lock {self.path}); wait for it to finish or use another --out"
                ) from None
            # the holder before us may have removed the file as we opened it: lock the live one
            try:
                same = os.path.samestat(os.fstat(fd), os.stat(self.path, follow_symlinks=False))
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode("ascii"))
        self.fd = fd
        _held.add(self.path)
        return self

    def __exit__(self, *exc) -> None:
        if self.fd is None:
            return
        _held.discard(self.path)
        with contextlib.suppress(FileNotFoundError):
            os.unlink(self.path)
        os.close(self.fd)  # releases the flock
        self.fd = None


def check_replaceable(target: Path) -> None:
    """Refuse a target that is a link, or holds anything but what a run writes."""
    if target.is_symlink():
        raise OutputRefused(
            f"output folder {target} is a symbolic link; refusing to write through it"
        )
    if not target.exists():
        return
    if not target.is_dir():
        raise OutputRefused(f"{target} is not a folder; refusing to replace it")
    foreign = []
    for entry in sorted(os.scandir(target), key=lambda e: e.name):
        mode = entry.stat(follow_symlinks=False).st_mode
        if entry.name == "frames" and stat.S_ISDIR(mode):
            for e in sorted(os.scandir(entry.path), key=lambda e: e.name):
                _refuse_link(e)
                if not (FRAME_FILE_RE.match(e.name) and e.is_file(follow_symlinks=False)):
                    foreign.append(f"frames/{e.name}")
            continue
        _refuse_link(entry)
        if entry.name not in RUN_FILES or not stat.S_ISREG(mode):
            foreign.append(entry.name)
    if foreign:
        shown = ", ".join(sorted(foreign)[:5]) + (", ..." if len(foreign) > 5 else "")
        raise OutputRefused(
            f"{target} holds files a run does not write ({shown}); a run replaces the whole "
            "folder, so move them away or use another --out"
        )


def _refuse_link(entry: os.DirEntry) -> None:
    if entry.is_symlink():
        raise OutputRefused(
            f"{entry.path} is a symbolic link; a run replaces its output folder whole and never "
            "follows or removes a link: remove it or use another --out"
        )


def clean_leftovers(root: Path, name: str) -> None:
    """Finish or undo what a killed run of NAME left in OUT; call with the lock held.

    Staging folders are removed. An old folder moved aside is put back when OUT/NAME is missing
    (the run was cut between its two renames), and removed otherwise.
    """
    swap.recover(Path(root) / name, swap.leftovers(root, name, (STAGE, swap.OLD)))


def abandon() -> list[Path]:
    """Undo the writes this process has not finished, as it is about to end: its staging folders
    and temporary files removed, its locks' files unlinked (the kernel drops the locks with the
    process). Returns the output folders whose new run was removed, as they were before it."""
    undone = swap.abandon()
    for path in list(_held):
        with contextlib.suppress(OSError):
            os.unlink(path)
    return undone


def new_stage(root: Path, name: str) -> Path:
    """A new empty staging folder for NAME in OUT."""
    return swap.make_temp(root, name, STAGE)


def swap_in(stage: Path, target: Path) -> None:
    """Put the complete staging folder at `target`, replacing the old run, and remove the old."""
    swap.swap_in(stage, target, atomic=True)
