"""Golden serialisation: a run's results as the bytes of a golden folder, and back
(docs/goldens.md).

Inputs are what a run hands over: the event records (`engine.events.EVENT_DTYPE`), the final
positions and velocities ((n, 2) float64 each) and the golden frames ((H, W, 3) uint8 RGB). Outputs
are the files of `goldens/NAME/`, each in one fixed text or image form so that a person can review a
change in a diff viewer and the same results always give the same bytes:

    manifest.json               format version, what was run, and a hash of every other file
    events.jsonl                one `engine.events.format_event` line per event
    final.csv                   `id,x,y,vx,vy` as `runner.output.files.final_csv_text` writes it
    frames/frame_000012.png     RGB PNG, deterministic encoding, no metadata

A frame is identified by its decoded pixels, never by its PNG bytes (zlib builds differ across
platforms): `pixel_sha256` hashes the width, the height and the RGB bytes. The manifest carries no
timestamps, so blessing the same results twice writes the same bytes.

Reading back treats every file as possibly hostile: JSON nested deeper than `MAX_JSON_DEPTH` is
refused before it is parsed, numbers must be finite and integers within 64 bits, the manifest must
have the exact shape written here (its paths plain, relative and inside the golden), and a PNG's
header is read and checked against the manifest's size and a pixel bound before any pixel is
decoded. Every refusal is a ValueError whose text says what is wrong.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import re
import struct
import warnings
import zlib

import numpy as np
from PIL import Image, UnidentifiedImageError

from collide2d.engine.events import event_dict, format_event
from collide2d.runner.command.version import version
from collide2d.runner.output.files import encode_png, final_csv_text

# The golden folder's layout version; a reader refuses other versions with a clear message.
FORMAT_VERSION = 1

MANIFEST_FILE = "manifest.json"
EVENTS_FILE = "events.jsonl"
FINAL_FILE = "final.csv"
FRAMES_DIR = "frames"
FINAL_HEADER = "id,x,y,vx,vy"
# Reading limits: JSON nesting (a manifest is 3 levels deep, an event line 1) and integers.
MAX_JSON_DEPTH = 32
MAX_INT = 2**63 - 1
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# A PNG side may be 1 to 2^31 - 1 pixels (PNG specification).
PNG_MAX_SIDE = 2**31 - 1
_HEX64_RE = re.compile(r"[0-9a-f]{64}")
# A JSON string literal (its brackets do not nest) and the bytes that are not brackets.
_JSON_STRING_RE = re.compile(rb'"(?:[^"\\]|\\.)*"')
_NOT_BRACKETS = bytes(b for b in range(256) if b not in b"[]{}")


def frame_file(frame: int) -> str:
    """The path of frame `frame`'s PNG inside a golden folder, e.g. `frames/frame_000012.png`."""
    return f"{FRAMES_DIR}/frame_{int(frame):06d}.png"


def sha256_bytes(data: bytes) -> str:
    """Hex SHA-256 of `data`."""
    return hashlib.sha256(data).hexdigest()


def pixel_sha256(rgb: np.ndarray) -> str:
    """Hex SHA-256 of a frame's decoded pixels: width and height (little-endian uint32) then the
    RGB bytes row by row. rgb: (H, W, 3) uint8."""
    rgb = _as_rgb(rgb)
    h, w = rgb.shape[:2]
    digest = hashlib.sha256(struct.pack("<II", w, h))
    digest.update(np.ascontiguousarray(rgb).tobytes())
    return digest.hexdigest()


def _as_rgb(rgb: np.ndarray) -> np.ndarray:
    rgb = np.asarray(rgb)
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
        raise ValueError(f"a frame must be (H, W, 3) uint8, not {rgb.shape} {rgb.dtype}")
    return rgb


def png_bytes(rgb: np.ndarray) -> bytes:
    """Deterministic RGB PNG of a frame (H, W, 3) uint8, at scale 1."""
    return encode_png(_as_rgb(rgb))


