"""The reports of `collide2d bench`: bench.csv (one row per measurement, the columns of `COLUMNS`)
and bench.md (the headline ratios first, then one table per part).
"""

from __future__ import annotations

import os

import numpy as np

from collide2d.runner.bench.error import HORIZON_S
from collide2d.runner.bench.peers import PEER_TARGET_MIN_N
from collide2d.runner.bench.scenes import (
    STANDARD_COVERAGE,
    STANDARD_FPS,
    STANDARD_SEED,
    STANDARD_SIZE_PX,
    STANDARD_SPEEDS,
)

# The parts whose rows are one figure each (`value`, described by `note`), and their titles.
FIGURE_PARTS = {
    "paper": "Paper model: the section IV demo",
    "exact": "Exact model: events per second",
    "raster": "Drawing and writing frames",
    "stages": "Stages: time per body-step, one thread and all, and pymunk in the same run",
    "load": "Loading a big scene",
}
COLUMNS = (
    "part",
    "scene",
    "model",
    "n",
    "fps",
    "substeps",
    "ticks",
    "steps_per_s",
    "body_steps_per_s",
    "ns_per_body_step",
    "events_per_s",
    "move_ms",
    "broad_ms",
    "narrow_ms",
    "response_ms",
    "render_ms",
    "run_time_s",
    "pairs",
    "missed",
    "count_error",
    "energy_drift",
    "max_penetration_px",
    "position_error_px",
    "horizon_s",
    "pareto",
    "peer_steps_per_s",
    "ratio",
    "with_s",
    "without_s",
    "saving",
    "value",
    "note",
)


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def csv_text(rows: list[dict]) -> str:
    """bench.csv: a header of COLUMNS and one line per row, blanks where a column does not apply."""
    import csv
    import io

    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(COLUMNS)
    for r in rows:
        writer.writerow([_cell(r.get(c)) for c in COLUMNS])
    return buf.getvalue()


def _fmt(value, digits: int = 3) -> str:
    """A table cell: whole thousands with separators, else `digits` significant digits."""
    if value is None or value == "":
        return "—"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return str(value)
    if value != value:  # nan
        return "nan"
    if abs(value) >= 1000:
        return f"{value:,.0f}"
    if isinstance(value, (int, np.integer)):
        return str(value)
    return f"{value:.{digits}g}"


def _table(header: list[str], lines: list[list]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(_fmt(v) for v in line) + " |" for line in lines]
    return out


def headline(rows: list[dict]) -> list[tuple[str, str]]:
    """(what, figure) pairs of the issue's targets, from this run's rows."""
    out = []
    scale = {r["n"]: r for r in rows if r["part"] == "scaling" and r["model"] == "stepped"}
    for r in rows:
        if r["part"] == "peers" and "ratio" in r:
            target = " (target >= 5)" if r["n"] >= PEER_TARGET_MIN_N else ""
            out.append((f"stepped / pymunk steps/s, N = {r['n']:,}{target}", f"{r['ratio']:.2f}"))
    if 1_000 in scale and max(scale) > 1_000:
        big = max(scale)
        ratio = scale[big]["ns_per_body_step"] / scale[1_000]["ns_per_body_step"]
        out.append(
            (f"stepped cost per body-step, N = {big:,} / N = 1,000 (target <= 2)", f"{ratio:.2f}")
        )
    for r in rows:
        if r["part"] == "targets":
            figure = f"{r['value']:,.0f}" if r["value"] > 100 else f"{r['value']:.3f}"
            out.append((r["note"], figure))
    return out


def markdown(rows: list[dict], args_line: str, seconds: float) -> str:
    """bench.md: headline, then one table per part."""
    lines = ["# collide2d bench", ""]
    lines.append(
        f"`{args_line}` on {_machine()}, {seconds:.0f} s in all. Ratios are from this one run."
    )
    lines.append("")
    head = headline(rows)
    if head:
        lines += ["## Headline", ""] + _table(["what", "figure"], [list(h) for h in head]) + [""]
    part = [r for r in rows if r["part"] == "scaling"]
    if part:
        lines += ["## Scaling: the standard scene", ""]
        lines.append(
            f"N boxes {STANDARD_SIZE_PX}x{STANDARD_SIZE_PX} px covering "
            f"{STANDARD_COVERAGE:.0%} of a 4:3 world, {STANDARD_SPEEDS[0]}-{STANDARD_SPEEDS[1]} "
            f"px/s, {STANDARD_FPS} fps, seed {STANDARD_SEED}. Stage times per step are measured "
            "by running the stages one at a time (each includes a call's overhead of a few "
            "microseconds); render is one frame of the whole world."
        )
        lines.append("")
        header = ["model", "N", "steps/s", "body-steps/s", "ns/body-step", "events/s"]
        header += ["move ms", "broad ms", "narrow ms", "response ms", "render ms", "timed by"]
        keys = ["model", "n", "steps_per_s", "body_steps_per_s", "ns_per_body_step"]
        keys += ["events_per_s", "move_ms", "broad_ms", "narrow_ms", "response_ms", "render_ms"]
        keys += ["note"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    part = [r for r in rows if r["part"] == "peers"]
    if part:
        lines += ["## Peers", ""]
        header = ["peer", "N", "steps/s", "ns/body-step", "stepped / peer", "broad phase"]
        keys = ["model", "n", "steps_per_s", "ns_per_body_step", "ratio", "note"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    part = [r for r in rows if r["part"] == "error"]
    if part:
        lines += ["## Run time against error", ""]
        lines.append(
            "Against the exact model at the scenario's fps. missed: collisions of the reference "
            "(per pair) the run does not have; count error: pair events minus the reference's; "
            f"position error: mean distance to the reference {HORIZON_S} s after its first "
            "collision (the horizon, s); Pareto: no "
            "other row of the scenario is both faster and closer."
        )
        lines.append("")
        header = ["scenario", "model", "fps", "substeps", "run ms", "pairs", "missed"]
        header += ["count error", "energy drift", "max penetration px", "position error px"]
        header += ["horizon s", "Pareto"]
        lines += _table(
            header,
            [
                [r["scene"], r["model"], r["fps"], r["substeps"], 1e3 * r["run_time_s"]]
                + [r[k] for k in ("pairs", "missed", "count_error", "energy_drift")]
                + [r["max_penetration_px"], r["position_error_px"], r["horizon_s"], r["pareto"]]
                for r in part
            ],
        ) + [""]
    part = [r for r in rows if r["part"] == "skips"]
    if part:
        lines += ["## Skips: what a scene does not need", ""]
        header = ["skip", "scene", "with s", "without s", "saving"]
        keys = ["note", "scene", "with_s", "without_s", "saving"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    for name, title in FIGURE_PARTS.items():
        part = [r for r in rows if r["part"] == name]
        if part:
            lines += [f"## {title}", ""]
            header = ["what", "scene", "N", "figure"]
            keys = ["note", "scene", "n", "value"]
            lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    return "\n".join(lines) + "\n"


def _machine() -> str:
    import platform

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"
