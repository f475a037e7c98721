"""Fixtures of the golden harness's tests: no CI in the environment, and a project tree in tmp."""

from __future__ import annotations

import pytest

from . import synthetic


@pytest.fixture(autouse=True)
def _no_ci(monkeypatch):
    """The harness's own tests write goldens into temporary trees, also when CI runs them."""
    monkeypatch.delenv("CI", raising=False)


@pytest.fixture
def tree(tmp_path, monkeypatch):
    """A project folder with scenarios/ holding one synthetic scenario `demo`; the current
    directory is the project (as when a user runs `collide2d check`)."""
    synthetic.write(tmp_path / "scenarios" / "demo.yaml", synthetic.spec())
    monkeypatch.chdir(tmp_path)
    return tmp_path
