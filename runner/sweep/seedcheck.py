"""A sweep's seeds checked in the background, ahead of the runs: each run checked before it is sent.

`plan.check` loads each combination of settings in full with the first seed; what another seed
changes, the objects its `generate` blocks draw, `check_run(plan, run)` checks by drawing them again
(`runner.sweep.reseed`, the drawing alone), and refuses a seed the drawing refuses with the located
message its full load gives (`FILE:LINE:COL: error: in the sweep run ..., seed=N: ...`). Drawing
100,000 seeds of a 2,000-object scene takes minutes, so the sweep does not wait for them all:
`SeedChecks(plan)`, for a `with` block, checks every run in the plan's order in a thread of its own
(`runner.sweep.driver` starts it with the runs), far faster than the runs go, and the sender calls
`wait(index)` before it sends a batch, which returns once the runs up to `index` are checked and
raises the first refusal (or error) found at any run, so a refused seed stops the sweep at the next
batch sent, whatever its place (docs/how-to/dask.md). Nothing is kept per run: the thread keeps a
count of the runs checked, and the combinations' scenarios it loads are the plan's (`Plan.base`),
which the sender then finds loaded.
"""

from __future__ import annotations

import threading

from collide2d.runner import lanes
from collide2d.runner.sweep import matrix
from collide2d.runner.sweep.matrix import SweepError
from collide2d.runner.sweep.reseed import Reseeded, reseed

JOIN_S = 5.0  # seconds the end of a sweep waits for the check under way (one drawing or load)
WAIT_S = 0.5  # seconds between two looks of a sender waiting for a check (it sees Ctrl-C at once)


def check_run(plan, run) -> None:
    """Refuse `run` as its full load would (a located error), else return; its combination's
    scenario is then loaded in the plan (`Plan.base`)."""
    base = plan.base(run.combo)
    if run.seed is None or run.seed == plan.seeds[0]:
        return  # loaded and checked in full by plan.check
    try:
        reseed(base, run.seed)
    except Reseeded as exc:
        matrix.load_run(run.combo, run.seed, plan.limits)  # refuses it, at its node
        said = ", ".join(list(run.combo.shown) + [f"seed={run.seed}"])
        raise SweepError(f"{run.combo.path}: in the sweep run {said}: {exc}") from None


class SeedChecks:
    """Every run of `plan` checked in a thread of its own (see the module docstring)."""

    def __init__(self, plan):
        self.plan = plan
        self.checked = 0  # the runs checked, in the plan's order
        self._error: BaseException | None = None
        self._changed = threading.Condition()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._check, name="collide2d-seeds", daemon=True)

    def __enter__(self) -> SeedChecks:
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join(JOIN_S)

    def wait(self, index: int) -> None:
        """Return once the runs up to number `index` are checked; raise the refusal (or the
        error) found at any run as soon as there is one."""
        with self._changed:
            while self._error is None and self.checked <= index:
                self._changed.wait(WAIT_S)
            if self._error is not None:
                raise self._error

    def _check(self) -> None:
        try:
            # the seeds' drawings run their kernels in the lane of all of them (runner.lanes)
            with lanes.loads(len(self.plan)):
                for run in self.plan.runs():
                    if self._stop.is_set():
                        return
                    check_run(self.plan, run)
                    with self._changed:
                        self.checked = run.index + 1
                        self._changed.notify_all()
        except BaseException as exc:  # a refusal, or a bug: the sender raises it
            with self._changed:
                self._error = exc
                self._changed.notify_all()
