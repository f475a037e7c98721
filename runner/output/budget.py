"""What a run's frames will cost, decided before the first tick: counts, bytes on disk, memory.

`plan_frames` turns a scenario and the run's options into the frames to draw (`FrameRule`s for the
PNG files and for the drawing loop) and refuses, with the option to change, a run whose frames
would pass a limit of docs/limits.md: more frame files than `--max-frames`, more bytes on disk than
`--max-output-bytes`, a frame larger in memory than `--max-frame-bytes`, or a GIF larger than the
format allows. Everything is arithmetic on the rules, so a billion-tick run is judged without a
list of its frames.

`--max-output-bytes` bounds the event log too, but how many events a run has is known only once
they happen: the frames' bound is settled before the first tick, and what it leaves of the limit
(`FramePlan.log_room`) is the most `events.jsonl` may take, counted as it is written
(`outputs.EventsWriter`); a run whose log would pass it stops there (`runner.run`). So a run's
frame files and event log together never pass the limit, and whether a run stops depends on the
scenario alone, not on how well its frames compress.

The byte counts are upper bounds of the files as written, per-file overheads included, for any
picture (noise too), so a run that passes never writes more:
- a PNG is its signature, IHDR and IEND chunks, the zlib stream of its filtered rows (raw size plus
  zlib's own worst-case growth, `compressBound`), 12 bytes per IDAT chunk of at least
  PNG_IDAT_MIN_BYTES, and room for one ancillary chunk;
- a GIF is its header (logical screen, a 256-colour table, the looping extension) and trailer, and
  per shown frame a graphic control extension, an image descriptor, and LZW data of at most 12 bits
  per pixel (every code covers one pixel or more, codes are at most 12 bits wide) plus clear and
  end codes, in sub-blocks of 255 bytes each with a length byte.
"""

from __future__ import annotations

from dataclasses import dataclass

from collide2d.runner.output.files import GifSchedule
from collide2d.runner.scenario.frames import FrameRule
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import Scenario, ScenarioError

# PNG file: 8-byte signature, IHDR (13 data + 12), IEND (12), room for one ancillary chunk.
PNG_FIXED_BYTES = 8 + 25 + 12 + 64
# The fewest bytes of compressed data an IDAT chunk of a PNG writer holds (all but the last).
PNG_IDAT_MIN_BYTES = 4096
PNG_CHUNK_OVERHEAD = 12  # length, type, CRC
# GIF file: signature 6, logical screen 7, 256-colour table 768, looping extension 19, trailer 1,
# room for a comment.
GIF_FIXED_BYTES = 6 + 7 + 3 * 256 + 19 + 1 + 64
# GIF frame: graphic control extension 8, image descriptor 10, LZW code size 1, block terminator 1.
GIF_FRAME_FIXED_BYTES = 8 + 10 + 1 + 1
GIF_MAX_CODE_BITS = 12
# At most one clear code per this many codes (the smallest table an encoder may reset at).
GIF_CODES_PER_CLEAR = 254
# The largest side of a GIF picture, px (its header holds 16-bit sizes).
GIF_MAX_SIDE_PX = 65535
RGB_BYTES = 3


def png_bytes_bound(width: int, height: int) -> int:
    """The most bytes a PNG of an RGB picture `width` x `height` px can take on disk."""
    raw = height * (1 + RGB_BYTES * width)  # a filter byte per row, then the row
    zlib = raw + (raw >> 12) + (raw >> 14) + (raw >> 25) + 13 + 6
    chunks = zlib // PNG_IDAT_MIN_BYTES + 2
    return PNG_FIXED_BYTES + zlib + PNG_CHUNK_OVERHEAD * chunks


def gif_frame_bytes_bound(width: int, height: int) -> int:
    """The most bytes one shown GIF frame of `width` x `height` px can take on disk."""
    pixels = width * height
    codes = pixels + pixels // GIF_CODES_PER_CLEAR + 3  # pixels, clear codes, first clear, end
    data = -(-codes * GIF_MAX_CODE_BITS // 8)
    return GIF_FRAME_FIXED_BYTES + data + -(-data // 255)


@dataclass(frozen=True)
class FramePlan:
    """The frames a run draws: `png` those written as PNG files, `draw` every frame rasterised
    (the PNG frames, and all of them when there is a GIF); `bytes_bound` the most they take;
    `log_room` the bytes `--max-output-bytes` leaves to the event log."""

    png: FrameRule
    gif: bool
    draw: FrameRule
    gif_frames: int
    bytes_bound: int
    log_room: int


def plan_frames(scenario: Scenario, *, png: bool, gif: bool, scale: int, limits: Limits):
    """The FramePlan of a run, or a ScenarioError naming the limit it would pass."""
    ticks = scenario.ticks
    rule = scenario.output.frames if scenario.output.frames else FrameRule.all(ticks)
    png_rule = rule if png else FrameRule.none(ticks)
    schedule = GifSchedule(ticks + 1, scenario.world.fps) if gif else None
    gif_frames = schedule.count if schedule else 0
    width = scenario.world.width * scale
    height = scenario.world.height * scale

    def refuse(message: str) -> ScenarioError:
        return ScenarioError(scenario.path or "<scenario>", 1, 1, message)

    if png_rule or gif:
        frame_bytes = width * height * RGB_BYTES
        if frame_bytes > limits.max_frame_bytes:
            raise refuse(
                f"one frame of this {scenario.world.width}x{scenario.world.height} world at "
                f"scale {scale} takes {frame_bytes:,} bytes in memory, past the limit of "
                f"{limits.max_frame_bytes:,}; use a smaller --scale, --no-png and --no-gif, "
                "or raise --max-frame-bytes"
            )
    if gif and max(width, height) > GIF_MAX_SIDE_PX:
        raise refuse(
            f"a GIF is at most {GIF_MAX_SIDE_PX} px a side, and this world at scale "
            f"{scale} needs {max(width, height)} px; use a smaller --scale or --no-gif"
        )
    for count, what, flag in (
        (len(png_rule), "PNG frames", "--no-png"),
        (gif_frames, "GIF frames", "--no-gif"),
    ):
        if count > limits.max_frames:
            raise refuse(
                f"the run would write {count:,} {what}, past the limit of {limits.max_frames:,}; "
                f"ask for fewer (output.frames, --ticks), use {flag}, or raise --max-frames"
            )
    total = len(png_rule) * png_bytes_bound(width, height)
    if gif:
        total += GIF_FIXED_BYTES + gif_frames * gif_frame_bytes_bound(width, height)
    if total > limits.max_output_bytes:
        raise refuse(
            f"the frames asked for could take up to {total:,} bytes on disk, past the output "
            f"limit of {limits.max_output_bytes:,} bytes; ask for fewer frames (output.frames, "
            "--no-png, --no-gif, a smaller --scale) or raise --max-output-bytes"
        )
    draw = FrameRule.all(ticks) if gif else png_rule
    return FramePlan(png_rule, gif, draw, gif_frames, total, limits.max_output_bytes - total)
