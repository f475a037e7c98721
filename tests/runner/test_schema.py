"""The JSON Schema of the format: valid JSON Schema, agreeing with the loader."""

from __future__ import annotations

import json
import re

import pytest
import yaml
from scenario_text import BASE, DATA, objects

from collide2d.runner.scenario.load import TOP_KEYS, ScenarioError, loads
from collide2d.runner.scenario.schema import json_schema

# ----------------------------------------------------------------------------- JSON Schema


def _validate(doc, schema, root=None) -> list[str]:
    """Errors of doc against the subset of JSON Schema 2020-12 that json_schema() uses."""
    root = schema if root is None else root
    if schema is True:
        return []
    if schema is False:
        return ["false schema"]
    if "$ref" in schema:
        target = root
        for part in schema["$ref"].removeprefix("#/").split("/"):
            target = target[part]
        return _validate(doc, target, root)
    errors: list[str] = []
    kinds = {"object": dict, "array": list, "string": str, "boolean": bool}
    t = schema.get("type")
    if t in kinds and not isinstance(doc, kinds[t]):
        return [f"not {t}: {doc!r}"]
    if t == "integer" and (
        isinstance(doc, bool)
        or not (isinstance(doc, int) or (isinstance(doc, float) and doc.is_integer()))
    ):
        return [f"not integer: {doc!r}"]
    if t == "number" and (isinstance(doc, bool) or not isinstance(doc, (int, float))):
        return [f"not number: {doc!r}"]
    if "const" in schema and doc != schema["const"]:
        errors.append(f"not {schema['const']!r}")
    if "enum" in schema and doc not in schema["enum"]:
        errors.append(f"{doc!r} not in enum")
    if "minimum" in schema and doc < schema["minimum"]:
        errors.append("below minimum")
    if "maximum" in schema and doc > schema["maximum"]:
        errors.append("above maximum")
    if "exclusiveMinimum" in schema and doc <= schema["exclusiveMinimum"]:
        errors.append("not above exclusiveMinimum")
    if "pattern" in schema and not re.search(schema["pattern"], doc):
        errors.append("pattern")
    if "maxLength" in schema and len(doc) > schema["maxLength"]:
        errors.append("too long")
    if isinstance(doc, list):
        if len(doc) < schema.get("minItems", 0) or len(doc) > schema.get("maxItems", len(doc)):
            errors.append("item count")
        if "items" in schema:
            for item in doc:
                errors += _validate(item, schema["items"], root)
    if isinstance(doc, dict):
        props = schema.get("properties", {})
        for key in schema.get("required", []):
            if key not in doc:
                errors.append(f"missing {key}")
        for key, value in doc.items():
            if key in props:
                errors += _validate(value, props[key], root)
            elif schema.get("additionalProperties") is False:
                errors.append(f"extra key {key}")
    if "anyOf" in schema and not any(not _validate(doc, s, root) for s in schema["anyOf"]):
        errors.append("anyOf")
    if "oneOf" in schema and sum(not _validate(doc, s, root) for s in schema["oneOf"]) != 1:
        errors.append("oneOf")
    if "not" in schema and not _validate(doc, schema["not"], root):
        errors.append("not")
    return errors


def test_schema_is_json_and_describes_every_top_level_key():
    schema = json_schema()
    assert json.loads(json.dumps(schema)) == schema
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert set(schema["properties"]) == set(TOP_KEYS)
    assert schema["additionalProperties"] is False and schema["required"] == ["version"]


GOOD_DOCS = [
    "version: 1\n",
    (DATA / "spec_example.yaml").read_text(),
    BASE + "model: {kind: stepped, substeps: 4}\nduration: 2.5\noutput: {frames: {every: 3}}\n",
    BASE + "model: {kind: exact, max_events_per_tick: 5000000}\n",
    "version: 1\nworld: {gravity: 980}\nmodel: {kind: exact, rest_height: 0.5}\n",
    objects(
        "{shape: polygon, points: [[0, 0], [4, 0], [0, 4]], position: [1, 1], color: '#aabbcc',"
        " fill: true, name: tri}"
    ),
    BASE + "generate:\n  - {count: 3, shape: circle, diameter: 4, velocity: {min: [-1, -1], "
    "max: [1, 1]}, seed: 2}\n",
    # gravity, restitution and friction (docs/scenario-format.md#gravity-restitution-and-friction)
    "version: 1\nworld: {gravity: [0, 980], restitution: 0.5, friction: 0.1}\n"
    "model: {kind: stepped, iterations: 8, slop: 0.1, rest_speed: 2, sleep: true, "
    "sleep_after: 0.5}\nobjects:\n  - {shape: box, size: 5, position: [0, 0], restitution: 0.2, "
    "friction: 0.3}\ngenerate:\n  - {count: 3, shape: circle, diameter: 4, restitution: 0}\n",
    "version: 1\nworld: {gravity: 980}\nmodel: stepped\n",
    "version: 1\nworld: {gravity: 0, restitution: 1, friction: 0}\nmodel: exact\n",
]


@pytest.mark.parametrize("text", GOOD_DOCS)
def test_schema_accepts_good_documents(text):
    loads(text)  # the loader takes it
    assert _validate(yaml.safe_load(text), json_schema()) == []


@pytest.mark.parametrize(
    "text",
    [
        "version: 2\n",
        "name: x\n",
        BASE + "nmae: x\n",
        BASE + "ticks: 3\nduration: 1\n",
        objects("{shape: circle, size: 3, position: [0, 0]}"),
        objects("{shape: box, size: 3, position: [0, 0], velocty: [1, 0]}"),
        objects("{shape: box, size: 0, position: [0, 0]}"),
        objects("{shape: box, size: 3}"),
        BASE + "model: {kind: paper, geometry: exact}\n",
        BASE + "model: {kind: stepped, max_events_per_tick: 10}\n",
        BASE + "model: {kind: exact, max_events_per_tick: 0}\n",
        BASE + "golden: {color_threshold: 300}\n",
        BASE + "name: ../x\n",
        "version: 1\nworld: {gravity: [1, 2, 3]}\nmodel: stepped\n",
        "version: 1\nworld: {restitution: 2}\nmodel: stepped\n",
        "version: 1\nworld: {gravity: 2e12}\nmodel: stepped\n",
        objects("{shape: box, size: 3, position: [0, 0], friction: -1}"),
        objects("{shape: box, size: 3, position: [0, 0], restitution: 1.5}"),
        BASE + "model: {kind: exact, iterations: 3}\n",
        BASE + "model: {kind: paper, sleep: true}\n",
        BASE + "model: {kind: stepped, iterations: 0}\n",
        BASE + "model: {kind: stepped, sleep: 3}\n",
        BASE + "model: {kind: stepped, slop: -1}\n",
        BASE + "model: {kind: exact, rest_height: -1}\n",
        BASE + "model: {kind: exact, rest_height: 2e9}\n",
        BASE + "model: {kind: stepped, rest_height: 0.5}\n",
        BASE + "model: {kind: paper, rest_height: 0.5}\n",
        BASE + "generate:\n  - {count: 3, shape: box, size: 3, speed: 1, velocity: {min: [0, 0], "
        "max: [0, 0]}}\n",
    ],
)
def test_schema_refuses_bad_documents(text):
    with pytest.raises(ScenarioError):
        loads(text)
    assert _validate(yaml.safe_load(text), json_schema()) != []
