"""Nothing changes without gravity (docs/scenario-format.md#gravity-restitution-and-friction):
every bundled scenario with `gravity: 0`, `restitution: 1` and `friction: 0` written out, for the
world and for every object and generate block, runs to the very bytes of the scenario without them
(events, final state, the golden frames), so no golden needs blessing again. The paper model takes
none of the keys, so its scenarios refuse them at their line.

The scenario's hash (`Scenario.text_sha256`, kept in a golden's manifest) is the hash of the file's
bytes: writing the defaults out edits the file, so the hash changes, as it does for any edit, and a
failing check would say the scenario was edited since bless; a check compares what runs, never the
hash, so it passes (docs/goldens.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from collide2d.runner.run import simulate
from collide2d.runner.scenario.load import ScenarioError, load

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = sorted((ROOT / "scenarios").glob("*.yaml"))
DEFAULTS = {"restitution": 1, "friction": 0}


def with_defaults(path: Path, folder: Path) -> Path:
    """A copy of the scenario at `path` with the defaults of gravity, restitution and friction
    written for the world, each listed object and each generate block."""
    doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    doc["world"] = {**doc.get("world", {}), "gravity": 0, **DEFAULTS}
    for key in ("objects", "generate"):
        items = doc.get(key, [])
        assert isinstance(items, list), "a table of objects would need the columns added"
        doc[key] = [{**item, **DEFAULTS} for item in items]
    out = folder / path.name
    out.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return out


def model_of(path: Path) -> str:
    model = yaml.safe_load(path.read_text(encoding="utf-8")).get("model", "paper")
    return model["kind"] if isinstance(model, dict) else model


def writes_physics(path: Path) -> bool:
    """Whether the scenario already gives gravity, restitution or friction (the gravity scenes)."""
    doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    items = [doc.get("world", {}), *doc.get("objects", []), *doc.get("generate", [])]
    return any(key in item for item in items for key in ("gravity", *DEFAULTS))


@pytest.mark.parametrize(
    "path",
    [p for p in SCENARIOS if model_of(p) != "paper" and not writes_physics(p)],
    ids=lambda p: p.stem,
)
def test_the_defaults_written_out_run_to_the_same_bytes(tmp_path, path):
    plain = load(path)
    written = load(with_defaults(path, tmp_path))
    assert written.world == plain.world and not written.world.has_gravity
    assert written.bodies.restitution.tolist() == [1.0] * plain.bodies.n
    assert written.text_sha256 != plain.text_sha256  # an edit of the file, as any other
    frames = plain.golden.frames
    a = simulate(plain, keep_frames=frames, log_events=True)
    b = simulate(written, keep_frames=frames, log_events=True)
    assert a.events.tobytes() == b.events.tobytes()
    assert a.final_pos.tobytes() == b.final_pos.tobytes()
    assert a.final_vel.tobytes() == b.final_vel.tobytes()
    assert sorted(a.frames) == sorted(b.frames) and len(a.frames) >= 1
    assert all(np.array_equal(a.frames[k], b.frames[k]) for k in a.frames)
    for key in ("kinetic_energy", "potential_energy", "total_energy"):
        assert a.summary[key] == b.summary[key]


@pytest.mark.parametrize(
    "path", [p for p in SCENARIOS if model_of(p) == "paper"], ids=lambda p: p.stem
)
def test_a_paper_scenario_refuses_them_at_their_line(tmp_path, path):
    with pytest.raises(ScenarioError) as info:
        load(with_defaults(path, tmp_path))
    lines = str(info.value).splitlines()
    assert "world.gravity cannot be given: the paper model has no gravity" in lines[0]
    assert all("cannot be given: the paper model has no" in line for line in lines)
