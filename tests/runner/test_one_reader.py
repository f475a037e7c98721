"""One object reader (runner.scenario.rules): the same objects written as a YAML list, as a long
list the fast lane takes, as a CSV table and as a .npy table give the same bodies, and the same
mistake in any of them is refused in the same words at the object's value or cell."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.runner.scenario import fastlane
from collide2d.runner.scenario.load import ScenarioError, load

N = 1000  # objects: as many as the fast lane takes by default
COLUMNS = ("id", "shape", "w", "h", "x", "y", "vx", "vy", "mass", "color", "name", "static", "fill")
HEAD = "version: 1\nname: one\nworld: {width: 800, height: 600, fps: 10}\nmodel: MODEL\nticks: 2\n"
FIRST_OBJECT_LINE = HEAD.count("\n") + 2  # after the head and the "objects:" line


def scene() -> list[dict]:
    """N objects of every kind a table can hold, apart, inside the 800 x 600 world."""
    out = []
    for k in range(N):
        o = {"shape": "box", "w": 6, "h": 4, "x": 20 * (k % 40), "y": 20 * (k // 40)}
        o.update(vx=0, vy=0, mass=None, color="white", name=None, static=False, fill=False)
        if k % 4 == 0:
            o.update(vx=k % 7 - 3, vy=2, mass=2.5, color="red", name=f"b{k}")
        elif k % 4 == 1:
            o.update(shape="circle", w=5, h=5, vx=1.5, vy=-0.5, color="lime")
        elif k % 4 == 2:
            o.update(w=8, h=8, static=True, color="teal", fill=True)
        else:
            o.update(w=3, h=9, vx=-4, mass=0.5, name=f"tall_{k}")
        out.append(o)
    return out


def num(v) -> str:
    return str(int(v)) if float(v).is_integer() else repr(float(v))


def yaml_item(o: dict) -> str:
    if o["shape"] == "circle":
        size = f"diameter: {num(o['w'])}"
    elif o["w"] == o["h"]:
        size = f"size: {num(o['w'])}"
    else:
        size = f"size: [{num(o['w'])}, {num(o['h'])}]"
    parts = [f"shape: {o['shape']}", size, f"position: [{num(o['x'])}, {num(o['y'])}]"]
    if o["vx"] or o["vy"]:
        parts.append(f"velocity: [{num(o['vx'])}, {num(o['vy'])}]")
    if o["mass"] is not None:
        parts.append(f"mass: {num(o['mass'])}")
    parts.append(f"color: '{o['color']}'" if o["color"].startswith("#") else f"color: {o['color']}")
    if o["name"] is not None:
        parts.append(f"name: {o['name']}")
    if o["static"]:
        parts.append("static: true")
    if o["fill"]:
        parts.append("fill: true")
    return "  - {" + ", ".join(parts) + "}"


def csv_row(k: int, o: dict) -> str:
    mass = "" if o["mass"] is None else num(o["mass"])
    values = [k, o["shape"], num(o["w"]), num(o["h"]), num(o["x"]), num(o["y"])]
    values += [num(o["vx"]), num(o["vy"]), mass, o["color"], o["name"] or ""]
    values += [str(o["static"]).lower(), str(o["fill"]).lower()]
    return ",".join(map(str, values))


def write(folder, objects: list[dict], model: str) -> dict:
    """The scene in each form: {form: scenario path}."""
    head = HEAD.replace("MODEL", model)
    (folder / "list.yaml").write_text(
        head + "objects:\n" + "\n".join(yaml_item(o) for o in objects) + "\n"
    )
    (folder / "t.csv").write_text(
        ",".join(COLUMNS) + "\n" + "\n".join(csv_row(k, o) for k, o in enumerate(objects)) + "\n"
    )
    numbers = ("id", "w", "h", "x", "y", "vx", "vy")
    text = {"shape": "U8", "mass": "U24", "color": "U16", "name": "U16"}
    dtype = [(c, "f8" if c in numbers else text.get(c, "?")) for c in COLUMNS]
    rec = np.zeros(len(objects), dtype)
    for k, o in enumerate(objects):
        rec[k] = (
            k, o["shape"], o["w"], o["h"], o["x"], o["y"], o["vx"], o["vy"],
            "" if o["mass"] is None else num(o["mass"]), o["color"], o["name"] or "",
            o["static"], o["fill"],
        )  # fmt: skip
    np.save(folder / "t.npy", rec)
    (folder / "csv.yaml").write_text(head + "objects: {file: t.csv}\n")
    (folder / "npy.yaml").write_text(head + "objects: {file: t.npy}\n")
    return {
        "list": folder / "list.yaml",
        "fast lane": folder / "list.yaml",
        "csv": folder / "csv.yaml",
        "npy": folder / "npy.yaml",
    }


@pytest.fixture
def lane(monkeypatch):
    """read(form, path): the scenario, or its ScenarioError, with the fast lane on only for the
    "fast lane" form; `taken` counts the lists the lane gave objects for."""
    taken = []
    real = fastlane.table

    def table(*args, **kw):
        result = real(*args, **kw)
        taken.append(result.n)
        return result

    monkeypatch.setattr(fastlane, "table", table)

    def read(form, path):
        monkeypatch.setattr(fastlane, "FAST_MIN_OBJECTS", 1000 if form == "fast lane" else 10**9)
        try:
            return load(path)
        except ScenarioError as err:
            return err

    read.taken = taken
    return read


@pytest.mark.parametrize("model", ["paper", "stepped"])
def test_the_same_objects_in_four_forms_give_the_same_bodies(tmp_path, lane, model):
    forms = write(tmp_path, scene(), model)
    read = {form: lane(form, path) for form, path in forms.items()}
    assert lane.taken == [N]  # the lane read the long list itself
    first = read["list"]
    assert first.bodies.n == N and first.bodies.static.sum() == N // 4
    for form, sc in read.items():
        for field in ("kind", "pos", "size", "vel", "mass", "static", "vert_start", "verts"):
            a, b = getattr(sc.bodies, field), getattr(first.bodies, field)
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), (form, field)
        assert sc.bodies.looks.color.tobytes() == first.bodies.looks.color.tobytes(), form
        assert sc.bodies.looks.fill.tobytes() == first.bodies.looks.fill.tobytes(), form
        assert sc.palette.tobytes() == first.palette.tobytes(), form
        assert sc.names == first.names, form


K = 516  # the object each mistake is made in: a box of [6, 4], after object 515, a box of [3, 9]


def _outside(o):
    o["x"] = 798  # 798 + 6 > 800


def _onto(o, before):
    o["x"], o["y"] = before["x"] + 1, before["y"] + 1


# (mistake, model, change of object K, YAML key whose value holds the fault (None: the object),
#  table column, the words every form says after its subject)
MISTAKES = [
    ("size below 1", "stepped", lambda o, b: o.update(w=0), "size: [", "w",
     "must be at least 1 px, not 0"),
    ("mass of 0", "stepped", lambda o, b: o.update(mass=0), "mass: ", "mass",
     "must be at least 1e-15, not 0"),
    ("speed past the bound", "stepped", lambda o, b: o.update(vx=2_000_000_000), "velocity: [",
     "vx", "must be at most 1000000000 px/s in size, not 2000000000"),
    ("fractional position under paper", "paper", lambda o, b: o.update(x=o["x"] + 0.5),
     "position: [", "x", "must be a whole number of pixels under the paper model, not 720.5"),
    ("overlap at the start", "stepped", lambda o, b: _onto(o, b), None, "x",
     "overlaps {other} at the start: boxes [701, 707) x [241, 245) and [700, 703) x [240, 249)"),
    ("outside the world", "stepped", lambda o, b: _outside(o), None, "x",
     "lies outside the world: its box [798, 804) x [240, 244) must fit in [0, 800) x [0, 600)"),
]  # fmt: skip


@pytest.mark.parametrize(
    "model, change, key, column, words", [m[1:] for m in MISTAKES], ids=[m[0] for m in MISTAKES]
)
def test_the_same_mistake_is_refused_in_the_same_words_at_its_object(
    tmp_path, lane, model, change, key, column, words
):
    objects = scene()
    change(objects[K], objects[K - 1])
    forms = write(tmp_path, objects, model)
    err = {form: lane(form, path) for form, path in forms.items()}
    assert all(isinstance(e, ScenarioError) for e in err.values()), err
    assert lane.taken == []  # the lane never decides: the general path refuses the file
    assert str(err["fast lane"]) == str(err["list"])

    # the YAML list: at the value's node (or the object's), after objects[K].FIELD
    line = FIRST_OBJECT_LINE + K
    written = forms["list"].read_text().split("\n")[line - 1]
    col = written.index(key) + len(key) + 1 if key else written.index("{") + 1
    assert (err["list"].line, err["list"].col) == (line, col)
    field = {"size: [": ".size w", "mass: ": ".mass", "velocity: [": ".velocity x"}
    name = objects[K]["name"]  # a named object is named beside its place
    subject = f"objects[{K}] ({name})" + field.get(key, ".position x" if key else "")
    other = None
    if "{other}" in words:
        subject = f"objects[{K}] ({name}, line {line})"
        before = f"{objects[K - 1]['name']}, " if objects[K - 1]["name"] else ""
        other = f"objects[{K - 1}] ({before}line {line - 1})"
    said = {"list": _after(err["list"].message, subject + " ", other)}

    # the tables: at the cell of row K + 1 and the column, after "row R, column C: "
    at = COLUMNS.index(column)
    row = forms["csv"].parent.joinpath("t.csv").read_text().split("\n")[K + 1]
    cell = len(",".join(row.split(",")[:at])) + 2
    assert (err["csv"].line, err["csv"].col) == (K + 2, cell)
    assert (err["npy"].line, err["npy"].col) == (K + 1, at + 1)
    for form in ("csv", "npy"):
        before = f"{objects[K - 1]['name']}, " if objects[K - 1]["name"] else ""
        other = f"object {K - 1} ({before}row {K})" if "{other}" in words else None
        said[form] = _after(err[form].message, f"row {K + 1} ({name}), column {column}: ", other)
    assert said == {"list": words, "csv": words, "npy": words}


def _after(message: str, subject: str, other: str | None) -> str:
    """The words of `message` after its `subject`, the object it names as {other}."""
    assert message.startswith(subject), (message, subject)
    words = message[len(subject) :]
    return words.replace(other, "{other}") if other else words


def test_a_table_judges_overlap_by_the_real_shapes_as_a_list_does(tmp_path, lane):
    """Circles whose boxes overlap but whose discs do not are legal under geometry exact, in a
    list and in a table alike."""
    head = HEAD.replace("MODEL", "exact")
    (tmp_path / "list.yaml").write_text(
        head + "objects:\n  - {shape: circle, diameter: 10, position: [0, 0]}\n"
        "  - {shape: circle, diameter: 10, position: [8, 8]}\n"
    )
    (tmp_path / "t.csv").write_text("id,shape,w,h,x,y\n0,circle,10,10,0,0\n1,circle,10,10,8,8\n")
    (tmp_path / "csv.yaml").write_text(head + "objects: {file: t.csv}\n")
    listed, table = lane("list", tmp_path / "list.yaml"), lane("csv", tmp_path / "csv.yaml")
    assert listed.bodies.pos.tobytes() == table.bodies.pos.tobytes()
    (tmp_path / "t.csv").write_text("id,shape,w,h,x,y\n0,circle,10,10,0,0\n1,circle,10,10,6,6\n")
    err = lane("csv", tmp_path / "csv.yaml")
    assert err.message.startswith("row 2, column x: overlaps object 0 (row 1) at the start: shapes")
