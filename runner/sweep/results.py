"""The results of a sweep: one row per run, sorted by its parameters, and the files OUT/sweep/.

A `Table` keeps the figures each worker measured (`worker.run_one`) by run number, a few numbers a
row in arrays sized to the plan (no run's scenario, no dict per row), so its memory is a small
fixed cost per run. The rows come out in the plan's sorted order (`plan.Plan.runs`: each run's
parameters, `plan.Run.params`, then its figures), the same whatever the worker count or the order
runs finished in. When the sweep includes the `exact` model, each run's `position_error_px` is the
mean distance of its final positions from those of the `exact` run of the same scenario, swept
keys, seed, fps and ticks (the same horizon; the exact run of the same geometry when both are
swept, else of the exact geometry), computed by the benchmark's one definition
(`runner.bench.error.position_error`). Final positions are kept only until every run of that
reference group is done (the runs are sent in order, so a group is done soon after it starts).

`write(folder, ...)` writes `results.csv` (the parameter columns, then `FIGURES`; `run_time_s`, the
wall time, is the last column and the only one that changes between two sweeps), `results.md` (one
table per scenario), both safe to open whatever a value holds (`runner.output.escape`: no text cell
runs as a spreadsheet formula, no cell breaks its markdown row), `sweep.json` (runs asked, done,
complete or not) and, with the `plot` extra and position errors, `runtime_vs_error.png` (the
benchmark's plot), row by row into `folder`: the sweep's staging folder, swapped in whole
(`runner.sweep.folder`).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from collide2d.runner.bench.error import mark_pareto, position_error
from collide2d.runner.output import escape

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
STATUSES = ("ok", "stopped", "error")
_INTS = ("objects", "wall_events", "pair_events", "left_world")
_FLOATS = ("energy_drift", "momentum_drift", "worst_overlap_px", "position_error_px", "run_time_s")


class Table:
    """The figures of a sweep's finished runs, by run number (see the module docstring)."""

    def __init__(self, plan):
        n = len(plan)
        self.plan = plan
        self.status = np.full(n, -1, np.int8)  # index into STATUSES; -1 not done
        self.ints = np.zeros((n, len(_INTS)), np.int64)
        self.floats = np.zeros((n, len(_FLOATS)), np.float64)
        self.has = np.zeros((n, len(_INTS) + len(_FLOATS)), np.bool_)
        self.notes: dict[int, str] = {}
        self.done = 0
        self._groups: dict[tuple, list] = {}  # reference group -> [(run, positions)]

    def take(self, run, figures: dict, positions) -> None:
        """Keep run `run`'s figures (and its final positions while its group needs them)."""
        i = run.index
        if self.status[i] < 0:
            self.done += 1
        self.status[i] = STATUSES.index(figures["status"])
        for k, name in enumerate(_INTS):
            if name in figures and figures[name] != "":
                self.ints[i, k], self.has[i, k] = figures[name], True
        for k, name in enumerate(_FLOATS):
            if name in figures and figures[name] != "":
                self.floats[i, k], self.has[i, len(_INTS) + k] = figures[name], True
        if figures.get("note"):
            self.notes[i] = figures["note"]
        if not self.plan.with_exact:
            return
        group = self._groups.setdefault(run.ref_key, [])
        group.append((run, positions))
        if len(group) == self.plan.ref_sizes[run.combo.ref]:
            self._measure(self._groups.pop(run.ref_key))

    def finish(self) -> None:
        """Measure the groups left with the runs done (a cancelled sweep)."""
        for key in list(self._groups):
            self._measure(self._groups.pop(key))

    def _measure(self, group: list) -> None:
        """position_error_px of each run of one reference group against its exact run."""
        group.sort(key=lambda rp: rp[0].index)
        exact = [(r, p) for r, p in group if r.params["model"] == "exact" and p is not None]
        if not exact:
            return
        column = len(_INTS) + _FLOATS.index("position_error_px")
        for run, pos in group:
            if pos is None:
                continue
            ref = _reference(run, exact)
            self.floats[run.index, column - len(_INTS)] = position_error(pos, ref)
            self.has[run.index, column] = True

    def row(self, run) -> dict | None:
        """The row of `run` (its parameters and figures), None when it did not finish."""
        i = run.index
        if self.status[i] < 0:
            return None
        row = dict(run.params)
        row.update({k: "" for k in FIGURES})
        row["status"] = STATUSES[self.status[i]]
        for k, name in enumerate(_INTS):
            if self.has[i, k]:
                row[name] = int(self.ints[i, k])
        for k, name in enumerate(_FLOATS):
            if self.has[i, len(_INTS) + k]:
                row[name] = float(self.floats[i, k])
        row["note"] = self.notes.get(i, "")
        return row

    def count(self, status: str) -> int:
        """Runs done with this status."""
        return int(np.count_nonzero(self.status == STATUSES.index(status)))

    def rows(self):
        """The finished runs' rows, in the runs' sorted order."""
        for run in self.plan.runs():
            row = self.row(run)
            if row is not None:
                yield row


