"""The stress report: one console line per case, and OUT/stress/report.md and report.json.

`line(result)` under `HEADER` is the console table; `report_markdown` and `report_json` hold the
mode, the bounds, every case's figures, problems and notes, and the scenes' descriptions;
`report_dir` is the folder they go to, refused when it is a symbolic link.
"""

from __future__ import annotations

import math
from dataclasses import asdict
from pathlib import Path

from collide2d.runner.stress.cases import VERDICT_FAIL, CaseResult
from collide2d.runner.stress.checks import (
    EXACT_ENERGY_TOL,
    EXACT_MOMENTUM_TOL,
    PENETRATION_TOL_PX,
    STEPPED_ENERGY_TOL,
    STEPPED_MOMENTUM_TOL,
)
from collide2d.runner.stress.falling import every_scene

REPORT_DIR = "stress"


def _num(x: float | None) -> str:
    return "—" if x is None else f"{x:.3g}"


def line(r: CaseResult) -> str:
    """One case as a line of the console table under HEADER."""
    return (
        f"{r.scene:<18} {r.model:<8} {r.verdict:<11} {r.ticks_run:>8}/{r.ticks:<8} "
        f"{r.events:>9} {_num(r.energy_drift):>9} {_num(r.momentum_drift):>9} "
        f"{_num(r.penetration_px):>9} {r.run_time_s:>7.2f}s"
    )


HEADER = (
    f"{'scene':<18} {'model':<8} {'verdict':<11} {'ticks run':>17} {'events':>9} "
    f"{'energy':>9} {'momentum':>9} {'overlap':>9} {'time':>8}"
)


def report_markdown(results: list[CaseResult], quick: bool, total_s: float) -> str:
    """The report as markdown: the table, then every problem and note."""
    broken = [r for r in results if r.verdict == VERDICT_FAIL]
    lines = [
        "# collide2d stress report",
        "",
        f"Mode: {'quick' if quick else 'full'}. Cases: {len(results)}, failed: {len(broken)}. "
        f"Total run time: {total_s:.1f} s.",
        "",
        f"Bounds: exact energy {EXACT_ENERGY_TOL:g} and momentum {EXACT_MOMENTUM_TOL:g} "
        f"(relative), stepped {STEPPED_ENERGY_TOL:g} and {STEPPED_MOMENTUM_TOL:g}, paper keeps "
        f"every velocity component's size; overlap after an exact tick at most "
        f"{PENETRATION_TOL_PX:g} px. "
        "Momentum is measured over ticks without wall events, in scenes without static objects.",
        "",
        "| scene | model | verdict | ticks run | events | energy drift | momentum drift "
        "| largest overlap (px) | run time (s) |",
        "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in results:
        lines.append(
            f"| {r.scene} | {r.model} | {r.verdict} | {r.ticks_run} / {r.ticks} | {r.events} "
            f"| {_num(r.energy_drift)} | {_num(r.momentum_drift)} | {_num(r.penetration_px)} "
            f"| {r.run_time_s:.2f} |"
        )
    notes = [r for r in results if r.problems or r.note]
    if notes:
        lines += ["", "## Problems and notes", ""]
        for r in notes:
            for p in r.problems:
                lines.append(f"- **{r.scene} / {r.model}**: {p}")
            if r.note:
                lines.append(f"- {r.scene} / {r.model}: {r.note}")
    run = {r.scene for r in results}
    lines += ["", "## Scenes", ""]
    lines += [f"- `{s.name}`: {s.about}." for s in every_scene(quick) if s.name in run]
    return "\n".join(lines) + "\n"


def report_json(results: list[CaseResult], quick: bool, total_s: float) -> dict:
    """The report as a JSON object: mode, verdict, bounds, scene descriptions, every case."""
    return {
        "mode": "quick" if quick else "full",
        "ok": all(r.verdict != VERDICT_FAIL for r in results),
        "run_time_s": round(total_s, 3),
        "bounds": {
            "exact_energy": EXACT_ENERGY_TOL,
            "exact_momentum": EXACT_MOMENTUM_TOL,
            "stepped_energy": STEPPED_ENERGY_TOL,
            "stepped_momentum": STEPPED_MOMENTUM_TOL,
            "penetration_px": PENETRATION_TOL_PX,
        },
        "scenes": {s.name: s.about for s in every_scene(quick)},
        "cases": [{k: _json_number(v) for k, v in asdict(r).items()} for r in results],
    }


def _json_number(v):
    """Floats that JSON cannot hold (inf, nan) as text; anything else as it is."""
    return repr(v) if isinstance(v, float) and not math.isfinite(v) else v


def report_dir(out_root) -> Path:
    """OUT/stress, refusing to write through a symbolic link."""
    target = Path(out_root) / REPORT_DIR
    if target.is_symlink():
        raise ValueError(f"report folder {target} is a symbolic link; refusing to write through it")
    return target
