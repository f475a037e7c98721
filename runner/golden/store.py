"""Golden storage: find the project, read a golden folder whole, write one atomically (SPEC §7).

Inputs: the project root (the nearest folder upward that has `scenarios/`) and, for a write, the
files of one golden as relative path -> bytes (from `serialize`). Outputs: `Golden` records read
back and checked against their manifest, and the list of files a write changed.

A write is queued and flushed in two phases. First every changed file goes to a temporary name next
to its target (flushed to disk); a failure here removes the temporaries and leaves the old golden
untouched. Then the temporaries are renamed into place, the manifest last; should a rename fail, the
files already replaced get their old bytes back. The manifest holds the hash of every other file, so
a golden torn some other way (the process killed between two renames) is reported as unreadable by
`read`, never trusted. Nothing is ever written when the `CI` environment variable is set, and a
golden folder is only removed by `remove` (the `--prune` of `bless`).
"""

from __future__ import annotations

import json
import os
import re
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from runner.golden import serialize as ser

GOLDENS_DIR = "goldens"
SCENARIOS_DIR = "scenarios"
SCENARIO_SUFFIXES = (".yaml", ".yml")
# Temporary files of a write: `.NAME.PID.tmp` next to their target.
TMP_SUFFIX = ".tmp"
# A golden folder's name: a scenario name that cannot leave goldens/ or hide as a dot-folder.
_NAME_RE = re.compile(r"[a-z0-9_-][a-z0-9._-]*")
# Values of CI that mean "not in CI".
_CI_OFF = ("", "0", "false", "no")


class GoldenError(Exception):
    """A golden cannot be used as asked; str(err) is the message for the user."""


class GoldenMissing(GoldenError):
    """The scenario has no golden yet."""


class GoldenUnreadable(GoldenError):
    """The golden folder exists but is damaged, torn or of another format."""


class WritesRefused(GoldenError):
    """Writing goldens is refused (the CI environment variable is set)."""


def ci_active(environ=None) -> bool:
    """True when the CI environment variable is set to anything but '', 0, false or no."""
    env = os.environ if environ is None else environ
    return "CI" in env and env["CI"].strip().lower() not in _CI_OFF


def find_root(start=None) -> Path:
    """The nearest folder at or above `start` (default: the current directory) with `scenarios/`."""
    here = Path(start if start is not None else os.getcwd()).resolve()
    for folder in (here, *here.parents):
        if (folder / SCENARIOS_DIR).is_dir():
            return folder
    raise GoldenError(
        f"no {SCENARIOS_DIR}/ folder in {here} or above it; run from the project or pass --root DIR"
    )


def scenario_files(root) -> list[Path]:
    """Every scenario file in ROOT/scenarios/, sorted by file name."""
    folder = Path(root) / SCENARIOS_DIR
    if not folder.is_dir():
        return []
    files = [p for p in folder.iterdir() if p.suffix in SCENARIO_SUFFIXES and p.is_file()]
    return sorted(files, key=lambda p: p.name)


def check_name(name: str) -> str:
    """`name` if it can name a golden folder, else GoldenError."""
    if not isinstance(name, str) or not _NAME_RE.fullmatch(name):
        raise GoldenError(f"{name!r} cannot name a golden folder (use [a-z0-9._-], no leading dot)")
    return name


@dataclass(frozen=True)
class Golden:
    """One golden read back whole and checked against its manifest.

    events  list of event objects as in events.jsonl
    final   (n, 4) float64 rows x, y (px), vx, vy (px/s)
    frames  frame number -> (H, W, 3) uint8 RGB decoded pixels
    files   relative path -> the bytes read, for every file the manifest names and the manifest
    """

    name: str
    folder: Path
    manifest: dict
    events: list
    final: np.ndarray
    frames: dict
    files: dict = field(repr=False)


