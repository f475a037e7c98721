"""Golden storage: find the project, read a golden folder whole, swap one in whole
(docs/goldens.md).

Inputs: the project root (the nearest folder upward that has `scenarios/`) and, for a write, the
files of one golden as relative path -> bytes (from `serialize`). Outputs: `Golden` records read
back and checked against their manifest, and the list of files a write changed.

Confinement. Everything stays inside ROOT/goldens/NAME/: nothing is read, written or removed
through a symbolic link (goldens/ itself, a golden folder, or any entry in one), the paths that
manifest.json names must be plain relative paths inside the golden, and every file is read with a
size bound. A link is refused with a message naming it, never followed. Hostile content (deep JSON,
numbers past range, a frame that is not a PNG or whose header claims more pixels than the manifest
or the bound allow) makes the golden `GoldenUnreadable` with a clear message, read before decoding.

A write builds the whole new golden in a sibling temporary folder `goldens/.NAME.PID.HEX.new.tmp/`
(every file flushed to disk), then swaps it in with two renames: the old folder aside to
`.NAME.PID.HEX.old.tmp`, the new one into place; only then is the old one removed. A kill at any
instant leaves either the old golden whole or the new one whole: between the two renames the old
golden waits whole under its aside name, where `read` finds it and the next write puts it back.
Leftovers are recognised by that exact name pattern, only as real folders, and a live process's own
temporaries are left alone (the names, the swap and the recovery are `runner.output.swap`'s). A
golden whose files all equal what is on disk is not rewritten. Nothing is ever written when the `CI`
environment variable is set, and a golden folder is only removed by `remove` (the `--prune` of
`bless`), and only when it holds a golden's manifest (`is_golden`): a folder of anything else is
never listed as an unused golden, nor removed.
"""

from __future__ import annotations

import json
import os
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from collide2d.runner.golden import serialize
from collide2d.runner.output import swap
from collide2d.runner.scenario.load import NAME_PATTERN

GOLDENS_DIR = "goldens"
SCENARIOS_DIR = "scenarios"
SCENARIO_SUFFIXES = (".yaml", ".yml")
# The kinds of a write's temporary folders next to goldens/NAME: `.NAME.PID.HEX.new.tmp` (the new
# golden being built) and `.NAME.PID.HEX.old.tmp` (the old golden moved aside during the swap).
NEW, OLD = "new", swap.OLD
# A golden folder's name: a scenario name that cannot leave goldens/ or hide as a dot-folder.
_NAME_RE = re.compile(NAME_PATTERN)
# Values of CI that mean "not in CI".
_CI_OFF = ("", "0", "false", "no")
# The largest golden file read, in bytes (a golden folder stays within a few MB, docs/goldens.md).
MAX_FILE_BYTES = 64 * 1024 * 1024
# The most pixels a golden frame may have when the run's own frames are smaller: a PNG header
# past this (or past the run's largest frame) is refused before anything is decoded.
DEFAULT_MAX_FRAME_PIXELS = 1 << 24

_O_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_O_BINARY = getattr(os, "O_BINARY", 0)
_O_NONBLOCK = getattr(os, "O_NONBLOCK", 0)


class GoldenError(Exception):
    """A golden cannot be used as asked; str(err) is the message for the user."""


class GoldenMissing(GoldenError):
    """The scenario has no golden yet."""


class GoldenUnreadable(GoldenError):
    """The golden folder exists but is damaged, torn, of another format or refused (a link)."""


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


def scenario_files(root, folder: str = SCENARIOS_DIR) -> list[Path]:
    """Every scenario file in ROOT/scenarios/ (or ROOT/FOLDER), sorted by file name."""
    folder = Path(root) / folder
    if not folder.is_dir():
        return []
    files = [p for p in folder.iterdir() if p.suffix in SCENARIO_SUFFIXES and p.is_file()]
    return sorted(files, key=lambda p: p.name)


def same_names(named) -> dict:
    """The refusal of scenario files that share a name, a golden belonging to one scenario:
    {path: message} for every file of `named` ((path, name) pairs, in order) whose name another
    file has too; {} when every name is its own. `check`, `bless` and the pytest plugin refuse
    by this one rule."""
    by_name: dict = {}
    for path, name in named:
        by_name.setdefault(name, []).append(path)
    refused = {}
    for name, paths in by_name.items():
        if len(paths) > 1:
            message = (
                f"{shown_path(paths[1])} and {shown_path(paths[0])} are both named {name!r}; "
                "a golden belongs to one scenario"
            )
            refused.update((p, message) for p in paths)
    return refused


