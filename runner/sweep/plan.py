"""A sweep's runs, none kept loaded: the plan, its combinations checked in full before any run.

`check(scenarios, axes, seeds)` loads and checks in full, once, each distinct combination of a
scenario file and the swept values (a `matrix.Combo`), with the first seed, and returns a `Plan`.
What only a seed changes, the objects its `generate` blocks draw, is checked for every other seed
while the sweep runs, ahead of the runs and before each is sent (`runner.sweep.seedcheck`), so a
sweep of many seeds starts at once (docs/how-to/dask.md). Progress shows the combinations checked
on a terminal; the loaded scenarios are dropped as soon as they are checked, so memory does not
grow with the runs.

A `Plan` keeps the combinations only (their values, columns and sort keys), grouped by what comes
before the seed in a run's sort key (the scenario's name and the dotted keys' values) and sorted
within a group by the run settings. `Plan.runs()` yields the runs in their sorted order (groups in
order, then seeds, then the group's combinations), numbered from 0, without loading anything; the
same order and numbering as sorting every run's parameters, so rows come out the same. A worker
gets each run as (its combination's scenario, the seed) and draws its objects itself (`base`
loads a combination's scenario for the runs being sent or checked, a few at a time; the sweep
calls it from two threads, the sender's and the seed checks').
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass

from collide2d.runner import lanes
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.sweep import matrix
from collide2d.runner.sweep.matrix import RUN_KEYS, Combo, SweepError
from collide2d.runner.sweep.reseed import reseed

BASES_KEPT = 64  # combinations' scenarios kept loaded while their runs are sent


@dataclass(frozen=True)
class Run:
    """One run of the sweep: its number in the sorted order, its combination and seed."""

    index: int
    combo: Combo
    seed: int | None

    @property
    def params(self) -> dict:
        """Column -> value as shown (str): every swept key, the seed and the run settings."""
        if self.seed is None:
            return self.combo.params
        return {**self.combo.params, "seed": str(self.seed)}

    @property
    def sort_key(self) -> tuple:
        seed = (matrix.seed_key(self.seed),) if self.seed is not None else ()
        return self.combo.head + seed + self.combo.tail

    @property
    def ref_key(self) -> tuple:
        """What an `exact` run must share with this one to be its reference."""
        return (self.combo.ref, self.seed)


class Plan:
    """The checked runs of a sweep (see the module docstring)."""

    def __init__(self, groups: list[list[Combo]], axes, seeds, limits: Limits):
        self.groups = groups
        self.axes = axes
        self.seeds = seeds
        self.limits = limits
        self.columns = matrix.columns(axes, seeds)
        self.total = sum(len(g) for g in groups) * (len(seeds) if seeds else 1)
        self.with_exact = any(c.params["model"] == "exact" for g in groups for c in g)
        self.ref_sizes: dict[tuple, int] = {}
        for group in groups:
            for c in group:
                self.ref_sizes[c.ref] = self.ref_sizes.get(c.ref, 0) + 1
        self._bases: OrderedDict = OrderedDict()
        self._bases_lock = threading.Lock()

    def __len__(self) -> int:
        return self.total

    def runs(self):
        """Every run, in sorted order, numbered from 0."""
        index = 0
        for group in self.groups:
            for seed in self.seeds or (None,):
                for combo in group:
                    yield Run(index, combo, seed)
                    index += 1

    def base(self, combo: Combo):
        """The scenario of `combo` as loaded for its first seed (the workers draw each run's
        own); the last BASES_KEPT stay loaded. Safe to call from several threads."""
        with self._bases_lock:
            if combo in self._bases:
                self._bases.move_to_end(combo)
                return self._bases[combo]
        first = self.seeds[0] if self.seeds else None
        scenario = matrix.load_run(combo, first, self.limits)  # outside the lock: it takes a while
        with self._bases_lock:
            self._bases[combo] = scenario
            while len(self._bases) > BASES_KEPT:
                self._bases.popitem(last=False)
        return scenario

    def scenario(self, run: Run):
        """The scenario of one run (as its worker makes it)."""
        return scenario_of(self.base(run.combo), run.seed)


def scenario_of(base, seed):
    """A run's scenario from its combination's scenario and its seed (None: no seeds)."""
    return base if seed is None else reseed(base, seed)


def check(
    scenarios: list[str],
    axes: list,
    seeds: tuple[int, ...] | None,
    limits: Limits | None = None,
    progress=None,
) -> Plan:
    """Check every combination of the matrix in full (see the module docstring);
    `progress(total)` gives a bar of the combinations (runner.output.progress.Progress) or None."""
    limits = limits or Limits()
    count = matrix.check_axes(scenarios, axes, seeds)
    dotted = [a for a in axes if a.key not in RUN_KEYS]
    per_combo = len(seeds) if seeds else 1
    bar = progress(count // per_combo) if progress is not None else None
    seen: dict[tuple, Combo] = {}
    names: dict[str, str] = {}
    done = 0
    try:
        with lanes.loads(count // per_combo):
            for path in scenarios:
                first = seeds[0] if seeds else None
                for chosen, model in matrix.choices(path, axes, first, limits):
                    combo, scenario = matrix.combo_of(path, chosen, model, dotted, first, limits)
                    name = scenario.name
                    if name in names and names[name] != path:
                        raise SweepError(
                            f"{path} and {names[name]} are both named {name!r}; rows are "
                            "told apart by the scenario's name"
                        )
                    names[name] = path
                    seen.setdefault((combo.head, combo.tail), combo)  # else the same runs
                    done += 1
                    if bar is not None:
                        bar.update(done)
                    del scenario
    finally:
        if bar is not None:
            bar.close()
    groups: dict[tuple, list[Combo]] = {}
    for combo in seen.values():
        groups.setdefault(combo.head, []).append(combo)
    ordered = [sorted(groups[h], key=lambda c: c.tail) for h in sorted(groups)]
    return Plan(ordered, axes, seeds, limits)
