"""runner.bench.skips: each skip measured with and without it."""

from __future__ import annotations

from collide2d.runner.bench import skips


def test_quick_skips_measure_each_skip(tmp_path):
    rows = skips.skips(True, lambda s: None)
    names = [r["note"] for r in rows]
    assert "no rasterising when no frame is asked for" in names
    assert "erase only what moved" in names
    assert "exact re-predicts only what an event touched" in names
    assert any("between static objects" in n for n in names)
    assert all(r["with_s"] > 0 and r["without_s"] > 0 for r in rows)