def check_name(name: str) -> str:
    """`name` if it can name a golden folder, else GoldenError."""
    if not isinstance(name, str) or not _NAME_RE.fullmatch(name):
        raise GoldenError(f"{name!r} cannot name a golden folder (use [a-z0-9._-], no leading dot)")
    return name


def link_message(path, what: str = "goldens") -> str:
    """The refusal of a symbolic link at `path`."""
    return (
        f"{shown_path(path)} is a symbolic link; {what} are never read, written or removed "
        "through a link (replace it with a real folder or file)"
    )


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

    def __init__(self, root, goldens: str = GOLDENS_DIR):
        self.root = Path(root)
        self.dir = self.root / goldens

    def folder(self, name: str) -> Path:
        return self.dir / check_name(name)

    def check_dir(self) -> None:
        """GoldenError when goldens/ is a symbolic link or not a folder (absent is fine)."""
        st = _lstat(self.dir)
        if st is not None and stat.S_ISLNK(st.st_mode):
            raise GoldenError(link_message(self.dir))
        if st is not None and not stat.S_ISDIR(st.st_mode):
            raise GoldenError(f"{shown_path(self.dir)} is not a folder")

    def names(self) -> list[str]:
        """The golden folders present, sorted: the folders holding a golden's manifest
        (`is_golden`); temporary and hidden entries, and folders of anything else, left out. A
        link with a golden's name is listed, and refused by whatever then uses it."""
        self.check_dir()
        if _lstat(self.dir) is None:
            return []
        out = []
        for entry in os.scandir(self.dir):
            if not _NAME_RE.fullmatch(entry.name):
                continue
            if entry.is_symlink() or (
                entry.is_dir(follow_symlinks=False) and is_golden(Path(entry.path))
            ):
                out.append(entry.name)
        return sorted(out)

    def unused(self, used) -> list[str]:
        """The golden folders that no name in `used` claims, sorted."""
        used = set(used)
        return [n for n in self.names() if n not in used]

    # ---------------------------------------------------------------------------------- reading

    def read(self, name: str, *, max_frame_pixels: int = DEFAULT_MAX_FRAME_PIXELS) -> Golden:
        """Golden `name`, every file checked against the manifest's hashes.

        max_frame_pixels: a frame whose PNG header claims more pixels is refused undecoded.
        Raises GoldenMissing when there is no golden, GoldenUnreadable when it cannot be trusted
        (damaged, torn, hostile, or reached through a symbolic link).
        """
        folder = self.folder(name)
        try:
            self.check_dir()
        except GoldenError as exc:
            raise GoldenUnreadable(f"golden {name}: {exc}") from None
        st = _lstat(folder)
        if st is None:
            # A write killed between its two renames left the old golden whole, aside.
            aside = swap.newest_aside(self._leftovers(name))
            if aside is None:
                raise GoldenMissing(f"no golden for {name}: {shown_path(folder)} does not exist")
            folder = aside
        elif stat.S_ISLNK(st.st_mode):
            raise GoldenUnreadable(f"golden {name}: {link_message(folder)}")
        elif not stat.S_ISDIR(st.st_mode):
            raise GoldenUnreadable(f"golden {name}: {shown_path(folder)} is not a folder")
        return _read_folder(name, folder, max_frame_pixels)

    # ---------------------------------------------------------------------------------- writing

    def write(self, name: str, files: dict) -> list[str]:
        """Write golden `name` from `files` (relative path -> bytes, which must include the
        manifest); returns the relative paths whose bytes changed, sorted. When every file equals
        what is on disk and nothing else is there, nothing is touched; otherwise the whole folder
        is swapped in (see the module's notes), so files the manifest no longer names go away.
        Raises GoldenError when a link stands in the way.
        """
        if ci_active():
            raise WritesRefused(_ci_message())
        if serialize.MANIFEST_FILE not in files:
            raise ValueError(f"a golden write needs {serialize.MANIFEST_FILE}")
        for rel in files:
            serialize.check_rel(rel)
        folder = self.folder(name)
        self.check_dir()
        self.dir.mkdir(parents=True, exist_ok=True)
        self.check_dir()
        self.recover(name)
        st = _lstat(folder)
        if st is not None and stat.S_ISLNK(st.st_mode):
            raise GoldenError(link_message(folder))
        if st is not None and not stat.S_ISDIR(st.st_mode):
            raise GoldenError(f"{shown_path(folder)} is not a folder; remove it and bless again")
        old, extra = _current_files(folder, files) if st is not None else ({}, False)
        changed = sorted(rel for rel in files if old.get(rel) != files[rel])
        if not changed and not extra:
            return []
        new = swap.make_temp(self.dir, name, NEW)
        try:
            _build(new, files)
        except BaseException:
            swap.remove_tree(new)
            raise
        swap.swap_in(new, folder)  # two renames: a kill between them is what `read` handles
        return changed

    def remove(self, name: str) -> None:
        """Delete golden folder `name` (what `bless --prune` does to an unused golden)."""
        if ci_active():
            raise WritesRefused(_ci_message())
        folder = self.folder(name)
        self.check_dir()
        st = _lstat(folder)
        if st is None:
            return
        if stat.S_ISLNK(st.st_mode):
            raise GoldenError(link_message(folder))
        if not stat.S_ISDIR(st.st_mode):
            raise GoldenError(f"{shown_path(folder)} is not a folder; remove it by hand")
        if not is_golden(folder):
            raise GoldenError(
                f"{shown_path(folder)} holds no golden's {serialize.MANIFEST_FILE}; it is not a "
                "golden, and is left alone"
            )
        aside = swap.temp_path(self.dir, name, OLD)
        os.rename(folder, aside)
        swap.remove_tree(aside)

    def recover(self, name: str) -> None:
        """Tidy what interrupted writes of golden `name` left: put an old golden moved aside back
        when no golden is in place, then remove the leftover temporary folders (only real folders
        named as ours, never a live process's)."""
        if ci_active() or _lstat(self.dir) is None:
            return
        self.check_dir()
        folder = self.folder(name)
        ours = [x for x in self._leftovers(name) if x[1] == os.getpid() or not swap.alive(x[1])]
        swap.recover(folder, ours)

    def _leftovers(self, name: str) -> list[tuple[Path, int, str]]:
        """(path, pid, kind) of the temporary folders of golden `name` in goldens/, real folders
        only."""
        return swap.leftovers(self.dir, check_name(name), (NEW, OLD))


