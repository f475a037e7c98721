"""Objects from a table (`objects: {file: bodies.csv}` or `.npy`): the same bodies as a listed
scene, every refusal at its FILE:ROW:COLUMN, paths kept inside the scenario's folder, limits
checked before the table is parsed."""

from __future__ import annotations

import os

import numpy as np
import pytest

from collide2d.runner.cli import main
from collide2d.runner.limits import Limits
from collide2d.runner.scenario import ScenarioError, load

HEAD = """version: 1
name: table
world: {width: 200, height: 100, fps: 10}
model: MODEL
ticks: 3
output: {frames: none, gif: false, events: true}
"""

ROWS = [
    "id,shape,w,h,x,y,vx,vy,mass,color,name,static,fill",
    "0,box,10,10,0,0,10,0,2,red,left,false,true",
    "1,circle,6,6,50,20,-20,5,,#00ff00,,false,false",
    '2,box,4,8,100,50,0,0,,white,"wall, east",true,false',
    "3,box,10,10,150,80,5,-10,0.5,red,,false,false",
]

LISTED = """objects:
  - {shape: box, size: [10, 10], position: [0, 0], velocity: [10, 0], mass: 2, color: red,
     name: left, fill: true}
  - {shape: circle, diameter: 6, position: [50, 20], velocity: [-20, 5], color: '#00ff00'}
  - {shape: box, size: [4, 8], position: [100, 50], color: white, name: 'wall, east',
     static: true}
  - {shape: box, size: [10, 10], position: [150, 80], velocity: [5, -10], mass: 0.5, color: red}
"""


def write(folder, rows=ROWS, model="stepped", extra="", name="bodies.csv"):
    (folder / name).write_text("\n".join(rows) + "\n")
    path = folder / "scene.yaml"
    path.write_text(HEAD.replace("MODEL", model) + f"objects: {{file: {name}}}\n" + extra)
    return path


def same_bodies(a, b):
    for field in ("kind", "pos", "size", "vel", "mass", "static", "vert_start", "verts"):
        x, y = getattr(a, field), getattr(b, field)
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), field
    assert a.looks.color.tobytes() == b.looks.color.tobytes()
    assert a.looks.fill.tobytes() == b.looks.fill.tobytes()


@pytest.mark.parametrize("model", ["paper", "stepped", "exact"])
def test_a_csv_table_gives_the_bodies_of_the_listed_objects(tmp_path, model):
    gen = "generate:\n  - {count: 5, shape: box, size: 3, speed: 10, seed: 4, color: blue}\n"
    table = load(write(tmp_path, model=model, extra=gen))
    listed_path = tmp_path / "listed.yaml"
    listed_path.write_text(HEAD.replace("MODEL", model) + LISTED + gen)
    listed = load(listed_path)
    same_bodies(table.bodies, listed.bodies)
    assert table.palette.tobytes() == listed.palette.tobytes()
    assert table.names == listed.names
    assert table.names[:3] == ("left", None, "wall, east")


def test_an_npy_table_gives_the_same_bodies(tmp_path):
    csv_scene = load(write(tmp_path))
    rec = np.array(
        [
            (0, "box", 10, 10, 0, 0, 10, 0, 2.0, "red", "left", False, True),
            (1, "circle", 6, 6, 50, 20, -20, 5, np.nan, "#00ff00", "", False, False),
            (2, "box", 4, 8, 100, 50, 0, 0, np.nan, "white", "wall, east", True, False),
            (3, "box", 10, 10, 150, 80, 5, -10, 0.5, "red", "", False, False),
        ],
        dtype=[
            ("id", "i8"),
            ("shape", "U8"),
            ("w", "i4"),
            ("h", "i4"),
            ("x", "f8"),
            ("y", "f8"),
            ("vx", "f8"),
            ("vy", "f8"),
            ("mass", "U10"),
            ("color", "U10"),
            ("name", "U20"),
            ("static", "?"),
            ("fill", "?"),
        ],
    )
    rec["mass"] = ["2", "", "", "0.5"]
    np.save(tmp_path / "bodies.npy", rec)
    (tmp_path / "n.yaml").write_text(
        HEAD.replace("MODEL", "stepped") + "objects: {file: bodies.npy}\n"
    )
    same_bodies(load(tmp_path / "n.yaml").bodies, csv_scene.bodies)


