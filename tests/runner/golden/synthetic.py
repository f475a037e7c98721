"""Synthetic scenarios for the golden harness's tests: a small JSON file states a run's results.

A synthetic scenario file (JSON, which is also YAML, named `*.yaml`) gives the scenario's fields and
the results its "run" returns, so a test changes exactly one thing — a pixel, an event, a number —
and watches the check react, independent of the physics:

    {"name": "a", "model": "paper", "ticks": 4, "width": 8, "height": 6, "fps": 10,
     "golden": {"frames": [0, 4], "time_tolerance": 0.0, "max_diff_pixels": 0,
                "color_threshold": 0},
     "events": [[tick, t, type, a, b, code, xdiff, ydiff], ...],
     "final": [[x, y, vx, vy], ...],
     "pixels": [[frame, x, y, r, g, b], ...],     (on a black background)
     "sizes": {"4": [w, h]},                      (optional: a frame of another size)
     "error": "MESSAGE"}                          (optional: the loader refuses the file)

`load(path)` and `simulate(scenario, keep_frames=..., log_events=..., progress=...)` mimic
`runner.scenario.load.load` and `runner.run.simulate`.
"""

from __future__ import annotations

import copy
import hashlib
import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from collide2d.engine.events import EVENT_DTYPE
from collide2d.engine.world import WorldSpec

BASE = {
    "name": "demo",
    "model": "paper",
    "ticks": 4,
    "width": 8,
    "height": 6,
    "fps": 10,
    "golden": {"frames": [0, 4], "time_tolerance": 0.0, "max_diff_pixels": 0, "color_threshold": 0},
    "events": [[2, 0.2, 0, 1, -1, 0, -1, -1], [3, 0.3, 1, 0, 1, 0, 2, 5]],
    "final": [[1.0, 2.0, 10.0, 0.0], [5.5, 3.0, -10.0, 2.5]],
    "pixels": [[0, 1, 1, 255, 0, 0], [0, 6, 4, 0, 255, 0], [4, 3, 2, 255, 255, 255]],
}


def spec(**changes) -> dict:
    """A copy of BASE with top-level fields replaced."""
    out = copy.deepcopy(BASE)
    out.update(copy.deepcopy(changes))
    return out


def write(path, data: dict) -> Path:
    """Write a synthetic scenario file; returns its path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=1) + "\n")
    return path


def load(path, *, overrides=None, limits=None):
    """A Scenario-like record of a synthetic file (raises ScenarioError for an `error` field)."""
    text = Path(path).read_text()
    data = json.loads(text)
    if "error" in data:
        from collide2d.runner.scenario.load import ScenarioError

        raise ScenarioError(path, 1, 1, data["error"])
    g = data["golden"]
    return SimpleNamespace(
        path=str(path),
        name=data["name"],
        model=data["model"],
        ticks=data["ticks"],
        world=WorldSpec(data["width"], data["height"], data["fps"]),
        golden=SimpleNamespace(
            frames=tuple(g["frames"]),
            time_tolerance=g["time_tolerance"],
            max_diff_pixels=g["max_diff_pixels"],
            color_threshold=g["color_threshold"],
        ),
        data=data,
        text_sha256=hashlib.sha256(text.encode()).hexdigest(),
    )


def simulate(scenario, *, keep_frames=(), log_events=True, progress=False):
    """A RunResult-like record with the results the synthetic file states."""
    data = scenario.data
    events = np.zeros(len(data["events"]) if log_events else 0, dtype=EVENT_DTYPE)
    for rec, row in zip(events, data["events"], strict=True):
        for field, value in zip(EVENT_DTYPE.names, row, strict=True):
            rec[field] = value
    final = np.array(data["final"], dtype=np.float64).reshape(-1, 4)
    frames = {}
    for k in keep_frames:
        w, h = data.get("sizes", {}).get(str(k), (data["width"], data["height"]))
        rgb = np.zeros((h, w, 3), np.uint8)
        for frame, x, y, r, g, b in data["pixels"]:
            if frame == k and x < w and y < h:
                rgb[y, x] = (r, g, b)
        frames[int(k)] = rgb
    return SimpleNamespace(
        scenario=scenario,
        events=events,
        final_pos=final[:, :2].copy(),
        final_vel=final[:, 2:].copy(),
        frames=frames,
        summary={},
    )