def png_size(data: bytes) -> tuple[int, int]:
    """(width, height) from a PNG's header (its IHDR chunk), without decoding anything; raises
    ValueError when `data` does not start as a PNG."""
    if data[:8] != PNG_SIGNATURE:
        raise ValueError("not a PNG file (no PNG signature)")
    if len(data) < 33 or data[8:16] != struct.pack(">I", 13) + b"IHDR":
        raise ValueError("damaged PNG (no IHDR header)")
    w, h = struct.unpack(">II", data[16:24])
    if not (1 <= w <= PNG_MAX_SIDE and 1 <= h <= PNG_MAX_SIDE):
        raise ValueError(f"damaged PNG (header size {w}x{h})")
    return w, h


def decode_png(data: bytes, *, size=None, max_pixels: int | None = None) -> np.ndarray:
    """The decoded pixels of a PNG as (H, W, 3) uint8 RGB (other modes are converted to RGB).

    size: the (width, height) the PNG must have; max_pixels: the most pixels it may have. Both are
    checked on the header before any pixel is decoded, so a small file claiming a huge picture
    costs nothing. Raises ValueError on anything that is not such a PNG.
    """
    w, h = png_size(data)
    if size is not None and (w, h) != (int(size[0]), int(size[1])):
        raise ValueError(f"the PNG is {w}x{h}, the manifest says {int(size[0])}x{int(size[1])}")
    if max_pixels is not None and w * h > max_pixels:
        raise ValueError(
            f"the PNG claims {w}x{h} pixels, past the {max_pixels} a golden frame may have here"
        )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(io.BytesIO(data), formats=["PNG"]) as im:
                if im.size != (w, h):
                    raise ValueError(f"damaged PNG (header {w}x{h}, image {im.size})")
                return np.array(im.convert("RGB"), dtype=np.uint8)
    except UnidentifiedImageError:
        raise ValueError("damaged PNG (not recognised past its header)") from None
    except (OSError, SyntaxError, EOFError, struct.error, zlib.error, IndexError) as exc:
        raise ValueError(f"damaged PNG ({exc})") from None
    except Image.DecompressionBombError as exc:
        raise ValueError(f"refused PNG ({exc})") from None


def check_rel(rel) -> str:
    """`rel` if it is a plain relative path inside a golden folder (`/`-separated, no `..`, `.`,
    empty part, backslash or NUL), else ValueError."""
    if (
        not isinstance(rel, str)
        or not rel
        or rel.startswith("/")
        or "\\" in rel
        or "\0" in rel
        or ":" in rel
        or any(part in ("", ".", "..") for part in rel.split("/"))
    ):
        raise ValueError(
            f"the path {json.dumps(rel)[:80]} is not a plain relative path inside the golden"
        )
    return rel


def json_depth(data: bytes) -> int:
    """The deepest bracket nesting of JSON text (brackets inside strings left out), in linear
    time and bounded memory, without parsing it."""
    brackets = _JSON_STRING_RE.sub(b'""', data).translate(None, _NOT_BRACKETS)
    level = peak = 0
    step = 1 << 20
    for i in range(0, len(brackets), step):
        chunk = np.frombuffer(brackets[i : i + step], dtype=np.uint8)
        delta = np.where((chunk == ord("[")) | (chunk == ord("{")), 1, -1).astype(np.int64)
        run = np.cumsum(delta) + level
        peak = max(peak, int(run.max()))
        level = int(run[-1])
    return peak


def load_json(data: bytes, *, max_depth: int | None = MAX_JSON_DEPTH):
    """json.loads of `data`, refusing (ValueError) nesting past `max_depth` (None: the caller has
    bounded it), non-UTF-8 text, numbers past range (non-finite, or integers past 64 bits) and
    anything that is not JSON."""
    if max_depth is not None:
        depth = json_depth(data)
        if depth > max_depth:
            raise ValueError(f"nested {depth} levels deep, past {max_depth}")
    try:
        return _DECODER.decode(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise ValueError("not UTF-8 text") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"not JSON: {exc.msg} at line {exc.lineno} column {exc.colno}") from None
    except _Refused as exc:
        raise ValueError(str(exc)) from None
    except RecursionError:
        raise ValueError("nested too deep") from None


