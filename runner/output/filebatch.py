"""A few files written all or nothing (`collide2d init`): every file whole, or none changed.

`FileBatch.add(target, data, old)` stages the new bytes of a file (`old`: its current bytes, None
for a file to create); `commit()` writes them. Each file is written whole under a temporary name in
its target's folder (`.NAME.PID.HEX.tmp`, as `runner.output.files` names its temporaries), with the
permission bits of the file it replaces; only once every one is written are they renamed over their
targets, one by one. When a write fails (a full disk, a refused permission) every temporary is
removed and no target has changed; when a rename fails (rare: each temporary already sits beside its
target), the targets renamed before it get their old bytes back the same way, and a file created is
removed. Folders made for the files are removed again when the batch fails, if still empty. The
OSError is then raised, naming the file. (Nothing is flushed to disk: like every output, this guards
against a failed write or a killed process, not against a power cut.)

Targets are paths as they are written: a caller that must not write through a symbolic link
resolves and checks them first (`runner.command.newproject` does).
"""

from __future__ import annotations

import contextlib
import os
import stat
from dataclasses import dataclass
from pathlib import Path

from collide2d.runner.output.swap import temp_beside


@dataclass
class _Staged:
    target: Path
    data: bytes
    old: bytes | None
    tmp: Path | None = None


class FileBatch:
    """Files staged with `add` and written all or nothing by `commit`."""

    def __init__(self):
        self.files: list[_Staged] = []

    def add(self, target, data: bytes, old: bytes | None) -> None:
        """Stage `data` as the new content of `target`; `old` its content now (None: new file)."""
        self.files.append(_Staged(Path(target), bytes(data), old))

    def commit(self) -> None:
        """Write every staged file, or, on an OSError, none (see the module docstring)."""
        made: list[Path] = []
        done: list[_Staged] = []
        current = None
        try:
            for current in self.files:
                made.extend(_make_folders(current.target.parent))
                current.tmp = _write_temp(current.target, current.data)
            for current in self.files:
                os.replace(current.tmp, current.target)
                current.tmp = None
                done.append(current)
        except OSError as exc:
            for f in self.files:
                if f.tmp is not None:
                    _remove(f.tmp)
                    f.tmp = None
            for f in reversed(done):
                _put_back(f)
            for folder in reversed(made):
                with contextlib.suppress(OSError):
                    folder.rmdir()
            if not exc.filename and current is not None:
                exc.filename = str(current.target)
            raise


def _make_folders(folder: Path) -> list[Path]:
    """Make `folder` and its missing parents; returns the ones made, outermost first."""
    missing = []
    while not folder.exists():
        missing.append(folder)
        folder = folder.parent
    for path in reversed(missing):
        path.mkdir()
    return missing[::-1]


def _write_temp(target: Path, data: bytes) -> Path:
    """A new temporary file beside `target` holding `data`, with `target`'s permission bits when
    it exists (else 0o666 less the umask, as any new file). An OSError names `target`."""
    tmp = None
    try:
        try:
            mode = stat.S_IMODE(os.stat(target).st_mode)
        except FileNotFoundError:
            mode = None
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
        while tmp is None:
            candidate = temp_beside(target)
            with contextlib.suppress(FileExistsError):
                fd = os.open(candidate, flags, 0o666)
                tmp = candidate
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        if mode is not None:
            os.chmod(tmp, mode)
    except OSError as exc:
        if tmp is not None:
            _remove(tmp)
        exc.filename = str(target)
        raise
    return tmp


def _put_back(f: _Staged) -> None:
    """Undo a rename already done: the old bytes back, or the created file removed."""
    with contextlib.suppress(OSError):
        if f.old is None:
            os.unlink(f.target)
        else:
            os.replace(_write_temp(f.target, f.old), f.target)


def _remove(path: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)