def _reference(run, exact: list):
    """The final positions of the exact run that `run` is measured against."""
    geometry = run.params["geometry"] or "box"
    for wanted in (geometry, "exact"):
        for r, pos in exact:
            if r.params["geometry"] == wanted:
                return pos
    return exact[0][1]


def _text(value, digits: int = 9) -> str:
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def write_csv(file, columns: list[str], rows) -> None:
    """results.csv of `rows` (dicts) into the open text `file`."""
    writer = csv.writer(file, lineterminator="\n")
    header = list(columns) + list(FIGURES)
    writer.writerow(header)
    for row in rows:
        writer.writerow([_text(escape.csv_cell(row[c])) for c in header])


def write_markdown(file, columns: list[str], rows, total: int, done: int, complete: bool):
    """results.md of `rows` (dicts, a scenario's rows together) into the open text `file`."""
    file.write("# Sweep\n\n")
    if complete:
        file.write(f"{done} runs.\n")
    else:
        file.write(
            f"**Incomplete**: cancelled with {done} of {total} runs done; the rows below "
            "are the runs that finished.\n"
        )
    shown = [c for c in columns if c != "scenario"] + [c for c in FIGURES if c != "note"]
    scenario, notes = None, []

    def end_scenario():
        if notes:
            file.write("\n")
            for r in notes:
                said = ", ".join(f"{c}={r[c]}" for c in columns if c != "scenario" and r[c])
                file.write(escape.one_line(f"- {said}: {r['note']}") + "\n")
        notes.clear()

    for r in rows:
        if r["scenario"] != scenario:
            end_scenario()
            scenario = r["scenario"]
            file.write(f"\n## {escape.one_line(scenario)}\n\n")
            file.write("| " + " | ".join(escape.markdown_cell(c) for c in shown) + " |\n")
            file.write("|" + "---|" * len(shown) + "\n")
        file.write("| " + " | ".join(escape.markdown_cell(_text(r[c], 4)) for c in shown) + " |\n")
        if r["note"]:
            notes.append({c: r[c] for c in (*columns, "note")})
    end_scenario()


def _plot(columns: list[str], rows, folder: Path) -> list[str]:
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
        for r in rows
        if r["position_error_px"] != "" and r["run_time_s"] != ""
    ]
    if not points:
        return []
    for scene in dict.fromkeys(p["scene"] for p in points):
        mark_pareto([p for p in points if p["scene"] == scene])
    return plots.plots(points, folder)


def write(folder: Path, table: Table, complete: bool) -> list[str]:
    """Write the sweep's files into the empty `folder`; the names written."""
    plan = table.plan
    with open(folder / "results.csv", "w", encoding="utf-8", newline="") as f:
        write_csv(f, plan.columns, table.rows())
    with open(folder / "results.md", "w", encoding="utf-8", newline="") as f:
        write_markdown(f, plan.columns, table.rows(), len(plan), table.done, complete)
    status = {"runs": len(plan), "done": table.done, "complete": complete}
    (folder / "sweep.json").write_text(json.dumps(status, indent=2) + "\n", encoding="utf-8")
    written = ["results.csv", "results.md", "sweep.json"]
    if plan.with_exact:
        written += _plot(plan.columns, table.rows(), folder)
    return written
