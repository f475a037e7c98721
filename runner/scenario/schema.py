"""The JSON Schema (draft 2020-12) of the scenario format, for editors and `collide2d schema`.

It states the shape of a file — keys, types, ranges that never change — from the same constants the
loader (`runner.scenario.load`) checks against, so the two cannot drift apart. What a schema cannot
say (limits, objects inside the world and apart, paper velocities, frames up to `ticks`, convex
polygons) only the loader checks.
"""

from __future__ import annotations

from collide2d.engine.models import MODEL_NAMES
from collide2d.runner.scenario import colors
from collide2d.runner.scenario.load import (
    BLOCK_SHAPES,
    DEFAULT_DURATION,
    DEFAULT_FPS,
    DEFAULT_HEIGHT,
    DEFAULT_MAX_EVENTS_PER_TICK,
    DEFAULT_WIDTH,
    FORMAT_VERSION,
    FRAME_WORDS,
    GEOMETRIES,
    MAX_EVENT_CAP,
    MAX_FPS,
    MAX_FRICTION,
    MAX_GRAVITY,
    MAX_ITERATIONS,
    MAX_MASS,
    MAX_NAME_LENGTH,
    MAX_OBJECT_NAME_CHARS,
    MAX_SEED,
    MAX_SPEED,
    MAX_SUBSTEPS,
    MIN_MASS,
    NAME_PATTERN,
    SHAPES,
)
from collide2d.runner.scenario.physics import MODEL_BOUNDS
from collide2d.runner.scenario.sections import OVERLAY_NAMES


