"""Model plugins registered for one test: a distribution's metadata with entry points in the group
`collide2d.models`, on sys.path for the test only (as `pip install` of a plugin would leave it)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "boxflip"


@pytest.fixture
def register(tmp_path, monkeypatch):
    """register({name: "module:Class"}, source=None): the entry points, with the module text
    `source` (a dict module name -> text) written beside them; the example plugin's folder is on
    the path too."""
    from collide2d.engine import models

    made = []

    def register(points: dict, source: dict | None = None) -> Path:
        site = tmp_path / f"site{len(made)}"
        info = site / f"fake_plugin_{len(made)}-0.1.dist-info"
        info.mkdir(parents=True)
        (info / "METADATA").write_text(
            f"Metadata-Version: 2.1\nName: fake-plugin-{len(made)}\nVersion: 0.1\n"
        )
        lines = "".join(f"{k} = {v}\n" for k, v in points.items())
        (info / "entry_points.txt").write_text(f"[collide2d.models]\n{lines}")
        for module, text in (source or {}).items():
            (site / f"{module}.py").write_text(text)
        monkeypatch.syspath_prepend(str(site))
        made.append(site)
        models.plugins.cache_clear()
        return site

    monkeypatch.syspath_prepend(str(EXAMPLE))
    yield register
    models.plugins.cache_clear()
    for module in [m for m in sys.modules if m.startswith("badmodel")]:
        del sys.modules[module]
