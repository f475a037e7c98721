"""The reports of `collide2d bench`: bench.csv (one row per measurement, the columns of `COLUMNS`)
and bench.md (the headline ratios first, then one table per part). Cells go through
`runner.output.escape`: no text cell of bench.csv runs as a spreadsheet formula, no cell of bench.md
breaks its table row.
"""

from __future__ import annotations

import os

import numpy as np

from collide2d.runner.bench import goals
from collide2d.runner.bench.error import NUDGE_PX_S
from collide2d.runner.bench.scenes import (
    STANDARD_COVERAGE,
    STANDARD_FPS,
    STANDARD_SEED,
    STANDARD_SIZE_PX,
    STANDARD_SPEEDS,
)
from collide2d.runner.bench.targets import AUTO_WITHIN
from collide2d.runner.output import escape

# The parts whose rows are one figure each (`value`, described by `note`), and their titles.
FIGURE_PARTS = {
    "paper": "Paper model: the section IV demo",
    "exact": "Exact model: events per second",
    "raster": "Drawing and writing frames",
    "stages": "Stages: time per body-step, one thread and all, and pymunk in the same run",
    "load": "Loading a big scene",
    "compile": "Compiling each model's kernels from an empty kernel cache (seconds)",
    "gravity": "Gravity: a settling pile against pymunk, the closed forms, exact events/s",
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
    "run_time_min_s",
    "run_time_max_s",
    "repeats",
    "calls",
    "spread",
    "noisy",
    "pairs",
    "missed",
    "count_error",
    "energy_drift",
    "max_penetration_px",
    "short_s",
    "error_short_px",
    "long_s",
    "error_long_px",
    "diverges_s",
    "pareto",
    "peer_steps_per_s",
    "ratio",
    "with_s",
    "on_s",
    "off_s",
    "off_stopped",
    "on_stopped",
    "auto_s",
    "without_s",
    "saving",
    "saving_min",
    "saving_max",
    "target",
    "met",
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
        writer.writerow([_cell(escape.csv_cell(r.get(c))) for c in COLUMNS])
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


def _range(r) -> str:
    """A timing's median and (min-max), s, or a blank."""
    if r.get("run_time_s") is None or r.get("run_time_min_s") is None:
        return "—"
    return f"{r['run_time_s']:.3g} ({r['run_time_min_s']:.3g}-{r['run_time_max_s']:.3g})"


def _table(header: list[str], lines: list[list]) -> list[str]:
    cell = escape.markdown_cell
    out = ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(cell(_fmt(v)) for v in line) + " |" for line in lines]
    return out


NOISY_LINE = "timings marked noisy (spread > 20 %)"


