"""Colours as a scenario writes them, turned into RGB triples.

A colour is a CSS name (Pillow's `PIL.ImageColor` table, case-insensitive), a `#rrggbb` hex string,
or a list `[r, g, b]` of integers 0..255. `parse_color_text` handles the two string forms and
`check_rgb` the list form; both return `(r, g, b)` as Python ints and raise `ValueError` with a
message meant for a user (an unknown name suggests the nearest spelling).
"""

from __future__ import annotations

import difflib
import re

from PIL import ImageColor

HEX_COLOR_RE = re.compile(r"#[0-9a-fA-F]{6}\Z")
HEX_COLOR_PATTERN = "^#[0-9a-fA-F]{6}$"  # the same rule, in JSON Schema (ECMA-262) form


def color_names() -> tuple[str, ...]:
    """Every accepted colour name, lower case, sorted."""
    return tuple(sorted(ImageColor.colormap))


def parse_color_text(text: str) -> tuple[int, int, int]:
    """(r, g, b) of a CSS colour name or a `#rrggbb` string; ValueError otherwise."""
    if HEX_COLOR_RE.match(text):
        return (int(text[1:3], 16), int(text[3:5], 16), int(text[5:7], 16))
    if text.startswith("#"):
        raise ValueError(f"colour {text!r} is not of the form #rrggbb")
    key = text.strip().lower()
    if key in ImageColor.colormap:
        rgb = ImageColor.getrgb(key)
        return (int(rgb[0]), int(rgb[1]), int(rgb[2]))
    near = difflib.get_close_matches(key, color_names(), n=1)
    hint = f"; did you mean {near[0]!r}?" if near else " (use a CSS name, #rrggbb or [r, g, b])"
    raise ValueError(f"unknown colour {text!r}{hint}")


def check_rgb(values) -> tuple[int, int, int]:
    """(r, g, b) from three integers 0..255 (bool is not an integer); ValueError otherwise."""
    if len(values) != 3:
        raise ValueError(f"a colour list needs 3 values [r, g, b], not {len(values)}")
    for v in values:
        if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= 255:
            raise ValueError(f"colour components must be whole numbers 0..255, not {v!r}")
    return (int(values[0]), int(values[1]), int(values[2]))
