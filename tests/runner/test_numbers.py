"""Every number in a scenario is in range or refused at its place (docs/limits.md#numbers), and
every run ends in finite figures.

Numbers of any length and YAML form are refused past `MAX_NUMBER_CHARS` characters at a cost
linear in the text (time and memory measured here, with libyaml's parser and with the pure Python
one); the short forms (hex, octal, binary, sexagesimal, underscores) still read; masses lie in
[MIN_MASS, MAX_MASS], so energy, momentum and 1/m stay finite, denormal masses are refused and
`-0.0` is read as `0.0`. A hypothesis test puts values past range into every numeric field of the
format: each document gives a located error at that value (or at what the value pushed out of
place) or a scenario whose run has a finite summary.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import time
import tracemalloc
import warnings

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from collide2d.engine.invariants import kinetic_energy, momentum
from collide2d.engine.world import Bodies
from collide2d.runner import run
from collide2d.runner.command.main import main
from collide2d.runner.run import RunStopped, simulate
from collide2d.runner.scenario import parse
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import (
    MAX_INTEGER,
    MAX_MASS,
    MAX_SEED,
    MAX_SPEED,
    MIN_MASS,
    ScenarioError,
    loads,
)


def at(text: str, needle: str) -> tuple[int, int]:
    """1-based (line, column) of the first `needle` in `text`."""
    index = text.index(needle)
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


def refused(text: str, **kw) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        loads(text, "n.yaml", **kw)
    return info.value


def with_mass(value: str) -> str:
    return (
        "version: 1\nworld: {width: 100, height: 80}\nmodel: stepped\nticks: 3\nobjects:\n"
        f"  - {{shape: box, size: 4, position: [1, 1], velocity: [5, 0], mass: {value}}}\n"
    )


def negative_zero(a) -> bool:
    """Whether any element of a is -0.0."""
    a = np.asarray(a, np.float64)
    return bool(np.any((a == 0) & np.signbit(a)))


def measured(fn):
    """(result or raised ScenarioError, seconds, peak traced bytes) of fn()."""
    tracemalloc.start()
    began = time.perf_counter()
    try:
        result = fn()
    except ScenarioError as err:
        result = err
    finally:
        seconds = time.perf_counter() - began
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return result, seconds, peak


# ----------------------------------------------------------------------------- long numbers

N = 60_000
LONG = {
    "decimal": "1" * N,
    "decimal of 4,301 digits": "9" * 4301,
    "negative": "-" + "1" * N,
    "hex": "0x" + "f" * N,
    "binary": "0b" + "1" * N,
    "octal": "0" + "7" * N,
    "sexagesimal": "1" + ":59" * (N // 3),
    "sexagesimal float": "1" + ":59" * (N // 3) + ".5",
    "underscores": "1_000" * (N // 5),
    "float digits": "1." + "5" * N,
    "float exponent": "1.0e+" + "9" * N,
    "exponent form": "1" * N + "e3",
    "tagged int": "!!int '" + "1" * N + "'",
    "tagged sexagesimal": "!!int '1" + ":59" * (N // 3) + "'",
    "tagged float": '!!float "' + "1" * N + '.5"',
}


@pytest.mark.parametrize("form", sorted(LONG))
def test_a_long_number_is_refused_at_its_place_in_linear_time(form):
    text = with_mass(LONG[form])
    err, seconds, peak = measured(lambda: loads(text, "n.yaml"))
    assert isinstance(err, ScenarioError)
    assert (err.line, err.col) == at(text, LONG[form])
    assert "characters long; a number in a scenario has at most 100" in err.message
    assert len(str(err)) < 200  # the number itself is not repeated
    # Quadratic conversion took about a second here; reading the text once takes milliseconds.
    assert seconds < 0.5
    assert peak < 4 * len(text) + 2**20


@pytest.mark.parametrize("form", ["decimal", "sexagesimal", "tagged sexagesimal", "exponent form"])
def test_the_pure_python_parser_refuses_long_numbers_too(monkeypatch, form):
    """Without libyaml the text is scanned in Python, more slowly but still once."""
    monkeypatch.setattr(parse, "_LOADER", yaml.SafeLoader)
    text = with_mass(LONG[form])
    err, seconds, peak = measured(lambda: loads(text, "n.yaml"))
    assert isinstance(err, ScenarioError) and "characters long" in err.message
    assert (err.line, err.col) == at(text, LONG[form])
    assert seconds < 2.0 and peak < 4 * len(text) + 2**20


@pytest.mark.parametrize("form", ["decimal", "sexagesimal", "hex"])
def test_the_cost_of_refusing_grows_linearly(form):
    """2,000,000 characters: quadratic work (int(), YAML 1.1's sexagesimal sum) would take minutes,
    and YAML's sexagesimal pattern would hold about 50 bytes per character."""
    value = {"decimal": "7" * 2_000_000, "sexagesimal": "1" + ":59" * 666_666}.get(
        form, "0x" + "a" * 2_000_000
    )
    text = with_mass(value)
    err, seconds, peak = measured(lambda: loads(text, "n.yaml"))
    assert isinstance(err, ScenarioError) and "characters long" in err.message
    assert seconds < 2.0
    assert peak < 4 * len(text) + 2**20


def test_long_numbers_are_refused_wherever_they_stand():
    long = "3" * 5000
    for text in (
        f"version: {long}\n",
        f"version: 1\ndescription: {long}\n",
        f"version: 1\nworld: {{background: [{long}, 0, 0]}}\n",
        f"version: 1\n? {long}\n: 1\n",
    ):
        err = refused(text)
        assert (err.line, err.col) == at(text, long)
        assert "quote it if it is text" in err.message


def test_long_text_is_text_and_costs_little():
    """A long plain scalar that is not a number (here one that starts as a sexagesimal number) is
    read as text without trying YAML's number patterns on it."""
    body = "1" + ":59" * 666_666 + " minutes"
    text = f"version: 1\ndescription: {body}\n"
    loads("version: 1\n")  # what a first reading loads once is not measured
    sc, seconds, peak = measured(lambda: loads(text, "n.yaml"))
    assert sc.description == body
    assert seconds < 2.0 and peak < 4 * len(text) + 2**20


def test_a_number_of_exactly_the_limit_reads():
    value = "0." + "0" * (parse.MAX_NUMBER_CHARS - 3) + "5"
    assert len(value) == parse.MAX_NUMBER_CHARS
    text = "version: 1\ngolden: {time_tolerance: %s}\n"
    assert loads(text % value).golden.time_tolerance == float(value) > 0
    err = refused(text % (value + "1"))
    assert "is 101 characters long" in err.message


# ----------------------------------------------------------------------------- short forms


@pytest.mark.parametrize(
    "written",
    ["64", "0x40", "0b1000000", "0100", "1:04", "6_4", "0x_4_0", "64.0", "6.4e1", "!!int '64'"],
)
def test_integers_in_every_yaml_form_read(written):
    sc = loads(f"version: 1\nworld: {{width: {written}}}\n")
    assert sc.world.width == 64 and isinstance(sc.world.width, int)


def test_sexagesimal_of_three_places_reads():
    assert loads("version: 1\nticks: 190:20:30\n").ticks == 190 * 3600 + 20 * 60 + 30


@pytest.mark.parametrize("written", ["0x_", "0b_", "-0b__", "+0x_"])
def test_an_integer_form_without_digits_is_text(written):
    """YAML 1.1 takes these for integers but they make none: text, never a traceback."""
    text = f"version: 1\nworld: {{width: {written}}}\n"
    err = refused(text)
    assert (err.line, err.col) == at(text, written)
    assert f"world.width must be a whole number of pixels, not the text '{written}'" in err.message
    assert loads(f"version: 1\ndescription: {written}\n").description == written


@pytest.mark.parametrize(
    ("field", "written", "fragment"),
    [
        ("golden: {max_diff_pixels: %s}", "1e300", f"at most {MAX_INTEGER}, not 1e300"),
        ("golden: {max_diff_pixels: %s}", "0x" + "f" * 98, f"at most {MAX_INTEGER}, not 0xfff"),
        ("output: {frames: {every: %s}}", str(2**63), f"at most {MAX_INTEGER}, not {2**63}"),
        ("ticks: %s", "-" + "9" * 30, f"at least 0, not -{'9' * 30}"),
        (
            "generate: [{count: 1, shape: box, size: 1, seed: %s}]",
            str(MAX_SEED + 1),
            f"generate[0].seed must be at most {MAX_SEED}",
        ),
    ],
)
def test_whole_numbers_past_their_bound_are_refused_at_their_place(field, written, fragment):
    text = "version: 1\n" + field % written + "\n"
    err = refused(text)
    assert (err.line, err.col) == at(text, written)
    assert fragment in err.message


def test_the_largest_seed_reads():
    text = f"version: 1\ngenerate: [{{count: 2, shape: box, size: 1, seed: {MAX_SEED}}}]\n"
    assert loads(text).bodies.n == 2


# ----------------------------------------------------------------------------- masses


@pytest.mark.parametrize("written", [repr(MIN_MASS), repr(MAX_MASS), "1e-12", "1e12", "0.5"])
def test_masses_inside_the_bounds_read(written):
    assert loads(with_mass(written)).bodies.mass.tolist() == [float(written)]


@pytest.mark.parametrize(
    ("written", "fragment"),
    [
        ("5e-324", "at least 1e-15, not 5e-324"),  # the smallest denormal
        ("2.2e-308", "at least 1e-15"),
        ("9.99e-16", "at least 1e-15"),
        ("0", "at least 1e-15, not 0"),
        ("-0.0", "at least 1e-15, not 0"),
        ("-1", "at least 1e-15, not -1"),
        ("1.0000001e15", "at most 1e+15"),
        ("1e308", "at most 1e+15, not 1e+308"),
        ("1e999", "must be a finite number, not 1e999"),
        (".nan", "must be a finite number"),
        ("-.inf", "must be a finite number"),
    ],
)
def test_masses_outside_the_bounds_are_refused_at_their_place(written, fragment):
    text = with_mass(written)
    err = refused(text)
    assert (err.line, err.col) == (6, text.splitlines()[5].index("mass: ") + len("mass: ") + 1)
    assert f"objects[0].mass must be {fragment}" in err.message or fragment in err.message


def test_the_bounds_keep_every_figure_finite_for_a_million_objects():
    """The worst start the bounds allow, and the fastest a light object could then move (all the
    energy on it): energy, momentum and inverse mass are finite and far from float64's end."""
    n = 1_000_000
    vel = np.tile([MAX_SPEED, -MAX_SPEED], (n, 1))
    bodies = Bodies.boxes(np.zeros((n, 2)), 1.0, vel, mass=np.full(n, MAX_MASS))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        energy = kinetic_energy(bodies.mass, bodies.static, bodies.vel)
        p = momentum(bodies.mass, bodies.static, bodies.vel)
        assert energy == pytest.approx(n * MAX_MASS * MAX_SPEED**2)
        assert p == pytest.approx((n * MAX_MASS * MAX_SPEED, -n * MAX_MASS * MAX_SPEED))
        fastest = math.sqrt(2 * energy / MIN_MASS)
        light = Bodies.boxes([[0, 0]], 1.0, [[fastest, fastest]], mass=[MIN_MASS])
        assert kinetic_energy(light.mass, light.static, light.vel) < 1e100
        assert abs(momentum(light.mass, light.static, light.vel)[0]) < 1e100
        assert light.inv_mass.tolist() == [1 / MIN_MASS]


@pytest.mark.parametrize("model", ["paper", "stepped", "exact"])
def test_extreme_masses_and_speeds_run_to_finite_figures(model):
    """The heaviest and the lightest objects at the largest speed, under every model, at a rate
    where the largest speed is a whole number of pixels per tick."""
    text = (
        "version: 1\nworld: {width: 2000, height: 2000, fps: 10000}\n"
        f"model: {model}\nticks: 3\nobjects:\n"
        f"  - {{shape: box, size: 4, position: [10, 10], velocity: [{MAX_SPEED:.0f}, 0], "
        f"mass: {MAX_MASS!r}}}\n"
        f"  - {{shape: box, size: 4, position: [100, 10], velocity: [0, -{MAX_SPEED:.0f}], "
        f"mass: {MIN_MASS!r}}}\n"
        "generate:\n  - {count: 50, shape: box, size: 3, seed: 4, mass: 1e15, "
        "velocity: {min: [-1e9, -1e9], max: [1e9, 1e9]}}\n"
    )
    sc = loads(text, "n.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            summary = simulate(sc, log_events=False).summary
        except RunStopped as stop:  # a runaway stopped with a message is fine, inf is not
            assert "not a finite number" not in str(stop)
            return
    check_summary(summary)
    assert summary["kinetic_energy"]["start"] > 1e33


def check_summary(summary: dict) -> None:
    """Every number in the summary is finite and none is -0.0; it is valid strict JSON."""
    figures = [summary["kinetic_energy"]["start"], summary["kinetic_energy"]["end"]]
    figures += summary["momentum"]["start"] + summary["momentum"]["end"]
    assert np.isfinite(figures).all() and not negative_zero(figures), summary
    json.dumps(summary, allow_nan=False)


def test_a_run_whose_model_breaks_the_bounds_stops_instead_of_writing_inf(monkeypatch):
    sc = loads(with_mass("2"))
    real = run.models.make

    class Diverging:
        """The real model, whose velocities turn infinite at the end of the run."""

        def __init__(self, *args, **kw):
            self.inner = real(*args, **kw)

        def __getattr__(self, name):
            return getattr(self.inner, name)

        def velocities(self):
            v = self.inner.velocities().copy()
            if self.inner.tick > 0:
                v[:] = np.inf
            return v

    monkeypatch.setattr(run.models, "make", Diverging)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(RunStopped, match="not a finite number"):
            simulate(sc, log_events=False)


# ----------------------------------------------------------------------------- negative zero


def test_negative_zero_is_read_as_zero_everywhere():
    text = (
        "version: 1\nmodel: stepped\nobjects:\n"
        "  - {shape: box, size: 4, position: [-0.0, -0.0], velocity: [-0.0, -0.0]}\n"
        "generate:\n"
        "  - {count: 5, shape: box, size: 2, seed: 1, velocity: {min: [-0.0, -0.0], "
        "max: [-0.0, -0.0]}}\n"
        "  - {count: 5, shape: box, size: 2, seed: 2, speed: {min: -0.0, max: -0.0}}\n"
        "  - {count: 5, shape: box, size: 2, seed: 3, speed: -0.0}\n"
        "golden: {time_tolerance: -0.0}\nduration: -0.0\n"
    )
    sc = loads(text)
    assert not negative_zero(sc.bodies.vel) and not negative_zero(sc.bodies.pos)
    assert not negative_zero(sc.golden.time_tolerance) and sc.ticks == 0
    check_summary(simulate(dataclasses.replace(sc, ticks=2), log_events=False).summary)
    paper = loads(text.replace("model: stepped", "model: paper"))
    assert not negative_zero(paper.bodies.vel)


# ----------------------------------------------------------------------------- every field

# A valid scenario in block style, one number per line, each written as @field=default@.
TEMPLATE = """\
version: @version=1@
world:
  width: @world.width=160@
  height: @world.height=120@
  fps: @world.fps=10@
  background:
    - @world.background.r=0@
    - @world.background.g=0@
    - @world.background.b=0@
@model
@ticks
objects:
  - shape: box
    size:
      - @objects.size.w=8@
      - @objects.size.h=6@
    position:
      - @objects.position.x=10@
      - @objects.position.y=10@
    velocity:
      - @objects.velocity.x=10@
      - @objects.velocity.y=0@
    mass: @objects.mass=2@
  - shape: circle
    diameter: @objects.diameter=6@
    position:
      - 60
      - 60
  - shape: polygon
    points:
      - - 0
        - 0
      - - @objects.points.x=5@
        - 0
      - - 0
        - @objects.points.y=5@
    position:
      - 100
      - 10
generate:
  - count: @generate.count=3@
    shape: box
    size: @generate.size=4@
    speed: @generate.speed=10@
    seed: @generate.seed=1@
  - count: 2
    shape: box
    size: 3
    speed:
      min: @generate.speed.min=0@
      max: @generate.speed.max=20@
  - count: 2
    shape: circle
    diameter: 3
    mass: @generate.mass=1@
    velocity:
      min:
        - @generate.velocity.min.x=-5@
        - @generate.velocity.min.y=-5@
      max:
        - @generate.velocity.max.x=5@
        - @generate.velocity.max.y=5@
output:
  frames:
    - @output.frames.item=0@
    - 4
golden:
  frames:
    every: @golden.frames.every=2@
  time_tolerance: @golden.time_tolerance=0.0@
  max_diff_pixels: @golden.max_diff_pixels=0@
  color_threshold: @golden.color_threshold=0@
"""
TICKS = "ticks: @ticks=4@"
DURATION = "duration: @duration=0.4@"
STEPPED = "model:\n  kind: stepped\n  substeps: @model.substeps=2@"
EXACT = "model:\n  kind: exact\n  max_events_per_tick: @model.max_events_per_tick=10000@"
FIELD = re.compile(r"@([a-z._]+)=([^@]*)@")
FIELDS = sorted(set(FIELD.findall(TEMPLATE + TICKS + DURATION + STEPPED + EXACT)))
NAMES = [name for name, _ in FIELDS]

# Errors that a value may cause away from its own line: objects pushed out of the world or into
# each other, boxes that no longer fit, frames past a shorter run or too many for a longer one,
# range ends out of order, a polygon point that leaves the polygon without area (under `exact`).
ELSEWHERE = (
    "a polygon must be convex with some area",
    "lies outside the world",
    "overlaps",
    "cannot place",
    "past the last frame",
    "frames, past the limit of",
    "is more than max",
)


def render(
    values: dict[str, str], duration: bool, exact: bool
) -> tuple[str, dict[str, tuple[int, int]]]:
    """The document with `values` written in, and the 1-based (line, column) of every field:
    with `duration` or `ticks`, under the exact model or the stepped one."""
    text = TEMPLATE.replace("@ticks", DURATION if duration else TICKS)
    text = text.replace("@model", EXACT if exact else STEPPED)
    places = {}
    out = []
    for number, line in enumerate(text.splitlines(), 1):
        for name, default in FIELD.findall(line):
            places[name] = (number, line.index("@") + 1)
            line = line.replace(f"@{name}={default}@", values.get(name, default))
        out.append(line)
    return "\n".join(out) + "\n", places


INTEGERS = st.one_of(
    st.integers(-100, 100),
    st.integers(-(2**70), 2**70),
    st.integers(-(10**120), 10**120),
    st.sampled_from([2**53, 2**63 - 1, 2**63, 2**64 - 1, 2**64, 10**99, 16385, 10**6 + 1]),
)


def int_text(n: int, form: str) -> str:
    sign = "-" if n < 0 else ""
    a = abs(n)
    if form == "hex":
        return f"{sign}0x{a:x}"
    if form == "binary":
        return f"{sign}0b{a:b}"
    if form == "octal":
        return f"{sign}0{a:o}"
    if form == "underscores":
        return f"{n:_}"
    if form == "sexagesimal" and a >= 60:
        places = []
        while a:
            a, r = divmod(a, 60)
            places.append(str(r))
        return sign + ":".join(reversed(places))
    if form == "float":
        return f"{n}.0"
    return str(n)


FORMS = ("decimal", "hex", "binary", "octal", "underscores", "sexagesimal", "float")


def float_text(x: float) -> str:
    if math.isnan(x):
        return ".nan"
    if math.isinf(x):
        return ".inf" if x > 0 else "-.inf"
    return repr(x)


SPECIAL = (
    "1e999",
    "-1e999",
    "-0.0",
    "-0",
    "5e-324",
    "-5e-324",
    "2.2250738585072014e-308",
    "1e308",
    "1.7976931348623157e308",
    "1e-15",
    "1e15",
    "1e9",
    "1000000001",
    "0x_",
    "1:30",
    "190:20:30",
    "1_000",
    "0o17",
    "~",
    "true",
    "'5'",
    "[1, 2]",
    "{a: 1}",
    "9" * 4301,
    "1" + ":30" * 3000,
    "0x" + "f" * 20_000,
)
values_past_range = st.one_of(
    st.integers(0, 200).map(str),
    st.floats(0, 1000).map(repr),
    st.builds(int_text, INTEGERS, st.sampled_from(FORMS)),
    st.floats(allow_nan=True, allow_infinity=True).map(float_text),
    st.sampled_from(SPECIAL),
    st.integers(parse.MAX_NUMBER_CHARS - 2, 70_000).map(lambda k: "8" * k),
)
LIMITS = Limits(max_objects=5_000, max_ticks=10**6, max_frames=10_000)


@st.composite
def documents(draw):
    """The template with one or two fields holding values past range (`ticks` or `duration`)."""
    names = {draw(st.sampled_from(NAMES)), draw(st.sampled_from(NAMES))}
    duration = draw(st.booleans())
    names.discard("ticks" if duration else "duration")
    exact = "model.max_events_per_tick" in names or (
        "model.substeps" not in names and draw(st.booleans())
    )
    names.discard("model.substeps" if exact else "model.max_events_per_tick")
    values = {name: draw(values_past_range) for name in sorted(names)}
    text, places = render(values, duration, exact)
    return text, {places[name] for name in values}


def test_the_template_is_valid_and_names_every_numeric_field():
    for duration in (False, True):
        for exact in (False, True):
            text, places = render({}, duration, exact)
            assert "@" not in text and len(places) == len(NAMES) - 2
            sc = loads(text, "n.yaml", limits=LIMITS)
            assert sc.bodies.n == 10 and sc.ticks == 4
            assert sc.model == ("exact" if exact else "stepped")
    assert (
        len(NAMES) == 37
        and "model.max_events_per_tick" in NAMES
        and "golden.color_threshold" in NAMES
    )


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(documents())
def test_every_numeric_field_is_in_range_or_refused_at_its_place(doc):
    text, changed = doc
    try:
        sc = loads(text, "n.yaml", limits=LIMITS)
    except ScenarioError as err:
        found = getattr(err, "errors", [err])  # every error of the file, in line order
        for one in found:
            assert str(one).startswith(f"n.yaml:{one.line}:{one.col}: error: ")
            assert len(str(one)) < 500
        here = any(
            one.line == line and one.col >= col for one in found for line, col in changed
        )  # in the value
        assert here or any(f in one.message for one in found for f in ELSEWHERE), str(err)
        event("refused at the value" if here else "refused elsewhere")
        return
    b = sc.bodies
    movable = ~b.static
    assert np.isfinite(b.pos).all() and np.isfinite(b.vel).all() and np.isfinite(b.size).all()
    assert np.all((b.mass[movable] >= MIN_MASS) & (b.mass[movable] <= MAX_MASS))
    assert np.all(np.abs(b.vel) <= MAX_SPEED)
    assert not negative_zero(b.pos) and not negative_zero(b.vel)
    assert math.isfinite(sc.golden.time_tolerance) and sc.golden.time_tolerance >= 0
    for whole in (sc.ticks, sc.world.fps, sc.substeps, sc.golden.max_diff_pixels, *sc.palette.flat):
        assert 0 <= int(whole) <= MAX_INTEGER
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            result = simulate(dataclasses.replace(sc, ticks=min(sc.ticks, 3)), log_events=False)
        except RunStopped as stop:  # a runaway stopped with a message: never inf or nan
            assert "not a finite number" not in str(stop)
            event("stopped as a runaway")
            return
    check_summary(result.summary)
    event("ran")


# ----------------------------------------------------------------------------- the CLI


def test_the_cli_refuses_a_long_number_with_exit_2_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "long.yaml"
    path.write_text(with_mass("1" * 60_000))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:6:")
    assert "characters long" in err and "Traceback" not in err
    assert not out.exists()


def test_the_cli_writes_a_finite_summary_at_the_bounds(tmp_path, capsys):
    path = tmp_path / "heavy.yaml"
    path.write_text(
        "version: 1\nworld: {width: 2000, height: 2000, fps: 10000}\n"
        "model: {kind: stepped, substeps: 100}\nticks: 3\nobjects:\n"
        "  - {shape: box, size: 4, position: [1, 1], velocity: [1e9, -1e9], mass: 1e15}\n"
    )
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet", "--no-gif"]) == 0
    capsys.readouterr()
    text = (out / "heavy" / "summary.json").read_text()

    def refuse(word):
        raise AssertionError(f"{word} in summary.json")

    summary = json.loads(text, parse_constant=refuse)
    assert summary["kinetic_energy"]["start"] == pytest.approx(MAX_MASS * MAX_SPEED**2)
    check_summary(summary)


def test_a_subnormal_speed_in_one_cell_with_a_circle_runs_without_a_numpy_warning():
    # found by the test above: in a world of one grid cell the exact model predicts every pair, and
    # a subnormal speed gives a contact interval of inf - inf; interpreted, nan as compiled
    text = """version: 1
world: {width: 160, height: 120, fps: 10}
model: {kind: exact}
ticks: 4
objects:
  - {shape: box, size: [8, 6], position: [10, 10], velocity: [1.1125369292536007e-308, 0], mass: 2}
  - {shape: circle, diameter: 6, position: [60, 60]}
  - {shape: polygon, points: [[0, 0], [5, 0], [0, 5]], position: [100, 10]}
generate:
  - {count: 3, shape: box, size: 4, speed: 10, seed: 1}
  - {count: 2, shape: box, size: 3, speed: {min: 0, max: 20}}
  - {count: 2, shape: circle, diameter: 3, mass: 1, velocity: {min: [-5, -5], max: [5, 5]}}
"""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = simulate(loads(text, "n.yaml"), log_events=False)
    check_summary(result.summary)