def headline(rows: list[dict]) -> list[tuple[str, str, str, str]]:
    """(what, figure, target, "✓" / "✗" / "") rows of the issue's targets, from this run's rows."""
    out = []

    def add(what, figure, target="", met=None):
        out.append((what, figure, target, "" if met is None else ("✓" if met else "✗")))

    scale = {r["n"]: r for r in rows if r["part"] == "scaling" and r["model"] == "stepped"}
    paper = {r["n"]: r for r in rows if r["part"] == "scaling" and r["model"] == "paper"}
    for r in rows:
        if r["part"] == "peers" and "ratio" in r:
            goal = goals.PEER_RATIO.get(r["n"])
            add(f"stepped / pymunk steps/s, N = {r['n']:,}", f"{r['ratio']:.2f}",
                f">= {goal:g}" if goal else "", r["ratio"] >= goal if goal else None)  # fmt: skip
    n, most = goals.STEPPED_NS_PER_BODY_STEP
    if n in scale:
        ns = scale[n]["ns_per_body_step"]
        add(f"stepped ns per body-step, N = {n:,}", f"{ns:.1f}", f"<= {most:g}", ns <= most)
    n, least = goals.PAPER_STEPS_PER_S
    if n in paper:
        steps = paper[n]["steps_per_s"]
        add(f"paper steps/s, N = {n:,}", f"{steps:,.0f}", f">= {least:,.0f}", steps >= least)
    for r in rows:
        if r["part"] == "exact" and r["scene"] in goals.EXACT_EVENTS_PER_S:
            least = goals.EXACT_EVENTS_PER_S[r["scene"]]
            add(f"exact events/s, {r['scene']}", f"{r['value']:,.0f}", f">= {least:,}",
                r["value"] >= least)  # fmt: skip
        if r["part"] == "load" and r.get("how") in goals.LOAD:
            most_s, most_mb = goals.LOAD[r["how"]]
            target = f"<= {most_s:g} s" + (f", <= {most_mb} MB" if most_mb else "")
            met = r["value"] <= most_s and (most_mb is None or r["peak_mb"] <= most_mb)
            figure = f"{r['value']:.2f} s, {r['peak_mb']:.0f} MB"
            add(f"load {r['n']:,} objects, {r['how']}", figure, target, met)
    if 1_000 in scale and max(scale) > 1_000:
        big = max(scale)
        ratio = scale[big]["ns_per_body_step"] / scale[1_000]["ns_per_body_step"]
        add(f"stepped cost per body-step, N = {big:,} / N = 1,000", f"{ratio:.2f}", "<= 2",
            ratio <= 2)  # fmt: skip
    for r in rows:
        if r["part"] == "targets":
            figure = f"{r['value']:,.0f}" if r["value"] > 100 else f"{r['value']:.3f}"
            add(r["note"], figure, r.get("target", ""), r.get("met"))
        if r["part"] == "compile":
            add(r["note"], f"{r['value']:.1f}", r["target"], r["met"])
    for r in rows:
        if (
            r["part"] == "error"
            and r["model"] == "stepped"
            and r["scene"] == "bench_dense_gas"
            and r["substeps"] == max(x["substeps"] for x in rows if x["part"] == "error")
            and r["fps"] == 60
        ):
            add(f"stepped error at {r['long_s']:g} s, bench_dense_gas, {r['substeps']} substeps",
                f"{r['error_long_px']:.3g} px", "< 1 px", r["error_long_px"] < 1)  # fmt: skip
        if r["part"] == "glancing":
            v = r["value"]
            add("glancing tunnelling at 1 substep below one box size per step",
                "none" if v is None else f"{v:g} box/step", "none", v is None)  # fmt: skip
    cold = [r for r in rows if r["part"] == "jit"]
    if cold:
        worst = max(cold, key=lambda r: r["ratio"])
        add(f"--jit auto / the faster of on and off, empty cache, worst of {len(cold)} scenes "
            f"({worst['scene']})", f"{worst['ratio']:.2f}", f"<= {worst['target'][3:]}",
            all(r["met"] for r in cold))  # fmt: skip
    noisy = [r for r in rows if r.get("noisy") == "yes"]
    timed = [r for r in rows if r.get("noisy") in ("yes", "no")]
    if timed:
        spread = max(r["spread"] for r in timed)
        add(NOISY_LINE, f"{len(noisy)} of {len(timed)}", "0",
            not noisy)  # fmt: skip
        add("largest repeat spread (max - min) / median", f"{spread:.0%}")
    return out


def missed(headline: list[tuple[str, str, str, str]]) -> list[tuple[str, str, str]]:
    """(what, figure, target) of the headline's targets missed; how noisy the timings were is
    not a target of collide2d's but a note on the figures, and never counts as missed."""
    return [(w, f, t) for w, f, t, met in headline if met == "✗" and w != NOISY_LINE]


