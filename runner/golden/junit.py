"""JUnit XML of a golden check (`collide2d check --junit FILE`), for CI systems that show tests.

One `testsuite` named `collide2d.check` with one `testcase` per scenario (classname `goldens`,
name the scenario's name). A scenario that differs from its golden (or whose golden is missing or
unreadable) holds a `failure` whose message is its first divergence (`report.first_divergence`)
and whose text is the console story, why it changed included; a scenario an unexpected error or
a refusal kept from being checked holds an `error`. Every text passes through `escape.visible`, so
the file is valid XML 1.0 whatever a name, a file name or a golden holds (control characters are
spelled out: XML forbids them even as character references). The file is written atomically; the
same outcomes give the same bytes (no timestamps, no host names).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from collide2d.runner.golden.report import STATUS_FAILED, first_divergence
from collide2d.runner.output.escape import visible
from collide2d.runner.output.files import atomic_write_bytes

SUITE_NAME = "collide2d.check"
CLASS_NAME = "goldens"


def junit_xml(outcomes, errors=()) -> bytes:
    """The XML bytes. outcomes: report.Outcome; errors: (name, message) of scenarios not checked."""
    outcomes = sorted(outcomes, key=lambda o: o.name)
    errors = sorted(errors)
    suite = ET.Element(
        "testsuite",
        name=SUITE_NAME,
        tests=str(len(outcomes) + len(errors)),
        failures=str(sum(not o.ok for o in outcomes)),
        errors=str(len(errors)),
        skipped="0",
    )
    v = visible
    for o in outcomes:
        case = ET.SubElement(
            suite, "testcase", classname=CLASS_NAME, name=v(o.name), file=v(o.scenario)
        )
        if not o.ok:
            kind = "difference" if o.status == STATUS_FAILED else o.status
            failure = ET.SubElement(case, "failure", message=v(first_divergence(o)), type=v(kind))
            failure.text = v(o.message())
    for name, message in errors:
        case = ET.SubElement(suite, "testcase", classname=CLASS_NAME, name=v(name))
        first = message.splitlines()[0] if message else ""
        err = ET.SubElement(case, "error", message=v(first))
        err.text = v(message)
    ET.indent(suite)
    return ET.tostring(suite, encoding="utf-8", xml_declaration=True) + b"\n"


def write_junit(path, outcomes, errors=()) -> Path:
    """Write the JUnit XML of a check to `path`; returns it."""
    path = Path(path)
    atomic_write_bytes(path, junit_xml(outcomes, errors))
    return path
