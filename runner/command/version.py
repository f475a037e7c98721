"""The installed distribution's version, read from its metadata when first asked for.

`importlib.metadata` costs tens of milliseconds to import, which a run that never prints the
version does not pay. A source tree that is not installed says `0+unknown`. `collide2d.__version__`,
`collide2d --version` and the goldens' manifests (which collide2d blessed them) read it here.
"""

from __future__ import annotations

import functools


@functools.cache
def version() -> str:
    """The version of the installed `collide2d` distribution."""
    from importlib import metadata

    try:
        return metadata.version("collide2d")
    except metadata.PackageNotFoundError:  # pragma: no cover - a tree that is not installed
        return "0+unknown"