def markdown(rows: list[dict], args_line: str, seconds: float) -> str:
    """bench.md: headline, then one table per part."""
    lines = ["# collide2d bench", ""]
    lines.append(
        f"`{args_line}` on {_machine()}, {seconds:.0f} s in all. Ratios are from this one run."
    )
    lines.append("")
    head = headline(rows)
    if head:
        header = ["what", "figure", "target", "met"]
        lines += ["## Headline", ""] + _table(header, [list(h) for h in head]) + [""]
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
        header += ["run s (min-max)", "noisy"]
        keys = ["model", "n", "steps_per_s", "body_steps_per_s", "ns_per_body_step"]
        keys += ["events_per_s", "move_ms", "broad_ms", "narrow_ms", "response_ms", "render_ms"]
        keys += ["note"]
        lines += _table(
            header,
            [[r.get(k) for k in keys] + [_range(r), r.get("noisy")] for r in part],
        ) + [""]
    part = [r for r in rows if r["part"] == "peers"]
    if part:
        lines += ["## Peers", ""]
        header = ["peer", "N", "steps/s", "ns/body-step", "stepped / peer", "broad phase"]
        keys = ["model", "n", "steps_per_s", "ns_per_body_step", "ratio", "note"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    part = [r for r in rows if r["part"] == "error"]
    if part:
        short, long = part[0]["short_s"], part[0]["long_s"]
        lines += ["## Run time against error", ""]
        lines.append(
            "Against the exact model at the scenario's fps, on the bodies the row's model loads "
            "(`generate` draws whole px/s under paper). Run time: seconds to run the long "
            "horizon with the log off, median of interleaved repeats (min-max; noisy: spread "
            f"> 20 %). Error: mean distance to the reference at {short:g} s and {long:g} s, px. "
            "Diverges: when the sequence of pair events first leaves the reference's (blank: "
            "never). missed: collisions of the reference (per pair) the run does not have; count "
            "error: pair events minus the reference's. Pareto: no other row of the scenario is "
            "both faster and closer at the long horizon."
        )
        lines.append("")
        header = ["scenario", "model", "fps", "substeps", "run ms", "min-max ms", "noisy"]
        header += [f"error {short:g} s px", f"error {long:g} s px", "diverges s", "pairs"]
        header += ["missed", "count error", "energy drift", "max penetration px", "Pareto"]
        lines += _table(
            header,
            [
                [r["scene"], r["model"], r["fps"], r["substeps"], 1e3 * r["run_time_s"]]
                + [f"{1e3 * r['run_time_min_s']:.3g}-{1e3 * r['run_time_max_s']:.3g}", r["noisy"]]
                + [r["error_short_px"], r["error_long_px"], r["diverges_s"], r["pairs"]]
                + [r[k] for k in ("missed", "count_error", "energy_drift")]
                + [r["max_penetration_px"], r["pareto"]]
                for r in part
            ],
        ) + [""]
    part = [r for r in rows if r["part"] == "sensitivity"]
    if part:
        lines += ["## How sensitive each scene is", ""]
        lines.append(
            f"The exact model against itself with every velocity nudged by up to {NUDGE_PX_S:g} "
            "px/s: an error this small already carried this far is the scene's own floor."
        )
        lines.append("")
        header = ["scenario", "bodies", "error short px", "error long px", "diverges s"]
        keys = ["scene", "note", "error_short_px", "error_long_px", "diverges_s"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    part = [r for r in rows if r["part"] == "glancing"]
    if part:
        lines += ["## Glancing contacts at one substep", ""]
        lines += _table(
            ["scene", "fps", "finding"], [[r["scene"], r["fps"], r["note"]] for r in part]
        )
        lines.append("")
    part = [r for r in rows if r["part"] == "skips"]
    if part:
        lines += ["## Skips: what a scene does not need", ""]
        lines.append(
            "Medians of interleaved repeats (with, without, without, with, ...); the range is "
            "the extremes against each other; noisy: a spread past 20 %."
        )
        lines.append("")
        header = ["skip", "scene", "with s", "without s", "saving", "min", "max", "noisy"]
        keys = ["note", "scene", "with_s", "without_s", "saving", "saving_min", "saving_max"]
        keys += ["noisy"]
        lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    part = [r for r in rows if r["part"] == "jit"]
    if part:
        lines += _jit_section(part)
    for name, title in FIGURE_PARTS.items():
        part = [r for r in rows if r["part"] == name]
        if part:
            lines += [f"## {title}", ""]
            header = ["what", "scene", "N", "figure"]
            keys = ["note", "scene", "n", "value"]
            lines += _table(header, [[r.get(k) for k in keys] for r in part]) + [""]
    return "\n".join(lines) + "\n"


def _jit_section(rows: list[dict]) -> list[str]:
    """bench.md's section of the jit part."""
    lines = ["## Compiled, interpreted or auto, from an empty kernel cache", ""]
    lines.append(
        "`collide2d run FILE --jit MODE`, each in a fresh process with an empty NUMBA_CACHE_DIR, "
        "wall seconds; `off` stopped past 3x `auto`, `on` once past both others (> s: the lane "
        "takes longer, so the ratio is at most the one shown). auto/faster: "
        f"`auto` over the faster of `on` and `off` (target <= {AUTO_WITHIN:g})."
    )
    lines.append("")
    header = ["scene", "bodies", "ticks", "on s", "off s", "auto s", "auto took", "auto/faster"]
    body = []
    for r in rows:
        off = f"> {r['off_s']:.1f}" if r["off_stopped"] else f"{r['off_s']:.2f}"
        on = f"> {r['on_s']:.1f}" if r.get("on_stopped") else f"{r['on_s']:.2f}"
        body.append([r["scene"], r["n"], r["ticks"], on, off,
                     f"{r['auto_s']:.2f}", r["note"], f"{r['ratio']:.2f}"])  # fmt: skip
    return lines + _table(header, body) + [""]


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
