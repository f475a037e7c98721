"""The `output` and `golden` sections: the frames a run keeps, what it writes, how goldens compare.

A `frames` entry is `all`, `none`, `last`, a list of frame numbers or `{every: k}`; its count is
checked against `Limits.max_frames` by arithmetic (`runner.scenario.frames.FrameRule`), so nothing
sized by `ticks` is built. A listed frame past the last one is refused, unless `--ticks` shortened
the run, where it is dropped. Goldens default to frames 0, ticks // 2 and ticks.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

import yaml

from collide2d.runner.scenario import parse
from collide2d.runner.scenario.frames import FrameRule
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.nodes import Nodes

FRAME_WORDS = ("all", "none", "last")
EVERY_KEYS = ("every",)
OUTPUT_KEYS = ("frames", "gif", "events", "viewer", "overlay")
# Debug overlays a scenario may ask to draw into its frames (runner.output.overlay draws them).
OVERLAY_NAMES = ("velocity", "boxes", "contacts", "labels", "overlap", "rests")
GOLDEN_KEYS = ("frames", "time_tolerance", "max_diff_pixels", "color_threshold")


@dataclass(frozen=True)
class Output:
    frames: FrameRule  # the frames (0..ticks) asked for
    frames_spec: (
        object  # what the file said, normalised: "all" | "none" | "last" | list | {"every": k}
    )
    gif: bool
    events: bool
    viewer: bool = False  # viewer.html beside the GIF (runner.output.viewerdata)
    # overlays drawn into every frame, goldens too (runner.output.overlay)
    overlay: tuple[str, ...] = ()


@dataclass(frozen=True)
class Golden:
    frames: tuple[int, ...]  # default (0, ticks // 2, ticks), deduplicated and sorted
    time_tolerance: float = 0.0  # s
    max_diff_pixels: int = 0
    color_threshold: int = 0  # per-pixel largest channel difference still counted as equal (0..255)


class OutputReader(Nodes):
    """Reads the output and golden sections of one scenario of `ticks` ticks."""

    def __init__(self, path: str, limits: Limits, ticks_from=None):
        super().__init__(path)
        self.limits = limits
        self.ticks_from = ticks_from  # the option the tick count came from, if any

    def frames(self, node, what: str, ticks: int) -> tuple[FrameRule, object]:
        """(the frame rule, normalised spec) of a `frames` entry; its count is checked against
        limits.max_frames by arithmetic, so no list sized by `ticks` is ever built."""
        origin = self.prefix(self.ticks_from)
        too_many = (
            f"{origin}{what} asks for {{n:,}} frames, past the limit of "
            f"{self.limits.max_frames:,} frames; raise it with --max-frames"
        )
        if isinstance(node, yaml.SequenceNode):
            given = []
            for item in node.value:
                f = self.integer(item, f"{what} item", lo=0)
                if f > ticks and self.ticks_from:
                    continue  # the run was shortened from the command line: past its end
                if f > ticks:
                    raise self.error(
                        item,
                        f"{origin}{what}: frame {f} is past the last frame, "
                        f"{ticks} (ticks: {ticks})",
                    )
                given.append(f)
            rule = FrameRule.of(given, ticks)
            if len(rule) > self.limits.max_frames:
                raise self.error(node, too_many.format(n=len(rule)))
            return rule, given
        if isinstance(node, yaml.MappingNode):
            m = self.mapping(node, what, EVERY_KEYS)
            if "every" not in m:
                raise self.error(node, f"{what} as a mapping must be {{every: k}}")
            k = self.integer(m["every"][1], f"{what}.every", lo=1, of=" of ticks")
            rule = FrameRule.every_k(k, ticks)
            if len(rule) > self.limits.max_frames:
                raise self.error(node, too_many.format(n=len(rule)))
            return rule, {"every": k}
        v = self.scalar(node, what)
        if v not in FRAME_WORDS or not isinstance(v, str):
            near = difflib.get_close_matches(v, FRAME_WORDS, n=1) if isinstance(v, str) else []
            hint = f"; did you mean '{near[0]}'?" if near else ""
            raise self.error(
                node,
                f"{what} must be all, none, last, a list of frame numbers or "
                f"{{every: k}}, not {parse.describe(node)}{hint}",
            )
        rule = {"all": FrameRule.all, "last": FrameRule.last, "none": FrameRule.none}[v](ticks)
        if len(rule) > self.limits.max_frames:
            raise self.error(node, too_many.format(n=len(rule)))
        return rule, v

    def output(self, top: dict, ticks: int) -> Output:
        m = self.mapping(top["output"][1], "output", OUTPUT_KEYS) if "output" in top else {}
        frames, spec = FrameRule.none(ticks), "none"
        if "frames" in m:
            frames, spec = self.frames(m["frames"][1], "output.frames", ticks)
        gif = self.boolean(m["gif"][1], "output.gif") if "gif" in m else True
        events = self.boolean(m["events"][1], "output.events") if "events" in m else True
        viewer = self.boolean(m["viewer"][1], "output.viewer") if "viewer" in m else False
        overlay = ()
        if "overlay" in m:
            items = self.seq(m["overlay"][1], "output.overlay")
            chosen = {self.choice(item, "output.overlay item", OVERLAY_NAMES) for item in items}
            overlay = tuple(n for n in OVERLAY_NAMES if n in chosen)
        return Output(
            frames=frames,
            frames_spec=spec,
            gif=gif,
            events=events,
            viewer=viewer,
            overlay=overlay,
        )

    def golden(self, top: dict, ticks: int) -> Golden:
        m = self.mapping(top["golden"][1], "golden", GOLDEN_KEYS) if "golden" in top else {}
        frames = tuple(sorted({0, ticks // 2, ticks}))
        if "frames" in m:
            rule, _ = self.frames(m["frames"][1], "golden.frames", ticks)
            frames = tuple(rule)  # within limits.max_frames: goldens store each one
        tol = 0.0
        if "time_tolerance" in m:
            tol = float(
                self.number(m["time_tolerance"][1], "golden.time_tolerance", lo=0, unit=" s")
            )
        pixels = 0
        if "max_diff_pixels" in m:
            pixels = self.integer(m["max_diff_pixels"][1], "golden.max_diff_pixels", lo=0)
        threshold = 0
        if "color_threshold" in m:
            threshold = self.integer(
                m["color_threshold"][1], "golden.color_threshold", lo=0, hi=255
            )
        return Golden(
            frames=frames, time_tolerance=tol, max_diff_pixels=pixels, color_threshold=threshold
        )
