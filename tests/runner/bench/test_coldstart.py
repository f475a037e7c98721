"""runner.bench.targets.cold_start, the jit part: its scenes (the bundled scenarios, the bench's,
a grid of 10 to 5,000 bodies and 10 to 100,000 ticks), a lane run in a fresh process from an
empty kernel cache, `off` stopped once it cannot be the faster, and auto against the faster lane
in the rows, the headline and bench.md."""

from __future__ import annotations

from collide2d.engine import kernelstore
from collide2d.runner.bench import goals, report, targets
from collide2d.runner.bench.scenes import PROJECT_SCENARIOS


def quiet(_text):
    pass


def test_the_scenes_span_the_bundled_ones_and_the_grid(tmp_path):
    found = targets.scene_files(PROJECT_SCENARIOS, tmp_path, quick=False)
    names = [name for name, *_ in found]
    bundled = sorted(p.stem for p in PROJECT_SCENARIOS.glob("*.yaml"))
    assert names[-len(bundled) :] == bundled
    assert "two-body-chain" in names and any(n.startswith("standard-") for n in names)
    grid = [(n, ticks) for name, _, n, ticks in found if name.startswith("grid-")]
    assert min(n for n, _ in grid) == 10 and max(n for n, _ in grid) == 5_000
    assert min(t for _, t in grid) == 10 and max(t for _, t in grid) == 100_000
    for name, path, n, ticks in found:  # each file says what its row says
        text = path.read_text()
        if name.startswith(("grid-", "standard-")):
            assert f"name: {name}\n" in text and f"count: {n}," in text
            assert f"ticks: {ticks}\n" in text


def test_a_cold_run_of_a_small_scene_is_interpreted(tmp_path):
    path = PROJECT_SCENARIOS / "tunnelling_1fps.yaml"
    wall, kernels = targets.run_cold(path, "auto", tmp_path)
    assert kernels == "interpreted" and wall > 0
    assert targets.run_cold(path, "off", tmp_path, limit=1e-3) == (1e-3, "stopped")


def test_rows_compare_auto_with_the_faster_lane(monkeypatch, tmp_path):
    times = {"on": (10.0, "compiled"), "auto": (3.0, "interpreted"), "off": (2.5, "interpreted")}

    def fake(path, mode, tmp, limit=None):
        wall, lane = times[mode]
        return (limit, "stopped") if limit is not None and wall > limit else (wall, lane)

    monkeypatch.setattr(targets, "run_cold", fake)
    monkeypatch.setattr(targets, "compile_budgets", lambda quick, echo, tmp: [])
    rows = targets.cold_start(True, quiet)
    # on stopped once past both others (3.0 + 1 s): it cannot be the faster
    assert rows and all(r["ratio"] == 3.0 / 2.5 and r["met"] for r in rows)
    assert all(r["on_stopped"] and r["on_s"] == 4.0 and not r["off_stopped"] for r in rows)
    times["off"] = (99.0, "interpreted")  # stopped past 3 x auto + 2 s: on is the faster
    times["auto"] = (16.0, "interpreted, then compiled")
    rows = targets.cold_start(True, quiet)
    assert all(r["off_stopped"] and r["off_s"] == 50.0 and r["ratio"] == 1.6 for r in rows)
    assert not any(r["on_stopped"] for r in rows)
    assert not any(r["met"] for r in rows)
    what, figure, target, met = [h for h in report.headline(rows) if "--jit auto" in h[0]][0]
    assert (figure, target, met) == ("1.60", "<= 1.2", "✗")
    md = report.markdown(rows, "collide2d bench --part jit", 1.0)
    assert "## Compiled, interpreted or auto" in md and "> 50.0" in md


def test_each_model_is_held_to_its_compile_budget_or_to_none_where_the_wheel_ships_it(
    monkeypatch, tmp_path
):
    compiled = {"paper": 2.9, "stepped": 47.0, "exact": 0.0}
    stored = {"exact"}
    ran = []

    def fake(path, mode, tmp, limit=None):
        model = path.read_text().split("model: ")[1].split()[0]
        ran.append((model, mode))
        return 1.0, {"compile_time_s": compiled[model], "kernels": "compiled"}

    monkeypatch.setattr(targets, "_cold", fake)
    monkeypatch.setattr(kernelstore, "holds_model", lambda model: model in stored)
    rows = targets.compile_budgets(False, quiet, tmp_path)
    assert ran == [("paper", "on"), ("stepped", "on"), ("exact", "on")]
    got = {r["model"]: (r["value"], r["target"], r["met"]) for r in rows}
    assert got == {
        "paper": (2.9, f"<= {goals.COMPILE_BUDGET_S['paper']:g}", True),
        "stepped": (47.0, f"<= {goals.COMPILE_BUDGET_S['stepped']:g}", False),
        "exact": (0.0, "<= 0", True),
    }
    head = {what: (figure, target, met) for what, figure, target, met in report.headline(rows)}
    stepped = "stepped model compiling, standard scene, empty cache (nothing precompiled), s"
    assert head[stepped] == ("47.0", "<= 8", "✗")
    assert "## Compiling each model's kernels" in report.markdown(rows, "bench", 1.0)
    compiled["exact"] = 0.4  # a kernel the store lacks compiled: the wheel's promise missed
    assert [r["met"] for r in targets.compile_budgets(True, quiet, tmp_path)] == [False]
