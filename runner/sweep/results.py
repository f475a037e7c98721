"""The results of a sweep: one row per run, sorted by its parameters, and the files OUT/sweep/.

`rows(runs, figures, positions)` joins each finished run's parameters (`matrix.Run.params`) with
the figures its worker measured (`runs.run_one`), in the runs' sorted order, so the table is the
same whatever the worker count or the order runs finished in. When the sweep includes the `exact`
model, each run's `position_error_px` is the mean distance of its final positions from those of
the `exact` run of the same scenario, swept keys, seed, fps and ticks (the same horizon; the
exact run of the same geometry when both are swept, else of the exact geometry), computed by the
benchmark's one definition (`runner.bench.error.position_error`).

`write(folder, ...)` writes `results.csv` (the parameter columns, then `FIGURES`; `run_time_s`, the
wall time, is the last column and the only one that changes between two sweeps), `results.md` (one
table per scenario), both safe to open whatever a value holds (`runner.escape`: no text cell runs
as a spreadsheet formula, no cell breaks its markdown row), `sweep.json` (runs asked, done,
complete or not) and, with the `plot` extra and position errors, `runtime_vs_error.png` (the
benchmark's plot). Every file is replaced atomically.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

from collide2d.runner import escape, outputs
from collide2d.runner.bench.error import mark_pareto, position_error

FIGURES = (
    "status",
    "objects",
    "wall_events",
    "pair_events",
    "energy_drift",
    "momentum_drift",
    "worst_overlap_px",
    "left_world",
    "position_error_px",
    "note",
    "run_time_s",
)
PLOT = "runtime_vs_error.png"


def _reference(run, done: dict, positions: dict, by_key: dict):
    """The final positions of the exact run that `run` is measured against, or None."""
    candidates = [
        r
        for r in by_key.get(run.ref_key, ())
        if r.index in done and positions.get(r.index) is not None
    ]
    if not candidates:
        return None
    geometry = run.params["geometry"] or "box"
    for wanted in (geometry, "exact"):
        for r in candidates:
            if r.params["geometry"] == wanted:
                return positions[r.index]
    return positions[candidates[0].index]


def rows(runs, figures: dict, positions: dict) -> list[dict]:
    """The finished runs' rows, in the runs' order (see the module docstring)."""
    with_error = any(r.params["model"] == "exact" for r in runs)
    by_key: dict[tuple, list] = {}
    for r in runs:
        if r.params["model"] == "exact":
            by_key.setdefault(r.ref_key, []).append(r)
    out = []
    for run in runs:
        if run.index not in figures:
            continue
        row = dict(run.params)
        row.update({k: "" for k in FIGURES})
        row.update(figures[run.index])
        if with_error and positions.get(run.index) is not None:
            ref = _reference(run, figures, positions, by_key)
            if ref is not None:
                row["position_error_px"] = position_error(positions[run.index], ref)
        out.append(row)
    return out


def _text(value, digits: int = 9) -> str:
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def csv_text(columns: list[str], table: list[dict]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    header = list(columns) + list(FIGURES)
    writer.writerow(header)
    for row in table:
        writer.writerow([_text(escape.csv_cell(row[c])) for c in header])
    return buf.getvalue()


def markdown(columns: list[str], table: list[dict], total: int, complete: bool) -> str:
    lines = ["# Sweep", ""]
    if complete:
        lines.append(f"{len(table)} runs.")
    else:
        lines.append(
            f"**Incomplete**: cancelled with {len(table)} of {total} runs done; the rows below "
            "are the runs that finished."
        )
    shown = [c for c in columns if c != "scenario"] + [c for c in FIGURES if c != "note"]
    for scenario in dict.fromkeys(r["scenario"] for r in table):
        mine = [r for r in table if r["scenario"] == scenario]
        lines += ["", f"## {escape.one_line(scenario)}", ""]
        lines.append("| " + " | ".join(escape.markdown_cell(c) for c in shown) + " |")
        lines.append("|" + "---|" * len(shown))
        for r in mine:
            cells = (escape.markdown_cell(_text(r[c], 4)) for c in shown)
            lines.append("| " + " | ".join(cells) + " |")
        notes = [r for r in mine if r["note"]]
        if notes:
            lines.append("")
            for r in notes:
                said = ", ".join(f"{c}={r[c]}" for c in columns if c != "scenario" and r[c])
                lines.append(escape.one_line(f"- {said}: {r['note']}"))
    return "\n".join(lines) + "\n"


def _plot(columns: list[str], table: list[dict], folder: Path) -> list[str]:
    """runtime_vs_error.png through the benchmark's plot, when there are position errors."""
    from collide2d.runner.bench import plots

    points = [
        {
            "part": "error",
            "scene": r["scenario"],
            "model": r["model"],
            "label": ",".join(_text(r[c], 4) for c in columns if c not in ("scenario", "model")),
            "run_time_s": r["run_time_s"],
            "error_long_px": r["position_error_px"],
        }
        for r in table
        if r["position_error_px"] != "" and r["run_time_s"] != ""
    ]
    if not points:
        return []
    for scene in dict.fromkeys(p["scene"] for p in points):
        mark_pareto([p for p in points if p["scene"] == scene])
    return plots.plots(points, folder)


def write(
    folder: Path, columns: list[str], table: list[dict], total: int, complete: bool
) -> list[str]:
    """Write the sweep's files into `folder` (made if missing); the names written."""
    outputs.make_folder(folder)
    outputs.atomic_write_text(folder / "results.csv", csv_text(columns, table))
    outputs.atomic_write_text(folder / "results.md", markdown(columns, table, total, complete))
    status = {"runs": total, "done": len(table), "complete": complete}
    outputs.atomic_write_text(folder / "sweep.json", json.dumps(status, indent=2) + "\n")
    written = ["results.csv", "results.md", "sweep.json"]
    plotted = _plot(columns, table, folder)
    if not plotted and (folder / PLOT).is_file():
        (folder / PLOT).unlink()  # a previous sweep's plot would not match these rows
    return written + plotted
