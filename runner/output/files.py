"""The files a run writes (docs/outputs.md): PNG frames, GIF, events.jsonl, final.csv, summary.json.

Input: RGB pictures `(H, W, 3) uint8`, palette-index frames `(H, W) uint8` with the scenario's
palette `(k, 3) uint8`, event records (`engine.events.EVENT_DTYPE`), final positions and
velocities, and plain JSON objects. Output: files on disk, written so that a killed run never leaves
half of one: every file is written under a temporary name in its own folder
(`.NAME.PID.RANDOM.tmp`) and renamed over `NAME` with `os.replace` only once it is whole, so a
reader sees the old file or the new one. (This guards against a killed process; it does not fsync,
which would cost a disk flush per frame, so a power cut may still lose the newest files.)

Encodings are deterministic: the same input gives the same bytes. PNGs carry no metadata and use a
fixed compression level. The GIF streams frame by frame to disk with exact palette colours, looping
forever, with whole-centisecond delays scheduled by `GifSchedule` so that its total length is the
run's length to the centisecond.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from PIL import GifImagePlugin, Image

from collide2d.engine.events import event_dict, format_event, format_number
from collide2d.runner.output import escape, swap

# zlib level of every PNG (0-9): fixed so that the same pixels give the same bytes.
PNG_COMPRESS_LEVEL = 6
# The shortest GIF frame delay browsers show as written, in centiseconds; shorter ones are
# stretched (usually to 10 cs), so at most 100 / GIF_MIN_DELAY_CS frames per second are kept.
GIF_MIN_DELAY_CS = 2
GIF_MAX_FPS = 100 // GIF_MIN_DELAY_CS
# A GIF delay is an unsigned 16-bit number of centiseconds.
GIF_MAX_DELAY_CS = 65535
# A GIF colour table has at most this many colours.
GIF_MAX_COLORS = 256

# Events formatted and written at once by EventsWriter: bounds the text held in memory (~5 MB).
EVENTS_PER_WRITE = 65_536

# A temporary file of NAME: `.NAME.PID.HEX.tmp` (`swapdir.temp_name` without a kind).
_TEMP_RE = re.compile(r"^\..+\.\d+\.[0-9a-f]{8}\.tmp$")


# --------------------------------------------------------------------------------------------
# Atomic files


def _open_temp(path: Path) -> tuple[Path, int]:
    """Create a new empty file next to `path`, only ours; returns (its path, an open write fd).

    The mode is 0o666 less the umask, as for any new file, so the renamed result has the usual
    permissions.
    """
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    while True:
        tmp = swap.temp_beside(path)
        try:
            return tmp, os.open(tmp, flags, 0o666)
        except FileExistsError:
            continue


def final_name(name: str) -> str:
    """The name a temporary file of this module will be renamed to (`name` itself otherwise)."""
    if _TEMP_RE.match(name):
        return name[1:].rsplit(".", 3)[0]
    return name


def _named(exc: OSError, path: Path) -> OSError:
    """`exc` naming `path` when it names no file (a failed write names none): the message
    then says which output could not be written."""
    if not exc.filename:
        exc.filename = str(path)
    return exc


def make_folder(path: str | os.PathLike) -> Path:
    """Make the output folder `path` and its parents where missing; returns it. An OSError that
    names the culprit when one cannot be a folder: a symbolic link to something missing, or a
    file."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError as exc:
        culprit = Path(exc.filename or path)
        if culprit.is_symlink():
            why = (
                f"a symbolic link to {os.readlink(culprit)}, which does not exist "
                "(make that folder, or name another)"
            )
        else:
            why = "exists and is not a folder"
        raise OSError(exc.errno, why, str(culprit)) from None
    return path