def json_schema() -> dict:
    """The JSON Schema (draft 2020-12) of the scenario format.

    It states the shape of a file: keys, types, ranges that never change. What it cannot state is
    checked by `load` alone: the limits (options), objects inside the world and not overlapping,
    paper-model velocities, frame numbers up to `ticks`, convex polygons under `geometry: exact`.
    """
    number = {"type": "number"}
    contact = {
        "restitution": {
            "type": "number",
            "minimum": 0,
            "maximum": 1,
            "description": "e: 1 elastic (default), 0 no bounce; a contact takes the smaller e "
            "of its two sides (stepped model; not under paper; only 1 under exact)",
        },
        "friction": {
            "type": "number",
            "minimum": 0,
            "maximum": MAX_FRICTION,
            "description": "Coulomb's mu, default 0; a contact takes the larger mu of its two "
            "sides (stepped model; not under paper; only 0 under exact)",
        },
    }
    stepped = {
        "iterations": {
            "type": "integer",
            "minimum": 1,
            "maximum": MAX_ITERATIONS,
            "description": "stepped model only: velocity passes over a step's contacts, default 8",
        },
        "slop": {
            "type": "number",
            "minimum": 0,
            "maximum": MODEL_BOUNDS["slop"][1],
            "description": "stepped model only: overlap left in place, px, default 0.1",
        },
        "rest_speed": {
            "type": "number",
            "minimum": 0,
            "maximum": MODEL_BOUNDS["rest_speed"][1],
            "description": "stepped model only, under gravity: a contact approaching slower "
            "(px/s) does not bounce; default 2 |g| times a substep",
        },
        "sleep": {
            "type": "boolean",
            "description": "stepped model only: slow bodies sleep; default true",
        },
        "sleep_after": {
            "type": "number",
            "minimum": 0,
            "maximum": MODEL_BOUNDS["sleep_after"][1],
            "description": "stepped model only: seconds below the rest speed before a body "
            "sleeps, default 0.5",
        },
    }
    exact = {
        "rest_height": {
            "type": "number",
            "minimum": 0,
            "maximum": MODEL_BOUNDS["rest_height"][1],
            "description": "exact model only, under gravity: a bounce on a wall that would rise "
            "less (px) comes to rest; default 0.01",
        },
    }
    gravity_component = {"type": "number", "minimum": -MAX_GRAVITY, "maximum": MAX_GRAVITY}
    whole_px = {"type": "integer", "minimum": 1, "description": "whole pixels"}
    xy = {"type": "array", "items": number, "minItems": 2, "maxItems": 2}
    common = {
        "position": {"$ref": "#/$defs/xy", "description": "[x, y] of the top-left corner, px"},
        "velocity": {"$ref": "#/$defs/xy", "description": "[vx, vy] in px/s; default [0, 0]"},
        "color": {"$ref": "#/$defs/color"},
        "mass": {
            "type": "number",
            "minimum": MIN_MASS,
            "maximum": MAX_MASS,
            "description": "default 1",
        },
        "static": {"type": "boolean", "description": "infinite mass, never moves"},
        "fill": {"type": "boolean", "description": "paint the inside too; default false"},
        "name": {
            "type": "string",
            "maxLength": MAX_OBJECT_NAME_CHARS,
            "description": "a label in logs and reports; no two objects share one",
        },
        **contact,
    }
    size = {
        "anyOf": [whole_px, {"type": "array", "items": whole_px, "minItems": 2, "maxItems": 2}],
        "description": "w x h in whole pixels: one number or [w, h]",
    }
    shape_keys = {
        "box": ("size", size),
        "circle": ("diameter", {**whole_px, "description": "a d x d box, whole pixels"}),
        "polygon": (
            "points",
            {
                "type": "array",
                "minItems": 3,
                "items": {
                    "type": "array",
                    "items": {"type": "integer"},
                    "minItems": 2,
                    "maxItems": 2,
                },
                "description": "[[x, y], ...] whole pixels relative to position",
            },
        ),
    }

    def variant(shape: str, props: dict, required: list[str]) -> dict:
        key, rule = shape_keys[shape]
        return {
            "type": "object",
            "properties": {"shape": {"const": shape}, key: rule, **props},
            "required": ["shape", key, *required],
            "additionalProperties": False,
        }

    block_props = {
        "count": {"type": "integer", "minimum": 0},
        "speed": {
            "anyOf": [
                {"type": "number", "minimum": 0, "maximum": MAX_SPEED},
                {
                    "type": "object",
                    "properties": {
                        "min": {"type": "number", "minimum": 0, "maximum": MAX_SPEED},
                        "max": {"type": "number", "minimum": 0, "maximum": MAX_SPEED},
                    },
                    "required": ["min", "max"],
                    "additionalProperties": False,
                },
            ],
            "description": "S: velocity (+-S, +-S); {min, max}: magnitude range, any direction",
        },
        "velocity": {
            "type": "object",
            "properties": {"min": {"$ref": "#/$defs/xy"}, "max": {"$ref": "#/$defs/xy"}},
            "required": ["min", "max"],
            "additionalProperties": False,
            "description": "each component drawn uniformly between min and max, px/s",
        },
        "seed": {"type": "integer", "minimum": 0, "maximum": MAX_SEED, "description": "default 0"},
        **{k: v for k, v in common.items() if k not in ("position", "velocity")},
    }
    frames = {
        "anyOf": [
            {"enum": list(FRAME_WORDS)},
            {"type": "array", "items": {"type": "integer", "minimum": 0}},
            {
                "type": "object",
                "properties": {"every": {"type": "integer", "minimum": 1}},
                "required": ["every"],
                "additionalProperties": False,
            },
        ],
        "description": "all | none | last | [frame, ...] | {every: k}",
    }
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "urn:collide2d:scenario:v1",
        "title": "collide2d scenario",
        "description": "A 2D collision scenario for collide2d (format version 1).",
        "type": "object",
        "required": ["version"],
        "additionalProperties": False,
        "not": {"required": ["ticks", "duration"]},
        "properties": {
            "version": {"const": FORMAT_VERSION},
            "name": {
                "type": "string",
                "pattern": f"^{NAME_PATTERN}$",
                "maxLength": MAX_NAME_LENGTH,
                "description": "output folder name; defaults to the file's stem",
            },
            "description": {"type": "string"},
            "world": {
                "type": "object",
                "properties": {
                    "width": {**whole_px, "description": f"px, default {DEFAULT_WIDTH}"},
                    "height": {**whole_px, "description": f"px, default {DEFAULT_HEIGHT}"},
                    "fps": {
                        "type": "integer",
                        "minimum": 1,
                        "maximum": MAX_FPS,
                        "description": f"whole ticks per second, default {DEFAULT_FPS}",
                    },
                    "background": {"$ref": "#/$defs/color"},
                    "gravity": {
                        "anyOf": [
                            gravity_component,
                            {
                                "type": "array",
                                "items": gravity_component,
                                "minItems": 2,
                                "maxItems": 2,
                            },
                        ],
                        "description": "px/s², y down: g (meaning [0, g]) or [gx, gy]; default 0 "
                        "(stepped model; not under paper; only 0 under exact)",
                    },
                    "restitution": {
                        **contact["restitution"],
                        "description": "the walls' restitution, default 1",
                    },
                    "friction": {
                        **contact["friction"],
                        "description": "the walls' friction, default 0",
                    },
                },
                "additionalProperties": False,
            },
            "model": {
                "anyOf": [
                    {"enum": list(MODEL_NAMES)},
                    {
                        "type": "object",
                        "properties": {
                            "kind": {"enum": list(MODEL_NAMES)},
                            "substeps": {"type": "integer", "minimum": 1, "maximum": MAX_SUBSTEPS},
                            "geometry": {"enum": list(GEOMETRIES)},
                            "max_events_per_tick": {
                                "type": "integer",
                                "minimum": 1,
                                "maximum": MAX_EVENT_CAP,
                                "description": "exact model only: the most wall and pair events "
                                f"one tick may take, default {DEFAULT_MAX_EVENTS_PER_TICK:,}",
                            },
                            **stepped,
                            **exact,
                        },
                        "required": ["kind"],
                        "additionalProperties": False,
                        "not": {
                            "anyOf": [
                                {
                                    "properties": {
                                        "kind": {"const": "paper"},
                                        "geometry": {"const": "exact"},
                                    },
                                    "required": ["kind", "geometry"],
                                },
                                *(
                                    {
                                        "properties": {"kind": {"enum": ["paper", "exact"]}},
                                        "required": ["kind", key],
                                    }
                                    for key in ("substeps", *stepped)
                                ),
                                *(
                                    {
                                        "properties": {"kind": {"enum": ["paper", "stepped"]}},
                                        "required": ["kind", key],
                                    }
                                    for key in ("max_events_per_tick", *exact)
                                ),
                            ]
                        },
                    },
                ],
                "description": "paper (default) | stepped | exact, or {kind, substeps, geometry, "
                "max_events_per_tick, iterations, slop, rest_speed, sleep, sleep_after, "
                "rest_height}",
            },
            "ticks": {"type": "integer", "minimum": 0},
            "duration": {
                "type": "number",
                "minimum": 0,
                "description": f"seconds; ticks = duration * fps; default {DEFAULT_DURATION}",
            },
            "objects": {
                "oneOf": [
                    {"type": "array", "items": {"$ref": "#/$defs/object"}},
                    {
                        "type": "object",
                        "properties": {
                            "file": {
                                "type": "string",
                                "pattern": r"\.(csv|npy|CSV|NPY)$",
                                "description": "a table of objects (.csv or .npy) in the "
                                "scenario's folder; columns id, shape, w, h, x, y, vx, vy, "
                                "mass, color, name, static, fill",
                            }
                        },
                        "required": ["file"],
                        "additionalProperties": False,
                    },
                ]
            },
            "generate": {"type": "array", "items": {"$ref": "#/$defs/block"}},
            "output": {
                "type": "object",
                "properties": {
                    "frames": {"$ref": "#/$defs/frames"},
                    "gif": {"type": "boolean"},
                    "events": {"type": "boolean"},
                    "viewer": {"type": "boolean"},
                    "overlay": {
                        "type": "array",
                        "items": {"enum": list(OVERLAY_NAMES)},
                    },
                },
                "additionalProperties": False,
            },
            "golden": {
                "type": "object",
                "properties": {
                    "frames": {"$ref": "#/$defs/frames"},
                    "time_tolerance": {"type": "number", "minimum": 0},
                    "max_diff_pixels": {"type": "integer", "minimum": 0},
                    "color_threshold": {"type": "integer", "minimum": 0, "maximum": 255},
                },
                "additionalProperties": False,
            },
        },
        "$defs": {
            "xy": xy,
            "color": {
                "anyOf": [
                    {"enum": list(colors.color_names())},
                    {"type": "string", "pattern": colors.HEX_COLOR_PATTERN},
                    {
                        "type": "array",
                        "items": {"type": "integer", "minimum": 0, "maximum": 255},
                        "minItems": 3,
                        "maxItems": 3,
                    },
                ],
                "description": "a CSS name, #rrggbb or [r, g, b]",
            },
            "frames": frames,
            "object": {
                "oneOf": [variant(s, common, ["position"]) for s in SHAPES],
            },
            "block": {
                "oneOf": [variant(s, block_props, ["count"]) for s in BLOCK_SHAPES],
                "not": {"required": ["speed", "velocity"]},
            },
        },
    }
