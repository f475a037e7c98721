"""collide2d: declarative 2D collision scenarios with golden-frame regression.

The public Python API (docs/reference/api.md):

- `load(path_or_dict)` reads and checks a scenario and returns a `Scenario`;
- `run(scenario, model=None, frames=None, events=True)` runs it and returns a `Result`: the final
  state as named columns, the events as records, the frames asked for as arrays, the summary;
- `check(scenarios, bless=False)` compares runs with their goldens (or writes them) and returns a
  `CheckResult`.

A refused scenario raises `ScenarioError` (`FILE:LINE:COL: error: MESSAGE`); a run a model stops
raises `RunStopped`; a run written to a folder that Ctrl-C stops raises `RunInterrupted` (a
KeyboardInterrupt) once the run so far is written; a plugin model that raises or breaks the model
protocol raises `ModelError` (`collide2d.engine.models.protocol`, which also defines the protocol,
`Model`). The `collide2d` command is a layer over these.

The distribution installs three import packages: `collide2d` (this one: the API, the version and
`python -m collide2d`), `collide2d.engine` (the simulation, from the repository's `engine/`
folder) and `collide2d.runner` (everything a user touches, from `runner/`). Importing `collide2d`
costs only the standard library: the runner is imported when a function is first called, the
names below from elsewhere when first asked for, and `__version__` is read from the installed
distribution when first asked for (importlib.metadata costs tens of ms to import, which a run
that never prints the version does not pay).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from collide2d.api import CheckResult, Result, ScenarioCheck, check, load, run

if TYPE_CHECKING:
    from collide2d.engine.models.protocol import Model, ModelError
    from collide2d.runner.run import RunInterrupted, RunStopped
    from collide2d.runner.scenario.limits import Limits
    from collide2d.runner.scenario.load import Scenario, ScenarioError

__all__ = [
    "CheckResult",
    "Limits",
    "Model",
    "ModelError",
    "Result",
    "RunInterrupted",
    "RunStopped",
    "Scenario",
    "ScenarioCheck",
    "ScenarioError",
    "__version__",
    "check",
    "load",
    "run",
]

# The names imported when first asked for: name -> the module holding it.
_LAZY = {
    "Limits": "collide2d.runner.scenario.limits",
    "Model": "collide2d.engine.models.protocol",
    "ModelError": "collide2d.engine.models.protocol",
    "RunInterrupted": "collide2d.runner.run",
    "RunStopped": "collide2d.runner.run",
    "Scenario": "collide2d.runner.scenario.load",
    "ScenarioError": "collide2d.runner.scenario.load",
}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name != "__version__":
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from collide2d.runner.command import version as distribution

    version = distribution.version()
    globals()["__version__"] = version
    return version