def _remove(path: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to `path`; rename it over `path` when the block ends normally.

    The temporary file exists (empty) when the block starts. If the block raises, the temporary
    file is removed, `path` is left as it was, and the exception propagates.
    """
    path = Path(path)
    tmp, fd = _open_temp(path)
    os.close(fd)
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as exc:
        _remove(tmp)
        raise _named(exc, path) from None
    except BaseException:
        _remove(tmp)
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write `data` to `path` atomically."""
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        f.write(data)


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write `text` to `path` atomically, UTF-8, newlines as written (no translation)."""
    atomic_write_bytes(path, text.encode("utf-8"))


class _StreamFile:
    """A binary file written in pieces under a temporary name; `commit` renames it into place."""

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        self.tmp, fd = _open_temp(self.path)
        self._file = os.fdopen(fd, "wb")
        self.done = False

    def write(self, data: bytes) -> None:
        if self.done:
            raise ValueError(f"{self.path}: already closed")
        try:
            self._file.write(data)
        except OSError as exc:
            raise _named(exc, self.path) from None

    def flush(self) -> None:
        try:
            self._file.flush()
        except OSError as exc:
            raise _named(exc, self.path) from None

    def commit(self) -> None:
        if self.done:
            return
        self.done = True
        try:
            self._file.close()
            os.replace(self.tmp, self.path)
        except OSError as exc:
            _remove(self.tmp)
            raise _named(exc, self.path) from None
        except BaseException:
            _remove(self.tmp)
            raise

    def abort(self) -> None:
        if self.done:
            return
        self.done = True
        try:
            self._file.close()
        finally:
            _remove(self.tmp)


class _StreamWriter:
    """A writer streaming into one _StreamFile (`self._file`): `close` renames the file into place,
    `abort` removes it; as a context manager it closes on success and aborts on an exception."""

    _file: _StreamFile

    @property
    def path(self) -> Path:
        return self._file.path

    def close(self) -> None:
        self._file.commit()

    def abort(self) -> None:
        """Drop the unfinished file; an older file at `path` stays as it was."""
        self._file.abort()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


# --------------------------------------------------------------------------------------------
# PNG


def _check_scale(scale: int) -> int:
    if isinstance(scale, bool) or int(scale) != scale or scale < 1:
        raise ValueError(f"scale must be a whole number >= 1, got {scale!r}")
    return int(scale)


def enlarge(image: np.ndarray, scale: int) -> np.ndarray:
    """`image` (H, W, ...) enlarged by nearest neighbour to (H*scale, W*scale, ...)."""
    scale = _check_scale(scale)
    if scale == 1:
        return image
    return np.repeat(np.repeat(image, scale, axis=0), scale, axis=1)


def encode_png(rgb: np.ndarray, scale: int = 1) -> bytes:
    """PNG bytes of an RGB picture (H, W, 3) uint8, enlarged `scale` times by nearest neighbour.

    No metadata, fixed compression (PNG_COMPRESS_LEVEL), no optimisation pass: the same pixels give
    the same bytes with the same Pillow and zlib.
    """
    rgb = np.asarray(rgb)
    if rgb.dtype != np.uint8 or rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) uint8 picture, got {rgb.shape} {rgb.dtype}")
    if rgb.shape[0] == 0 or rgb.shape[1] == 0:
        raise ValueError(f"cannot encode an empty picture {rgb.shape}")
    im = Image.fromarray(np.ascontiguousarray(enlarge(rgb, scale)))
    out = io.BytesIO()
    im.save(out, format="PNG", compress_level=PNG_COMPRESS_LEVEL, optimize=False)
    return out.getvalue()


def write_png(path: str | os.PathLike, rgb: np.ndarray, scale: int = 1) -> None:
    """Write `encode_png(rgb, scale)` to `path` atomically."""
    atomic_write_bytes(path, encode_png(rgb, scale))


# --------------------------------------------------------------------------------------------
# GIF


class GifSchedule:
    """Which frames the GIF shows and for how long, by arithmetic (nothing sized by the run).

    Frame i of n is due at t_i = i / fps seconds and the animation ends at t_n. GIF delays are
    whole centiseconds, so each kept frame starts at a rounded time and lasts until the next kept
    frame starts: the rounding never accumulates and the delays add up to round(100 * t_n), the
    exact length to the centisecond. Rounding is half up, in integers: round(100 i / fps) =
    (200 i + fps) // (2 fps).

    Up to GIF_MAX_FPS (50) every frame is kept, and every delay is at least
    floor(100 / fps) >= 2 cs. Above it, browsers would stretch delays under 2 cs, so frames are
    dropped evenly: frame i is kept when floor(i * 50 / fps) changes, that is the first frame of
    each 2 cs slot, which then starts at its slot's time 2 * slot (at most 1/fps early) and lasts
    2 cs. The last kept frame lasts until the end; if that leaves it under 2 cs, it is dropped and
    the one before lasts until the end (2 or 3 cs). A whole animation shorter than 2 cs is one frame
    of 2 cs. `note` says, for people, that frames were dropped; it is None when none were.

    `count` is the number of frames shown; `kept(j)` the run frame shown j-th, `delay_cs(j)` how
    long it lasts, for 0 <= j < count.
    """

    def __init__(self, n_frames: int, fps: int):
        self.n = n = max(int(n_frames), 0)
        self.fps = fps = int(fps)
        if fps < 1:
            raise ValueError(f"fps must be >= 1, got {fps}")
        self.end_cs = (200 * n + fps) // (2 * fps)
        self.dropping = fps > GIF_MAX_FPS
        if n == 0 or not self.dropping:
            self.count = n
        else:
            slots = (n - 1) * GIF_MAX_FPS // fps + 1
            last_start = GIF_MIN_DELAY_CS * (slots - 1)
            drop_last = slots >= 2 and self.end_cs - last_start < GIF_MIN_DELAY_CS
            self.count = slots - 1 if drop_last else slots
        self.note = None
        if self.count != n:
            self.note = (
                f"GIF shows {GIF_MAX_FPS} of {fps} frames per second "
                f"(delays under {GIF_MIN_DELAY_CS} cs are stretched by browsers)"
            )

    def kept(self, j: int) -> int:
        """The run frame shown j-th: the first frame of 2 cs slot j when dropping."""
        if not self.dropping:
            return j
        return (j * self.fps + GIF_MAX_FPS - 1) // GIF_MAX_FPS  # ceil(j * fps / 50)

    def _start_cs(self, j: int) -> int:
        if j >= self.count:
            return max(self.end_cs, GIF_MIN_DELAY_CS) if self.dropping else self.end_cs
        if self.dropping:
            return GIF_MIN_DELAY_CS * j
        return (200 * j + self.fps) // (2 * self.fps)

    def delay_cs(self, j: int) -> int:
        """How long the j-th shown frame lasts, in centiseconds."""
        return self._start_cs(j + 1) - self._start_cs(j)


def _gif_palette(palette: np.ndarray) -> bytes:
    """The palette's bytes padded with black to a power-of-two size >= 2 (a GIF colour table)."""
    k = palette.shape[0]
    size = 2
    while size < k:
        size *= 2
    table = np.zeros((size, 3), np.uint8)
    table[:k] = palette
    return table.tobytes()


class GifWriter(_StreamWriter):
    """Streams an animated GIF of palette-index frames to `path`, one frame at a time.

    palette (k, 3) uint8 with 1 <= k <= 256 is the scenario's palette; frames are (height, width)
    uint8 indices into it, shown enlarged `scale` times, at `fps` frames per second, looping
    forever. Give `add` every one of the `n_frames` frames in order: frames the schedule drops
    (`GifSchedule`, above 50 fps) are skipped here. `close` writes the trailer and renames the
    file into place; `abort` removes it and leaves any older GIF at `path` whole. As a context
    manager it closes on success and aborts on an exception. `note` is the schedule's message.
    """

    def __init__(
        self,
        path: str | os.PathLike,
        palette: np.ndarray,
        width: int,
        height: int,
        fps: int,
        n_frames: int,
        scale: int = 1,
    ):
        palette = np.asarray(palette)
        if palette.dtype != np.uint8 or palette.ndim != 2 or palette.shape[1] != 3:
            raise ValueError(f"palette must be (k, 3) uint8, got {palette.shape} {palette.dtype}")
        if not 1 <= palette.shape[0] <= GIF_MAX_COLORS:
            raise ValueError(f"a GIF holds 1 to {GIF_MAX_COLORS} colours, got {palette.shape[0]}")
        if int(n_frames) < 1:
            raise ValueError(f"a GIF needs at least one frame, got {n_frames}")
        self.scale = _check_scale(scale)
        self.width = int(width)
        self.height = int(height)
        if self.width < 1 or self.height < 1:
            raise ValueError(f"frame size must be positive, got {width}x{height}")
        out_w = self.width * self.scale
        out_h = self.height * self.scale
        if out_w > 65535 or out_h > 65535:
            raise ValueError(f"a GIF is at most 65535 px a side, got {out_w}x{out_h}")
        self.n_frames = int(n_frames)
        self.n_colors = int(palette.shape[0])
        self.schedule = GifSchedule(self.n_frames, int(fps))
        self.note = self.schedule.note
        self._palette = _gif_palette(palette)
        self._size = (out_w, out_h)
        self._seen = 0  # frames given to add
        self._next = 0  # index into kept of the next frame to write
        self._file = _StreamFile(path)
        try:
            im = self._image(np.zeros((self.height, self.width), np.uint8))
            header, _ = GifImagePlugin.getheader(im, None, {"loop": 0})
            for part in header:
                self._file.write(part)
        except BaseException:
            self._file.abort()
            raise

    def _image(self, frame: np.ndarray) -> Image.Image:
        data = np.ascontiguousarray(enlarge(frame, self.scale))
        im = Image.frombuffer("P", self._size, data, "raw", "P", 0, 1)
        im.putpalette(self._palette, "RGB")
        return im

    def add(self, frame: np.ndarray) -> None:
        """Take the next frame, (height, width) uint8 palette indices; write it if it is kept."""
        if self._file.done:
            raise ValueError(f"{self.path}: the GIF is already closed")
        if self._seen >= self.n_frames:
            raise ValueError(f"{self.path}: more than the {self.n_frames} frames announced")
        i = self._seen
        self._seen += 1
        if self._next >= self.schedule.count or self.schedule.kept(self._next) != i:
            return
        frame = np.asarray(frame)
        if frame.shape != (self.height, self.width) or frame.dtype != np.uint8:
            raise ValueError(
                f"frame must be ({self.height}, {self.width}) uint8, "
                f"got {frame.shape} {frame.dtype}"
            )
        if int(frame.max()) >= self.n_colors:
            raise ValueError(
                f"frame uses colour {int(frame.max())}; the palette has {self.n_colors}"
            )
        delay = self.schedule.delay_cs(self._next)
        if delay > GIF_MAX_DELAY_CS:
            raise ValueError(f"a GIF frame lasts at most {GIF_MAX_DELAY_CS} cs, needed {delay}")
        self._next += 1
        # getdata takes the duration in milliseconds and writes duration // 10 centiseconds;
        # disposal 1 leaves each full frame in place until the next covers it.
        for part in GifImagePlugin.getdata(
            self._image(frame), (0, 0), duration=delay * 10, disposal=1
        ):
            self._file.write(bytes(part))
        self._file.flush()  # on disk frame by frame: memory stays one frame whatever the length

    def close(self) -> None:
        """Write the trailer and rename the GIF into place; all n_frames frames must have come."""
        if self._file.done:
            return
        if self._seen != self.n_frames:
            self.abort()
            raise ValueError(
                f"{self.path}: {self._seen} frames given, {self.n_frames} announced; "
                "GIF not written"
            )
        self._file.write(b";")
        self._file.commit()


# --------------------------------------------------------------------------------------------
# Text outputs


class LogFull(Exception):
    """The event log would pass the bytes it may take: `tick` is the tick of the first event
    that did not fit, `limit` those bytes; nothing past them was written."""

    def __init__(self, path: Path, limit: int, tick: int):
        super().__init__(f"{path}: the event log would pass {limit:,} bytes at tick {tick:,}")
        self.path, self.limit, self.tick = path, limit, tick


class EventsWriter(_StreamWriter):
    """Streams events.jsonl: one `engine.events.format_event` line per event, in the order given.

    `write(events)` appends an EVENT_DTYPE array; `close` renames the file into place, `abort`
    removes it. As a context manager it closes on success and aborts on an exception. `names`
    (per object, None where not given): a named object's name follows its id, as `"name"` in a
    wall event and `"a_name"` / `"b_name"` in a pair event. `max_bytes` (None: no bound) is the
    most the file may hold: a `write` that would pass it raises LogFull before writing any of
    its lines, so the file never holds more (`bytes` counts what it holds).
    """

    def __init__(self, path: str | os.PathLike, names=None, max_bytes: int | None = None):
        self._file = _StreamFile(path)
        self.count = 0
        self.bytes = 0
        self.max_bytes = max_bytes
        self.names = list(names) if names is not None and any(names) else None

    def line(self, rec) -> str:
        if self.names is None:
            return format_event(rec)
        d = event_dict(rec)
        named = (("id", "name"),) if "id" in d else (("a", "a_name"), ("b", "b_name"))
        out = {}
        for key, value in d.items():
            out[key] = value
            for id_key, name_key in named:
                if key == id_key and self.names[value] is not None:
                    out[name_key] = self.names[value]
        return json.dumps(out)

    def write(self, events: np.ndarray) -> None:
        # in slices, so that the text of a tick with millions of events is never held whole
        for start in range(0, len(events), EVENTS_PER_WRITE):
            part = events[start : start + EVENTS_PER_WRITE]
            data = "".join(self.line(rec) + "\n" for rec in part).encode("utf-8")
            if self.max_bytes is not None and self.bytes + len(data) > self.max_bytes:
                self._full(part)
            self._file.write(data)
            self.count += len(part)
            self.bytes += len(data)

    def _full(self, part: np.ndarray) -> None:
        """Raise LogFull naming the tick of the first event of `part` that does not fit."""
        size = self.bytes
        for rec in part:
            size += len((self.line(rec) + "\n").encode("utf-8"))
            if size > self.max_bytes:
                raise LogFull(self.path, self.max_bytes, int(rec["tick"]))


def final_csv_text(pos: np.ndarray, vel: np.ndarray, names=None) -> str:
    """final.csv's text: header `id,x,y,vx,vy`, then one row per object in id order.

    pos (n, 2) px and vel (n, 2) px/s; numbers as `engine.events.format_number` writes them.
    `names` (per object, None where not given): when any object has a name, a last column `name`
    holds it (empty for the others; CSV-quoted when it needs to be; `escape.csv_cell`: a name a
    spreadsheet would run as a formula, such as `=1+1`, gets a leading `'`, and control
    characters but newline and tab are spelled out).
    """
    pos = np.asarray(pos, dtype=np.float64).reshape(-1, 2)
    vel = np.asarray(vel, dtype=np.float64).reshape(-1, 2)
    if pos.shape != vel.shape:
        raise ValueError(f"positions {pos.shape} and velocities {vel.shape} differ in shape")
    cols = np.concatenate([pos, vel], axis=1).tolist()
    fmt = format_number
    lines = ["id,x,y,vx,vy"]
    lines.extend(
        f"{i},{fmt(x)},{fmt(y)},{fmt(vx)},{fmt(vy)}" for i, (x, y, vx, vy) in enumerate(cols)
    )
    if names is not None and any(names):
        lines[0] += ",name"
        for i, name in enumerate(names):
            lines[i + 1] += "," + _csv_cell(escape.csv_cell(name or ""))
    return "\n".join(lines) + "\n"


def _csv_cell(text: str) -> str:
    if any(c in text for c in ',"\r\n') or text != text.strip():
        return '"' + text.replace('"', '""') + '"'
    return text


def write_final_csv(path: str | os.PathLike, pos: np.ndarray, vel: np.ndarray, names=None) -> None:
    """Write final.csv (see `final_csv_text`) to `path` atomically."""
    atomic_write_text(path, final_csv_text(pos, vel, names))


def write_json(path: str | os.PathLike, obj) -> None:
    """Write `json.dumps(obj, indent=2)` and a newline to `path` atomically, keys in given order.

    Non-finite floats are refused (ValueError): they are not JSON.
    """
    atomic_write_text(path, json.dumps(obj, indent=2, allow_nan=False) + "\n")