class GoldenStore:
    """The goldens of one project: ROOT/goldens/NAME/ per scenario."""

    def __init__(self, root):
        self.root = Path(root)
        self.dir = self.root / GOLDENS_DIR

    def folder(self, name: str) -> Path:
        return self.dir / check_name(name)

    def names(self) -> list[str]:
        """The golden folders present, sorted (temporary and hidden entries left out)."""
        if not self.dir.is_dir():
            return []
        return sorted(
            p.name for p in self.dir.iterdir() if p.is_dir() and _NAME_RE.fullmatch(p.name)
        )

    def unused(self, used) -> list[str]:
        """The golden folders that no name in `used` claims, sorted."""
        used = set(used)
        return [n for n in self.names() if n not in used]

    def read(self, name: str) -> Golden:
        """Golden `name`, every file checked against the manifest's hashes.

        Raises GoldenMissing when there is no golden, GoldenUnreadable when it cannot be trusted.
        """
        folder = self.folder(name)
        mpath = folder / ser.MANIFEST_FILE
        if not folder.is_dir():
            raise GoldenMissing(f"no golden for {name}: {shown_path(folder)} does not exist")
        if not mpath.is_file():
            raise GoldenMissing(
                f"no golden for {name}: {shown_path(folder)} has no {ser.MANIFEST_FILE} "
                "(an interrupted first bless?)"
            )
        files = {ser.MANIFEST_FILE: mpath.read_bytes()}
        try:
            manifest = json.loads(files[ser.MANIFEST_FILE])
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            msg = f"golden {name}: {shown_path(mpath)} is not JSON ({exc})"
            raise GoldenUnreadable(msg) from None
        fmt = manifest.get("format") if isinstance(manifest, dict) else None
        if fmt != ser.FORMAT_VERSION:
            raise GoldenUnreadable(
                f"golden {name} has format {fmt!r}; this collide2d reads format "
                f"{ser.FORMAT_VERSION}: bless it again"
            )
        try:
            events = ser.parse_events(self._checked(name, folder, manifest["events"], files))
            final = ser.parse_final(self._checked(name, folder, manifest["final"], files))
            frames = {}
            for entry in manifest["frames"]:
                data = self._file(name, folder, entry["file"], files)
                rgb = ser.decode_png(data)
                if ser.pixel_sha256(rgb) != entry["pixels_sha256"]:
                    raise GoldenUnreadable(_torn(name, folder / entry["file"]))
                frames[int(entry["frame"])] = rgb
        except (KeyError, TypeError, ValueError, OSError) as exc:
            raise GoldenUnreadable(f"golden {name} cannot be read: {exc}") from None
        return Golden(name, folder, manifest, events, final, frames, files)

    def _file(self, name, folder, rel, files) -> bytes:
        path = folder / rel
        if not path.is_file():
            raise GoldenUnreadable(f"golden {name}: {shown_path(path)} is missing; bless it again")
        files[rel] = path.read_bytes()
        return files[rel]

    def _checked(self, name, folder, entry, files) -> bytes:
        data = self._file(name, folder, entry["file"], files)
        if ser.sha256_bytes(data) != entry["sha256"]:
            raise GoldenUnreadable(_torn(name, folder / entry["file"]))
        return data

    def write(self, name: str, files: dict) -> list[str]:
        """Write golden `name` from `files` (relative path -> bytes, which must include the
        manifest); returns the relative paths whose bytes changed, sorted. Files equal to what is
        on disk are left alone; frame PNGs the manifest no longer names are removed afterwards.
        """
        if ci_active():
            raise WritesRefused(_ci_message())
        if ser.MANIFEST_FILE not in files:
            raise ValueError(f"a golden write needs {ser.MANIFEST_FILE}")
        folder = self.folder(name)
        for rel in files:
            _check_rel(rel)
        folder.mkdir(parents=True, exist_ok=True)
        _remove_temporaries(folder)
        order = sorted(r for r in files if r != ser.MANIFEST_FILE) + [ser.MANIFEST_FILE]
        old = {}
        for rel in order:
            path = folder / rel
            old[rel] = path.read_bytes() if path.is_file() else None
        changed = [rel for rel in order if old[rel] != files[rel]]
        # Phase 1: every changed file to a temporary name; on failure nothing in place changed.
        temps = {}
        try:
            for rel in changed:
                target = folder / rel
                target.parent.mkdir(parents=True, exist_ok=True)
                temps[rel] = _temp_name(target)
                _write_temp(temps[rel], files[rel])
        except BaseException:
            _discard(temps.values())
            raise
        # Phase 2: rename into place, the manifest last; on failure put the old bytes back.
        done = []
        try:
            for rel in changed:
                os.replace(temps[rel], folder / rel)
                done.append(rel)
        except BaseException:
            _discard(temps[rel] for rel in changed if rel not in done)
            for rel in reversed(done):
                _restore(folder / rel, old[rel])
            raise
        keep = set(files)
        frames_dir = folder / ser.FRAMES_DIR
        if frames_dir.is_dir():
            for png in sorted(frames_dir.glob("frame_*.png")):
                if f"{ser.FRAMES_DIR}/{png.name}" not in keep:
                    png.unlink()
        return sorted(changed)

    def remove(self, name: str) -> None:
        """Delete golden folder `name` (what `bless --prune` does to an unused golden)."""
        if ci_active():
            raise WritesRefused(_ci_message())
        folder = self.folder(name)
        if folder.is_dir():
            shutil.rmtree(folder)


def _ci_message() -> str:
    return (
        "CI is set: goldens are never written in CI; bless locally and commit goldens/ "
        "(or unset CI)"
    )


def _torn(name: str, path: Path) -> str:
    return (
        f"golden {name}: {shown_path(path)} does not match {ser.MANIFEST_FILE} (edited by hand "
        "or an interrupted bless); bless it again"
    )


def shown_path(path) -> str:
    """A path as the user would type it, with forward slashes: relative to the current directory
    when it lies inside it, else as given."""
    path = Path(path)
    try:
        rel = Path(os.path.relpath(path.resolve()))
    except ValueError:
        return path.as_posix()
    return path.as_posix() if rel.parts[:1] == ("..",) else rel.as_posix()


def _check_rel(rel: str) -> None:
    parts = Path(rel).parts
    if Path(rel).is_absolute() or not parts or any(p in ("..", ".") for p in parts):
        raise ValueError(f"golden file {rel!r} must be a plain relative path")


def _temp_name(target: Path) -> Path:
    return target.with_name(f".{target.name}.{os.getpid()}{TMP_SUFFIX}")


def _write_temp(path: Path, data: bytes) -> None:
    """Write `data` to `path` and flush it to disk."""
    with open(path, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())


def _discard(paths) -> None:
    for p in paths:
        try:
            os.unlink(p)
        except FileNotFoundError:
            pass


def _restore(path: Path, data: bytes | None) -> None:
    """Put `data` back at `path` (None: the file did not exist before)."""
    if data is None:
        _discard([path])
        return
    tmp = _temp_name(path)
    _write_temp(tmp, data)
    os.replace(tmp, path)


def _remove_temporaries(folder: Path) -> None:
    """Remove temporaries an interrupted write of this folder left behind."""
    for tmp in sorted(folder.rglob(f".*{TMP_SUFFIX}")):
        if tmp.is_file():
            tmp.unlink()