class _Refused(ValueError):
    """A number no golden holds: NaN or an infinity, or an integer past 64 bits."""


def _refuse_constant(name):
    raise _Refused(f"{name} is not a number a golden holds")


def _parse_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise _Refused("a number is out of range (not finite)")
    return value


def _parse_int(text: str) -> int:
    # Refused by its length before it is converted: no cost grows with the digits.
    value = int(text) if len(text) <= 20 else MAX_INT + 1
    if abs(value) > MAX_INT:
        raise _Refused("a number is out of range (an integer past 64 bits)")
    return value


_DECODER = json.JSONDecoder(
    parse_float=_parse_float, parse_int=_parse_int, parse_constant=_refuse_constant
)


def _int(obj, what: str, lo: int = 0, hi: int = MAX_INT) -> int:
    if not isinstance(obj, int) or isinstance(obj, bool) or not lo <= obj <= hi:
        raise ValueError(f"{what} must be an integer from {lo} to {hi}")
    return obj


def _hex64(obj, what: str) -> str:
    if not isinstance(obj, str) or not _HEX64_RE.fullmatch(obj):
        raise ValueError(f"{what} must be a SHA-256 in hex")
    return obj


def check_manifest(obj) -> dict:
    """`obj` (a parsed manifest.json of this format) if it has the shape `manifest` writes, with
    every path plain and the one this format uses; else ValueError naming what is wrong."""
    if not isinstance(obj, dict):
        raise ValueError("the manifest must be a JSON object")
    for key, rel in (("events", EVENTS_FILE), ("final", FINAL_FILE)):
        entry = obj.get(key)
        if not isinstance(entry, dict):
            raise ValueError(f"{key!r} must be an object")
        check_rel(entry.get("file"))
        if entry["file"] != rel:
            raise ValueError(f"{key}.file is {json.dumps(entry['file'])[:80]}, not {rel!r}")
        _hex64(entry.get("sha256"), f"{key}.sha256")
    if obj.get("scenario_sha256") is not None:  # goldens blessed before it was kept lack it
        _hex64(obj["scenario_sha256"], "scenario_sha256")
    version = obj.get("collide2d_version")
    if version is not None and not (isinstance(version, str) and 0 < len(version) <= 64):
        raise ValueError("collide2d_version must be a version text of at most 64 characters")
    frames = obj.get("frames")
    if not isinstance(frames, list):
        raise ValueError("'frames' must be a list")
    seen = set()
    for i, entry in enumerate(frames):
        if not isinstance(entry, dict):
            raise ValueError(f"frames[{i}] must be an object")
        k = _int(entry.get("frame"), f"frames[{i}].frame")
        check_rel(entry.get("file"))
        if entry["file"] != frame_file(k) or k in seen:
            raise ValueError(
                f"frames[{i}].file is {json.dumps(entry['file'])[:80]}, not {frame_file(k)!r} "
                "(or the frame is listed twice)"
            )
        seen.add(k)
        _int(entry.get("width"), f"frames[{i}].width", 1, PNG_MAX_SIDE)
        _int(entry.get("height"), f"frames[{i}].height", 1, PNG_MAX_SIDE)
        _hex64(entry.get("pixels_sha256"), f"frames[{i}].pixels_sha256")
    return obj


def events_jsonl(events: np.ndarray) -> bytes:
    """events.jsonl bytes: one `format_event` line per EVENT_DTYPE record, newline-ended."""
    return "".join(format_event(rec) + "\n" for rec in events).encode("utf-8")


def event_dicts(events: np.ndarray) -> list[dict]:
    """The JSON objects of EVENT_DTYPE records, as `parse_events` gives them back from the file."""
    return [event_dict(rec) for rec in events]


def parse_events(data: bytes) -> list[dict]:
    """The events of an events.jsonl file, in order; raises ValueError naming a bad line (not
    JSON, nested, not an object, or a number past range)."""
    lines = data.splitlines()
    if json_depth(data) > 1:  # one pass over the file bounds every line
        k = next(k for k, ln in enumerate(lines, 1) if json_depth(ln) > 1)
        raise ValueError(f"line {k}: an event is one flat JSON object (this line nests)")
    out = []
    for k, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            obj = load_json(line, max_depth=None)
        except ValueError as exc:
            raise ValueError(f"line {k}: {exc}") from None
        if not isinstance(obj, dict):
            raise ValueError(f"line {k}: not a JSON object")
        out.append(obj)
    return out


