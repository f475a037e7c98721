"""One run of a sweep, as a worker does it: the figures of its row.

`run_one(scenario)` runs the scenario twice. First tick by tick, looking at every tick's end: the
deepest overlap of two boxes (`engine.invariants.max_penetration`) and which objects stuck out of
the world (`mark_outside`); this first run also loads or compiles the kernels, so that cost never
lands in the timing. Then once as `collide2d run` does (`runner.run.drive`, no frames, no log),
timed: its summary gives the wall time, the events by type and the energy and momentum at both
ends. A model that stops the run (a runaway) makes a row with status `stopped` and its message.
`run_batch(runs)` runs several, in order, as one Dask task (`runner.sweep.driver`), each given as
its combination's scenario and its seed, whose objects it draws first (`runner.sweep.reseed`).

Kernels are numba's with `cache=True`: a worker process compiles (or loads from the cache on
disk) each kernel the first time it runs it and keeps it for every later run it is given.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.errors import Runaway
from collide2d.engine.invariants import max_penetration
from collide2d.engine.jit import njit
from collide2d.runner import lanes

OUTSIDE_TOL_PX = 1e-9  # px a box may stick out of the world by rounding
STATUS_OK = "ok"
STATUS_STOPPED = "stopped"
STATUS_ERROR = "error"


@njit(cache=True)
def mark_outside(pos, size, width, height, tol, left):
    """Set left[i] for each box that sticks out of the world by more than `tol` px.

    pos, size (n, 2) float64 px; left (n,) bool, updated in place."""
    for i in range(pos.shape[0]):
        x = pos[i, 0]
        y = pos[i, 1]
        if x < -tol or y < -tol or x + size[i, 0] > width + tol or y + size[i, 1] > height + tol:
            left[i] = True


def _checked(scenario) -> tuple[float, int]:
    """(deepest overlap px over every tick's end, objects that left the world at any)."""
    from collide2d.runner.run import make_model

    bodies = scenario.bodies
    model = make_model(scenario)
    size = np.ascontiguousarray(bodies.size, np.float64)
    width, height = float(scenario.world.width), float(scenario.world.height)
    left = np.zeros(bodies.n, np.bool_)
    deepest = 0.0
    for k in range(scenario.ticks + 1):
        if k:
            model.advance(1, False)
        pos = np.ascontiguousarray(model.positions(), np.float64)
        deepest = max(deepest, float(max_penetration(pos, size)[0]))
        mark_outside(pos, size, width, height, OUTSIDE_TOL_PX, left)
    return deepest, int(left.sum())


def run_batch(runs) -> list[tuple[dict, np.ndarray | None]]:
    """run_one of each run, in order, given as (its combination's scenario, its seed or None:
    `runner.sweep.plan.scenario_of` draws the run's objects); a run that raises (a bug) is a row
    with status `error` and the exception in its note, and the others still run. A fatal signal (a
    crash in a kernel) leaves its traceback where the sweep finds it (runner.command.crashwatch)."""
    from collide2d.runner.command import crashwatch
    from collide2d.runner.sweep.plan import scenario_of

    crashwatch.record_in_worker()
    out = []
    with lanes.loads(len(runs)):
        for base, seed in runs:
            try:
                out.append(run_one(scenario_of(base, seed)))
            except Exception as exc:
                out.append((error_figures(exc), None))
    return out


def error_figures(exc: BaseException, since: float | None = None) -> dict:
    """The figures of a run that failed unexpectedly: status `error`, the exception as note; for
    a task whose workers all died (Dask's KilledWorker), why they died, as the traceback one of
    them left after `since` (time.time()) tells (runner.command.crashwatch)."""
    if type(exc).__name__ == "KilledWorker":
        from collide2d.runner.command import crashwatch

        return {"status": STATUS_ERROR, "note": crashwatch.worker_death(since or 0.0)}
    detail = " ".join(str(exc).split())[:300]
    return {"status": STATUS_ERROR, "note": f"{type(exc).__name__}: {detail}"}


def run_one(scenario) -> tuple[dict, np.ndarray | None]:
    """(the figures of the row, the final positions or None) of one run of `scenario`."""
    from collide2d.runner.run import RunStopped, drive

    try:
        overlap, left = _checked(scenario)
        model, summary = drive(scenario)
    except (Runaway, RunStopped) as exc:
        return {"status": STATUS_STOPPED, "note": " ".join(str(exc).split())}, None
    bodies = scenario.bodies
    e0, e1 = summary["kinetic_energy"]["start"], summary["kinetic_energy"]["end"]
    p0 = np.array(summary["momentum"]["start"])
    p1 = np.array(summary["momentum"]["end"])
    movers = float(np.sum(bodies.mass[~bodies.static]))
    scale = math.sqrt(2.0 * e0 * movers) if e0 > 0 else 0.0
    figures = {
        "status": STATUS_OK,
        "objects": bodies.n,
        "wall_events": summary["events"]["wall"],
        "pair_events": summary["events"]["pair"],
        "energy_drift": (e1 - e0) / e0 if e0 > 0 else 0.0,
        "momentum_drift": float(np.hypot(*(p1 - p0))) / scale if scale > 0 else 0.0,
        "worst_overlap_px": overlap,
        "left_world": left,
        "run_time_s": summary["run_time_s"],
        "note": "",
    }
    return figures, model.positions()
