"""Why a golden check failed: the scenario edited since bless, or the same scenario run by another
collide2d.

A golden's manifest keeps the SHA-256 of the scenario (its file's bytes, and its table's when its
objects come from one: `runner.scenario.table.with_table`) and the collide2d version that blessed it
(`serialize.manifest`). `cause(scenario, manifest)` compares them with the scenario checked now and
this collide2d, and returns a `Cause`: a `kind` for tools and a sentence for the reviewer, shown at
the top of the report, in the console text and in the JSON and JUnit outputs.
"""

from __future__ import annotations

from dataclasses import dataclass

from collide2d.runner.command import version

# The kinds of cause, for tools (summary.json, --format json).
SCENARIO_EDITED = "scenario-edited"
ENGINE_CHANGED = "engine-changed"
SAME_VERSION = "same-scenario-same-version"
UNKNOWN = "unknown"


@dataclass(frozen=True)
class Cause:
    kind: str
    text: str

    def as_dict(self) -> dict:
        return {"kind": self.kind, "text": self.text}


def cause(scenario, manifest: dict) -> Cause:
    """What changed between the bless recorded in `manifest` and the check of `scenario` now (by
    the collide2d installed)."""
    now = version.version()
    then_hash = manifest.get("scenario_sha256")
    then_version = manifest.get("collide2d_version")
    now_hash = getattr(scenario, "text_sha256", None)
    if then_hash is None or now_hash is None:
        return Cause(
            UNKNOWN,
            "unknown: the golden does not record the scenario it was blessed from "
            "(bless it again to record it)",
        )
    engine = (
        f"blessed by collide2d {then_version}, checked by collide2d {now}"
        if then_version is not None
        else f"blessed by an unrecorded collide2d version, checked by collide2d {now}"
    )
    if then_hash != now_hash:
        same = then_version == now
        return Cause(
            SCENARIO_EDITED,
            f"the scenario was edited since bless (SHA-256 {then_hash[:12]}… then, "
            f"{now_hash[:12]}… now)" + ("" if same else f"; also {engine}"),
        )
    if then_version != now:
        return Cause(ENGINE_CHANGED, f"same scenario, different engine: {engine}")
    return Cause(
        SAME_VERSION,
        f"same scenario, same collide2d version ({now}): the engine's code changed without "
        "a new version, or the run depends on the machine",
    )