def is_golden(folder: Path) -> bool:
    """Whether `folder` holds a golden's manifest: a regular file manifest.json (not a link) whose
    JSON object names a format and a scenario. Only such folders are goldens that `unused` lists
    and `remove` deletes; any other folder is left alone."""
    try:
        manifest = serialize.load_json(_read_regular(folder / serialize.MANIFEST_FILE, folder.name))
    except (GoldenError, ValueError):
        return False
    return isinstance(manifest, dict) and "format" in manifest and "scenario" in manifest


def _ci_message() -> str:
    return (
        "CI is set: goldens are never written in CI; bless locally and commit goldens/ "
        "(or unset CI)"
    )


def _torn(name: str, path: Path) -> str:
    return (
        f"golden {name}: {shown_path(path)} does not match {serialize.MANIFEST_FILE} (edited by "
        "hand or an interrupted bless); bless it again"
    )


def shown_path(path) -> str:
    """A path as the user would type it, with forward slashes: relative to the current directory
    when it lies inside it, else as given. The last component is shown as it is named (a link is
    not replaced by its target)."""
    path = Path(path)
    try:
        real = Path(os.path.realpath(path.parent)) / path.name
        rel = Path(os.path.relpath(real))
    except ValueError:
        return path.as_posix()
    return path.as_posix() if rel.parts[:1] == ("..",) else rel.as_posix()


# ---------------------------------------------------------------------------------- safe files


def _lstat(path):
    try:
        return os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None


def _below(base: Path, rel: str, name: str) -> Path:
    """base/rel, after checking that no component below `base` is a symbolic link."""
    path = base
    for part in rel.split("/"):
        path = path / part
        st = _lstat(path)
        if st is not None and stat.S_ISLNK(st.st_mode):
            raise GoldenUnreadable(f"golden {name}: {link_message(path)}")
    return path


