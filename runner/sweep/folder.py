"""OUT/sweep/ whole, as a run folder is: the lock, the staging folder and the swap.

A sweep into OUT takes `OUT/.sweep.lock` (`runner.output.folder.RunLock`: a second sweep, or a run
of a scenario named `sweep`, into the same OUT is refused while it is held, naming the process that
holds it) for as long as it runs, writes its files into a fresh sibling staging folder and, only
when all of them are written, swaps it in for `OUT/sweep` (`runner.output.folder.swap_in`). So
`OUT/sweep/` always holds one whole sweep, the old or the new; on any failure the staging folder
goes and the old sweep stays. What a killed sweep left is finished or removed by the next one
(`runner.output.folder.clean_leftovers`).

Nothing is followed through a symbolic link, and the old folder is replaced only when it holds
nothing but the files a sweep writes (SWEEP_FILES): a file a user put there is never deleted.
"""

from __future__ import annotations

import contextlib
import os
import stat
from pathlib import Path

from collide2d.runner.output import files, folder, swap

NAME = "sweep"
SWEEP_FILES = ("results.csv", "results.md", "sweep.json", "runtime_vs_error.png")


class FolderRefused(Exception):
    """OUT/sweep cannot be replaced safely, or another process writes it; str says why."""


def check_replaceable(root) -> Path:
    """OUT/sweep, refused when it is a link, not a folder, or holds what a sweep does not write."""
    target = Path(root) / NAME
    if target.is_symlink():
        raise FolderRefused(f"{target} is a symbolic link; name another folder")
    if not target.exists():
        return target
    if not target.is_dir():
        raise FolderRefused(f"{target} is not a folder; refusing to replace it")
    foreign = []
    for entry in sorted(os.scandir(target), key=lambda e: e.name):
        mode = entry.stat(follow_symlinks=False).st_mode
        if entry.name not in SWEEP_FILES or not stat.S_ISREG(mode):
            foreign.append(entry.name)
    if foreign:
        shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
        raise FolderRefused(
            f"{target} holds files a sweep does not write ({shown}); a sweep replaces the whole "
            "folder, so move them away or use another --out"
        )
    return target


@contextlib.contextmanager
def staged(root):
    """A `with` block holding OUT/sweep's lock and giving an empty staging folder, swapped in for
    OUT/sweep when the block ends normally and removed otherwise (and OUT with it when this made
    it and it is left empty: a sweep refused once its runs went, docs/how-to/dask.md, leaves
    nothing)."""
    root = Path(root)
    check_replaceable(root)
    made = not os.path.lexists(root)
    files.make_folder(root)
    try:
        lock = folder.RunLock(root, NAME).__enter__()
    except folder.OutputBusy as exc:
        raise FolderRefused(str(exc)) from None
    swapped = False
    try:
        folder.clean_leftovers(root, NAME)
        target = check_replaceable(root)  # again, now that no other sweep can change it
        stage = folder.new_stage(root, NAME)
        try:
            yield stage
            folder.swap_in(stage, target)
            swapped = True
        except BaseException:
            swap.remove_tree(stage)
            raise
    finally:
        lock.__exit__(None, None, None)
        if made and not swapped:
            with contextlib.suppress(OSError):  # not empty: another sweep's, or a user's, now
                root.rmdir()