def final_csv(pos: np.ndarray, vel: np.ndarray) -> bytes:
    """final.csv bytes, as `collide2d run` writes them: `id,x,y,vx,vy` then one row per object.
    pos, vel: (n, 2) float64, px and px/s. Numbers are written by `format_number`, which reads
    back to the same float64."""
    return final_csv_text(pos, vel).encode("utf-8")


def final_state(pos: np.ndarray, vel: np.ndarray) -> np.ndarray:
    """(n, 4) float64 rows x, y, vx, vy from pos and vel, each (n, 2)."""
    pos = np.asarray(pos, dtype=np.float64).reshape(-1, 2)
    vel = np.asarray(vel, dtype=np.float64).reshape(-1, 2)
    if pos.shape != vel.shape:
        raise ValueError(f"positions {pos.shape} and velocities {vel.shape} differ in shape")
    return np.concatenate([pos, vel], axis=1)


def parse_final(data: bytes) -> np.ndarray:
    """The (n, 4) float64 state (x, y, vx, vy) of a final.csv; raises ValueError on a bad row."""
    try:
        lines = data.decode("utf-8").splitlines()
    except UnicodeDecodeError:
        raise ValueError(f"{FINAL_FILE} is not UTF-8 text") from None
    if not lines or lines[0].strip() != FINAL_HEADER:
        raise ValueError(f"the file must start with the header {FINAL_HEADER!r}")
    rows = []
    for k, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        if len(cells) != 5 or cells[0] != str(len(rows)):
            raise ValueError(f"line {k}: expected '{len(rows)},x,y,vx,vy'")
        try:
            row = [float(c) for c in cells[1:]]
        except ValueError:
            raise ValueError(f"line {k}: not a number") from None
        if not all(math.isfinite(v) for v in row):
            raise ValueError(f"line {k}: a number is out of range (not finite)")
        rows.append(row)
    return np.array(rows, dtype=np.float64).reshape(-1, 4)


def manifest(scenario, events: bytes, final: bytes, frames: dict[int, np.ndarray]) -> dict:
    """The manifest of a golden: format version, what was run, and the hash of every file.

    scenario: the Scenario that was run (name, model, ticks, world, the SHA-256 of its text, kept
    with the collide2d version that blesses it so a failed check can say whether the scenario or
    the engine changed); events / final: the bytes of
    events.jsonl and final.csv; frames: frame number -> (H, W, 3) uint8. Keys are in a fixed order
    and no value depends on the time or the machine.
    """
    return {
        "format": FORMAT_VERSION,
        "scenario": scenario.name,
        "model": str(scenario.model),
        "world": {
            "width": int(scenario.world.width),
            "height": int(scenario.world.height),
            "fps": int(scenario.world.fps),
        },
        "ticks": int(scenario.ticks),
        # why a check fails: was the scenario edited, or did another collide2d bless it
        "scenario_sha256": getattr(scenario, "text_sha256", None),
        "collide2d_version": version(),
        "events": {
            "file": EVENTS_FILE,
            "count": events.count(b"\n"),
            "sha256": sha256_bytes(events),
        },
        "final": {
            "file": FINAL_FILE,
            "objects": max(final.count(b"\n") - 1, 0),
            "sha256": sha256_bytes(final),
        },
        "frames": [
            {
                "frame": int(k),
                "file": frame_file(k),
                "width": int(frames[k].shape[1]),
                "height": int(frames[k].shape[0]),
                "pixels_sha256": pixel_sha256(frames[k]),
            }
            for k in sorted(frames)
        ],
    }


def manifest_bytes(obj: dict) -> bytes:
    """manifest.json bytes: two-space indented JSON in the dict's own key order, newline-ended."""
    return (json.dumps(obj, indent=2) + "\n").encode("utf-8")