def _read_regular(path: Path, name: str, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of the regular file `path` (opened without following a link), at most `limit`."""
    try:
        fd = os.open(path, os.O_RDONLY | _O_NOFOLLOW | _O_BINARY | _O_NONBLOCK)
    except FileNotFoundError:
        raise GoldenUnreadable(
            f"golden {name}: {shown_path(path)} is missing; bless it again"
        ) from None
    except OSError as exc:
        if _lstat(path) is not None and stat.S_ISLNK(os.lstat(path).st_mode):
            raise GoldenUnreadable(f"golden {name}: {link_message(path)}") from None
        raise GoldenUnreadable(f"golden {name}: {shown_path(path)}: {exc.strerror}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise GoldenUnreadable(f"golden {name}: {shown_path(path)} is not a regular file")
        if st.st_size > limit:
            raise GoldenUnreadable(
                f"golden {name}: {shown_path(path)} has {st.st_size} bytes, past the "
                f"{limit} a golden file may have"
            )
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:
            raise GoldenUnreadable(f"golden {name}: {shown_path(path)} grew past {limit} bytes")
        return b"".join(chunks)
    finally:
        os.close(fd)


def _read_folder(name: str, folder: Path, max_frame_pixels: int) -> Golden:
    mpath = folder / serialize.MANIFEST_FILE
    if _lstat(mpath) is None:
        raise GoldenMissing(
            f"no golden for {name}: {shown_path(folder)} has no {serialize.MANIFEST_FILE} "
            "(an interrupted first bless?)"
        )
    files = {}

    def load(rel: str) -> bytes:
        files[rel] = _read_regular(_below(folder, rel, name), name)
        return files[rel]

    def checked(entry: dict) -> bytes:
        data = load(entry["file"])
        if serialize.sha256_bytes(data) != entry["sha256"]:
            raise GoldenUnreadable(_torn(name, folder / entry["file"]))
        return data

    def unreadable(rel: str, exc: Exception) -> GoldenUnreadable:
        return GoldenUnreadable(f"golden {name}: {shown_path(folder / rel)}: {exc}; bless it again")

    try:
        manifest = serialize.load_json(load(serialize.MANIFEST_FILE))
    except ValueError as exc:
        raise unreadable(serialize.MANIFEST_FILE, exc) from None
    fmt = manifest.get("format") if isinstance(manifest, dict) else None
    if fmt != serialize.FORMAT_VERSION or isinstance(fmt, bool):
        raise GoldenUnreadable(
            f"golden {name} has format {json.dumps(fmt)[:40]}; this collide2d reads format "
            f"{serialize.FORMAT_VERSION}: bless it again"
        )
    try:
        serialize.check_manifest(manifest)
    except ValueError as exc:
        raise unreadable(serialize.MANIFEST_FILE, exc) from None
    try:
        events = serialize.parse_events(checked(manifest["events"]))
    except ValueError as exc:
        raise unreadable(serialize.EVENTS_FILE, exc) from None
    try:
        final = serialize.parse_final(checked(manifest["final"]))
    except ValueError as exc:
        raise unreadable(serialize.FINAL_FILE, exc) from None
    frames = {}
    for entry in manifest["frames"]:
        rel = entry["file"]
        try:
            rgb = serialize.decode_png(
                load(rel),
                size=(entry["width"], entry["height"]),
                max_pixels=max_frame_pixels,
            )
        except ValueError as exc:
            raise unreadable(rel, exc) from None
        if serialize.pixel_sha256(rgb) != entry["pixels_sha256"]:
            raise GoldenUnreadable(_torn(name, folder / rel))
        frames[entry["frame"]] = rgb
    return Golden(name, folder, manifest, events, final, frames, files)


def _current_files(folder: Path, wanted: dict) -> tuple[dict, bool]:
    """({rel: bytes} of the files of `wanted` present in `folder`, whether anything else is
    there). GoldenError when a symbolic link is inside."""
    found, extra = {}, False
    for dirpath, dirnames, filenames in os.walk(folder, followlinks=False):
        for entry in (*dirnames, *filenames):
            path = Path(dirpath) / entry
            st = os.lstat(path)
            if stat.S_ISLNK(st.st_mode):
                raise GoldenError(link_message(path))
            rel = path.relative_to(folder).as_posix()
            if stat.S_ISDIR(st.st_mode):
                extra = extra or not any(w.startswith(rel + "/") for w in wanted)
            elif rel in wanted and stat.S_ISREG(st.st_mode) and st.st_size <= MAX_FILE_BYTES:
                found[rel] = _read_regular(path, folder.name)
            else:
                extra = True
    return found, extra


def _build(folder: Path, files: dict) -> None:
    """Write `files` into the new empty `folder`, each flushed to disk, then the folders."""
    dirs = {folder}
    for rel in sorted(files):
        path = folder / rel
        if path.parent not in dirs:
            path.parent.mkdir(parents=True, exist_ok=True)
            dirs.add(path.parent)
        _write_new(path, files[rel])
    for d in sorted(dirs, key=lambda p: -len(p.parts)):
        swap.fsync_dir(d)


def _write_new(path: Path, data: bytes) -> None:
    """Create `path` (never through a link: it must not exist) with `data`, flushed to disk."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | _O_NOFOLLOW | _O_BINARY
    fd = os.open(path, flags, 0o666)
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view) :]
        os.fsync(fd)
    finally:
        os.close(fd)
