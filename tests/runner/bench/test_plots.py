"""runner.bench.plots: written with matplotlib, skipped without it."""

from __future__ import annotations

import sys
import warnings

import pytest

from collide2d.runner.bench import plots


def test_without_matplotlib_the_csv_and_markdown_still_come_out(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    rows = [{"part": "error", "scene": "s", "model": "exact", "run_time_s": 0.1}]
    assert plots.plots(rows, tmp_path) == []
    assert list(tmp_path.iterdir()) == []


def test_plots_are_written_with_matplotlib(tmp_path):
    pytest.importorskip("matplotlib")
    rows = [
        {"part": "scaling", "model": "stepped", "n": 50, "steps_per_s": 100.0},
        {"part": "scaling", "model": "stepped", "n": 500, "steps_per_s": 10.0},
        {"part": "error", "scene": "s", "model": "exact", "fps": 60, "substeps": 1,
         "run_time_s": 0.1, "run_time_min_s": 0.09, "run_time_max_s": 0.12, "long_s": 10.0,
         "error_long_px": 0.0, "pareto": "yes"},
        {"part": "error", "scene": "s", "model": "stepped", "fps": 60, "substeps": 16,
         "run_time_s": 0.01, "run_time_min_s": 0.01, "run_time_max_s": 0.01, "long_s": 10.0,
         "error_long_px": 3.0, "pareto": "yes"},
        {"part": "sensitivity", "scene": "s", "error_long_px": 1e-6},
    ]  # fmt: skip
    assert plots.plots(rows, tmp_path) == ["scaling.png", "runtime_vs_error.png"]
    assert (tmp_path / "runtime_vs_error.png").read_bytes()[:4] == b"\x89PNG"


def test_points_all_at_one_error_plot_without_a_warning(tmp_path):
    # a sweep of the exact model: every error at the floor, a y range of zero height
    pytest.importorskip("matplotlib")
    rows = [
        {"part": "error", "scene": "s", "model": "exact", "fps": fps, "substeps": 1,
         "run_time_s": 0.1 * fps, "long_s": 10.0, "error_long_px": 0.0, "pareto": "yes"}
        for fps in (10, 60)
    ]  # fmt: skip
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        assert plots.plots(rows, tmp_path) == ["runtime_vs_error.png"]
    # (a dependency's own deprecation notices are not ours to judge)
    shown = [str(w.message) for w in seen if not issubclass(w.category, DeprecationWarning)]
    assert shown == []
