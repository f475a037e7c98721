"""collide2d: declarative 2D collision scenarios with golden-frame regression.

The distribution installs three import packages: `collide2d` (this one: the version and
`python -m collide2d`), `collide2d.engine` (the simulation, from the repository's `engine/`
folder) and `collide2d.runner` (everything a user touches, from `runner/`). `__version__` is read
from the installed distribution when first asked for (importlib.metadata costs tens of ms to
import, which a run that never prints the version does not pay).
"""

from __future__ import annotations


def __getattr__(name: str) -> str:
    if name != "__version__":
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib import metadata

    try:
        version = metadata.version("collide2d")
    except metadata.PackageNotFoundError:  # pragma: no cover - a tree that is not installed
        version = "0+unknown"
    globals()["__version__"] = version
    return version
