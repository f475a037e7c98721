"""`collide2d stress`: exit 1 and a report on a broken invariant, refusals, --quick end to end."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from collide2d.runner.command.main import main
from collide2d.runner.stress import cases
from collide2d.runner.stress.falling import every_scene

from .test_cases import FakeModel, set_nan

ROOT = Path(__file__).resolve().parents[3]


def test_stress_exits_1_and_reports_a_broken_invariant(tmp_path, monkeypatch, capsys):
    def fake_make(name, world, bodies, **options):
        return FakeModel(world, bodies, set_nan if name == "stepped" else None, at=1)

    monkeypatch.setattr(cases, "make_model", fake_make)
    argv = ["stress", "--quick", "--scene", "runaway", "--scene", "half_pixel", "--out", tmp_path]
    assert main([str(a) for a in argv]) == 1
    err = capsys.readouterr().err
    assert "half_pixel / stepped: tick 1: a position or velocity is not finite" in err
    data = json.loads((tmp_path / "stress" / "report.json").read_text())
    verdicts = {(c["scene"], c["model"]): c["verdict"] for c in data["cases"]}
    assert verdicts[("half_pixel", "stepped")] == "fail"
    assert verdicts[("half_pixel", "exact")] == "pass"
    assert data["ok"] is False
    assert "**half_pixel / stepped**: tick 1" in (tmp_path / "stress" / "report.md").read_text()
    assert sorted(p.name for p in (tmp_path / "stress").iterdir()) == ["report.json", "report.md"]


def test_stress_refuses_an_unknown_scene_and_a_linked_report_folder(tmp_path, capsys):
    assert main(["stress", "--scene", "nope", "--out", str(tmp_path)]) == 2
    assert "unknown scene 'nope'" in capsys.readouterr().err
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "stress").symlink_to(elsewhere)
    assert main(["stress", "--quick", "--out", str(tmp_path / "out")]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert list(elsewhere.iterdir()) == []


def test_collide2d_stress_quick_passes_and_reports_every_case(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "collide2d", "stress", "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr
    data = json.loads((tmp_path / "stress" / "report.json").read_text())
    assert data["mode"] == "quick" and data["ok"] is True
    cases = {(c["scene"], c["model"]): c for c in data["cases"]}
    expected = {(s.name, m) for s in every_scene(True) for m in s.models}
    assert set(cases) == expected
    for (scene, model), c in cases.items():
        assert c["verdict"] in ("pass", "stopped"), (scene, model, c["problems"])
        if c["verdict"] == "pass":
            assert c["ticks_run"] == c["ticks"]
            assert c["events"] >= 0 and c["run_time_s"] >= 0
            assert c["energy_drift"] is not None and c["penetration_px"] is not None
    for model in ("stepped", "exact"):
        assert cases[("runaway", model)]["verdict"] == "stopped"
    assert cases[("long_run", "paper")]["events"] > 0
    text = (tmp_path / "stress" / "report.md").read_text()
    assert "| scene | model | verdict | ticks run | events | energy drift |" in text
    assert f"Cases: {len(expected)}, failed: 0" in text
    assert "## Scenes" in text and "- `mass_ratios`: masses 1e-12 ... 1e12" in text
    assert data["scenes"].keys() == {s.name for s in every_scene(True)}
    assert "stress: " in proc.stdout and " 0 failed" in proc.stdout
