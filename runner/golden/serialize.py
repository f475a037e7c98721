"""Golden serialisation: a run's results as the bytes of a golden folder, and back (SPEC section 7).

Inputs are what a run hands over: the event records (`engine.events.EVENT_DTYPE`), the final
positions and velocities ((n, 2) float64 each) and the golden frames ((H, W, 3) uint8 RGB). Outputs
are the files of `goldens/NAME/`, each in one fixed text or image form so that a person can review a
change in a diff viewer and the same results always give the same bytes:

    manifest.json               format version, what was run, and a hash of every other file
    events.jsonl                one `engine.events.format_event` line per event
    final.csv                   `id,x,y,vx,vy` as `runner.outputs.final_csv_text` writes it
    frames/frame_000012.png     RGB PNG, deterministic encoding, no metadata

A frame is identified by its decoded pixels, never by its PNG bytes (zlib builds differ across
platforms): `pixel_sha256` hashes the width, the height and the RGB bytes. The manifest carries no
timestamps, so blessing the same results twice writes the same bytes.
"""

from __future__ import annotations

import hashlib
import io
import json
import struct

import numpy as np
from PIL import Image

from engine.events import event_dict, format_event
from runner.outputs import encode_png, final_csv_text

# The golden folder's layout version; a reader refuses other versions with a clear message.
FORMAT_VERSION = 1

MANIFEST_FILE = "manifest.json"
EVENTS_FILE = "events.jsonl"
FINAL_FILE = "final.csv"
FRAMES_DIR = "frames"
FINAL_HEADER = "id,x,y,vx,vy"


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


def decode_png(data: bytes) -> np.ndarray:
    """The decoded pixels of a PNG as (H, W, 3) uint8 RGB (other modes are converted to RGB)."""
    with Image.open(io.BytesIO(data)) as im:
        return np.array(im.convert("RGB"), dtype=np.uint8)


def events_jsonl(events: np.ndarray) -> bytes:
    """events.jsonl bytes: one `format_event` line per EVENT_DTYPE record, newline-ended."""
    return "".join(format_event(rec) + "\n" for rec in events).encode("utf-8")


def event_dicts(events: np.ndarray) -> list[dict]:
    """The JSON objects of EVENT_DTYPE records, as `parse_events` gives them back from the file."""
    return [event_dict(rec) for rec in events]


def parse_events(data: bytes) -> list[dict]:
    """The events of an events.jsonl file, in order; raises ValueError naming a bad line."""
    out = []
    for k, line in enumerate(data.decode("utf-8").splitlines(), start=1):
        if not line.strip():
            continue
        try:
            obj = json.loads(line)
        except json.JSONDecodeError as exc:
            raise ValueError(f"{EVENTS_FILE} line {k}: {exc.msg}") from None
        if not isinstance(obj, dict):
            raise ValueError(f"{EVENTS_FILE} line {k}: not a JSON object")
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
    lines = data.decode("utf-8").splitlines()
    if not lines or lines[0].strip() != FINAL_HEADER:
        raise ValueError(f"{FINAL_FILE} must start with the header {FINAL_HEADER!r}")
    rows = []
    for k, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        if len(cells) != 5 or cells[0] != str(len(rows)):
            raise ValueError(f"{FINAL_FILE} line {k}: expected '{len(rows)},x,y,vx,vy'")
        try:
            rows.append([float(c) for c in cells[1:]])
        except ValueError:
            raise ValueError(f"{FINAL_FILE} line {k}: not a number") from None
    return np.array(rows, dtype=np.float64).reshape(-1, 4)


def manifest(scenario, events: bytes, final: bytes, frames: dict[int, np.ndarray]) -> dict:
    """The manifest of a golden: format version, what was run, and the hash of every file.

    scenario: the Scenario that was run (name, model, ticks, world); events / final: the bytes of
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