def test_a_run_from_a_table_writes_the_events_of_the_listed_scene(tmp_path):
    write(tmp_path)
    head = HEAD.replace("MODEL", "exact").replace("ticks: 3", "ticks: 100")
    (tmp_path / "listed").mkdir()
    (tmp_path / "listed" / "scene.yaml").write_text(head + LISTED)
    (tmp_path / "scene.yaml").write_text(head + "objects: {file: bodies.csv}\n")
    for scene, out in (("scene.yaml", "a"), ("listed/scene.yaml", "b")):
        assert main(["run", str(tmp_path / scene), "--out", str(tmp_path / out), "--quiet"]) == 0
    a = (tmp_path / "a" / "table" / "events.jsonl").read_bytes()
    assert a and a == (tmp_path / "b" / "table" / "events.jsonl").read_bytes()


def refusal(tmp_path, rows, limits=None, **kw) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        load(write(tmp_path, rows, **kw), limits=limits)
    return info.value


@pytest.mark.parametrize(
    "row, column, fragment",
    [
        ("3,box,10,10,150,80,abc,-10,0.5,red,,false,false", "vx", "column vx: must be a number"),
        ("4,box,10,10,150,80,5,-10,0.5,red,,false,false", "id", "column id: must be 3"),
        ("3,star,10,10,150,80,5,-10,0.5,red,,false,false", "shape", "must be box or circle"),
        ("3,box,10,0,150,80,5,-10,0.5,red,,false,false", "h", "column h: must be a whole"),
        ("3,box,10,10,195,80,5,-10,0.5,red,,false,false", "x", "column x: the box [195, 205)"),
        ("3,box,10,10,150,80,5,-10,0.5,redd,,false,false", "color", "unknown colour 'redd'"),
        ("3,box,10,10,150,80,5,-10,0,red,,false,false", "mass", "column mass: must be from"),
        ("3,box,10,10,150,80,5,-10,1,red,,maybe,false", "static", "must be true or false"),
        ("3,box,10,10,150,80,5,-10,1,red,,true,false", "vx", "static, so it cannot move"),
        ("3,box,10,10,5,5,5,-10,1,red,,false,false", "x", "object 3 overlaps object 0"),
        ("3,box,10,10,150,80,5", "id", "row 4 has 7 fields; the header names 13"),
        ("3,circle,10,8,150,80,5,-10,1,red,,false,false", "h", "diameter and must be equal"),
    ],
)
def test_a_bad_cell_is_refused_at_its_row_and_column(tmp_path, row, column, fragment):
    err = refusal(tmp_path, ROWS[:4] + ["", row])  # a blank line is skipped, lines still count
    k = ROWS[0].split(",").index(column)
    col = len(",".join(row.split(",")[:k])) + (2 if k else 1)  # where field k starts
    assert (err.path, err.line, err.col) == (os.path.join(str(tmp_path), "bodies.csv"), 6, col)
    assert fragment in err.message


def test_the_first_bad_cell_in_row_order_is_the_one_reported(tmp_path):
    rows = ROWS[:2] + [
        "1,box,10,10,50,20,zz,5,,red,,false,false",
        "2,box,10,10,100,20,5,5,,bleu,,false,false",
        ROWS[4],
    ]
    err = refusal(tmp_path, rows)
    assert (err.line, "column vx" in err.message) == (3, True)


def test_paper_rules_hold_for_tables(tmp_path):
    rows = ROWS[:4] + ["3,box,10,10,150.5,80,5,-10,0.5,red,,false,false"]
    err = refusal(tmp_path, rows, model="paper")
    assert err.line == 5 and "whole number of pixels under the paper model" in err.message
    rows = ROWS[:4] + ["3,box,10,10,150,80,0.0000003,-10,0.5,red,,false,false"]
    err = refusal(tmp_path, rows, model="paper")
    assert err.line == 5 and "not a whole number of pixels per whole number" in err.message


