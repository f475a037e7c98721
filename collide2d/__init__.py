"""collide2d: declarative 2D collision scenarios with golden-frame regression.

The distribution installs three import packages: `collide2d` (this one: the version and
`python -m collide2d`), `collide2d.engine` (the simulation, from the repository's `engine/`
folder) and `collide2d.runner` (everything a user touches, from `runner/`).
"""

from importlib import metadata

try:
    __version__ = metadata.version("collide2d")
except metadata.PackageNotFoundError:  # pragma: no cover - run from a tree that is not installed
    __version__ = "0+unknown"