def test_the_header_is_checked(tmp_path):
    err = refusal(tmp_path, ["id,shape,w,h,x,y,colour", "0,box,1,1,1,1,red"])
    assert (err.line, err.col) == (1, 18)
    assert "unknown column 'colour'; did you mean 'color'?" in err.message
    err = refusal(tmp_path, ["id,shape,w,x,y", "0,box,1,1,1"])
    assert "lacks the column(s) h" in err.message


@pytest.mark.parametrize(
    "given, fragment",
    [
        ("../bodies.csv", "outside the scenario's folder"),
        ("/etc/passwd.csv", "relative to the scenario's folder"),
        ("bodies.txt", "must be a .csv or .npy file"),
        ("link.csv", "outside the scenario's folder"),
        ("missing.csv", "cannot read the table"),
    ],
)
def test_a_table_must_lie_in_the_scenario_folder(tmp_path, given, fragment):
    inner = tmp_path / "inner"
    inner.mkdir()
    (tmp_path / "bodies.csv").write_text("\n".join(ROWS) + "\n")
    os.symlink(tmp_path / "bodies.csv", inner / "link.csv")
    path = inner / "scene.yaml"
    path.write_text(HEAD.replace("MODEL", "stepped") + f"objects: {{file: '{given}'}}\n")
    with pytest.raises(ScenarioError) as info:
        load(path)
    assert fragment in info.value.message
    if given != "missing.csv":  # at the `file` value in the scenario
        assert (info.value.path, info.value.line) == (str(path), 7)


def test_limits_are_checked_before_the_table_is_parsed(tmp_path):
    rows = ROWS[:1] + ["0,box,not parsed"] * 10
    err = refusal(tmp_path, rows, limits=Limits(max_objects=9))
    assert "has 10 rows, past the limit of 9 objects" in err.message
    err = refusal(tmp_path, rows, limits=Limits(max_file_bytes=100))
    assert "larger than the limit of 100 bytes" in err.message
    big = np.zeros(
        20,
        dtype=[("id", "i8"), ("shape", "U3"), ("w", "i8"), ("h", "i8"), ("x", "f8"), ("y", "f8")],
    )
    np.save(tmp_path / "t.npy", big)
    (tmp_path / "n.yaml").write_text(HEAD.replace("MODEL", "stepped") + "objects: {file: t.npy}\n")
    with pytest.raises(ScenarioError, match="has 20 rows, past the limit of 19"):
        load(tmp_path / "n.yaml", limits=Limits(max_objects=19))


def test_a_bad_table_exits_2_and_writes_nothing(tmp_path, capsys):
    write(tmp_path, ROWS[:4] + ["3,box,10,10,150,80,abc,-10,0.5,red,,false,false"])
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "scene.yaml"), "--out", str(out), "--quiet"]) == 2
    assert "bodies.csv:5:20: error: row 4, column vx: must be a number" in capsys.readouterr().err
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("distinct", [3, 20])  # compared column-wise, and past FEW_DISTINCT
def test_colours_keep_the_order_of_first_use(tmp_path, distinct):
    shades = [f"#{(37 * k) % 256:02x}{(91 * k) % 256:02x}{255 - k:02x}" for k in range(distinct)]
    order = [shades[(7 * r) % distinct] for r in range(40)]
    rows = ["id,shape,w,h,x,y,color"] + [f"{r},box,4,4,{r * 5},0,{c}" for r, c in enumerate(order)]
    scene = load(write(tmp_path, rows=rows))
    first_use = list(dict.fromkeys(order))
    expected = [[int(c[i : i + 2], 16) for i in (1, 3, 5)] for c in first_use]
    assert scene.palette[1 : 1 + len(expected)].tolist() == expected  # row 0: background
