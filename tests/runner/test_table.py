"""Objects from a table (`objects: {file: bodies.csv}` or `.npy`): the same bodies as a listed
scene, every refusal at its FILE:ROW:COLUMN, paths kept inside the scenario's folder, limits
checked before the table is parsed."""

from __future__ import annotations

import os
import threading
import time
import tracemalloc

import numpy as np
import pytest

from collide2d.runner.command.main import main
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import ScenarioError, load

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
        ("3,box,10,0,150,80,5,-10,0.5,red,,false,false", "h", "column h: must be at least 1 px"),
        ("3,box,10,10,195,80,5,-10,0.5,red,,false,false", "x", "x: lies outside the world"),
        ("3,box,10,10,150,80,5,-10,0.5,redd,,false,false", "color", "unknown colour 'redd'"),
        ("3,box,10,10,150,80,5,-10,0,red,,false,false", "mass", "mass: must be at least 1e-15"),
        ("3,box,10,10,150,80,5,-10,1,red,,maybe,false", "static", "must be true or false"),
        ("3,box,10,10,150,80,5,-10,1,red,,true,false", "vx", "static, so it cannot move"),
        ("3,box,10,10,5,5,5,-10,1,red,,false,false", "x", "x: overlaps object 0 (left, row 1)"),
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


# --- hostile tables: a located error or a correct read, never exit 3, never a cut cell ---------


def run_validate(tmp_path, capsys, content: bytes, name="bodies.csv"):
    """(exit status, stderr) of `collide2d validate` on a scene whose table holds `content`."""
    (tmp_path / name).write_bytes(content)
    path = tmp_path / "scene.yaml"
    path.write_text(HEAD.replace("MODEL", "stepped") + f"objects: {{file: {name}}}\n")
    capsys.readouterr()
    status = main(["validate", str(path)])
    return status, capsys.readouterr().err


def test_a_table_with_a_header_alone_is_a_scene_of_no_objects(tmp_path, capsys):
    csv_status, err = run_validate(tmp_path, capsys, ROWS[0].encode() + b"\n")
    assert (csv_status, err) == (0, "")
    empty = np.zeros(0, dtype=[(c, "f8") for c in ("id", "w", "h", "x", "y")] + [("shape", "U3")])
    np.save(tmp_path / "none.npy", empty)
    status, err = run_validate(tmp_path, capsys, (tmp_path / "none.npy").read_bytes(), "t.npy")
    assert (status, err) == (0, "")
    assert load(tmp_path / "scene.yaml").bodies.n == 0


def test_lines_ending_in_cr_alone_read_as_lines(tmp_path):
    lf = load(write(tmp_path))
    (tmp_path / "bodies.csv").write_bytes(("\r".join(ROWS) + "\r").encode())
    cr = load(tmp_path / "scene.yaml")
    same_bodies(cr.bodies, lf.bodies)
    assert cr.names == lf.names
    bad = ROWS[:4] + ["3,box,10,10,150,80,abc,-10,0.5,red,,false,false"]
    (tmp_path / "bodies.csv").write_bytes(("\r".join(bad) + "\r").encode())
    with pytest.raises(ScenarioError) as info:
        load(tmp_path / "scene.yaml")
    assert (info.value.line, info.value.col) == (5, 20)  # the line an editor shows


@pytest.mark.parametrize(
    "cell, line, fragment",
    [
        ("x" * 101, 2, "column name: the cell holds more than 100 characters"),
        ("x" * 200_000, 2, "column name: the cell holds more than 100 characters"),  # past csv's
        ('"' + "x" * 200_000 + '"', 2, "column name: the cell holds more than 100 characters"),
        ("  " + "x" * 100, 2, "column name: the cell holds more than 100 characters"),
    ],
)
def test_a_text_cell_past_its_bound_is_refused_not_cut(tmp_path, capsys, cell, line, fragment):
    rows = ["id,shape,w,h,x,y,name", f"0,box,2,2,0,0,{cell}", "1,box,2,2,10,0,zz"]
    status, err = run_validate(tmp_path, capsys, ("\n".join(rows) + "\n").encode())
    assert status == 2
    assert err == f"{tmp_path / 'bodies.csv'}:{line}:15: error: row 1, {fragment}\n"


def test_a_long_cell_does_not_hide_a_bad_cell_after_it(tmp_path, capsys):
    """The bad cell is found again with the csv module, whose field limit (131,072 characters)
    a long quoted name passes."""
    rows = [
        "id,shape,w,h,x,y,color",
        f'0,box,2,2,0,0,"{"white" + " " * 200_000}"',
        "1,box,2,2,10,0,white",
        "2,box,2,2,1_0,0,white",
    ]
    status, err = run_validate(tmp_path, capsys, ("\n".join(rows) + "\n").encode())
    assert (status, err) == (
        2,
        f"{tmp_path / 'bodies.csv'}:4:11: error: row 3, column x: must be a number, not '1_0'\n",
    )


@pytest.mark.parametrize("number", ["1_0", "１０", "0x10", "1d5", "nan(1)", "- 1", "1e", "."])
def test_a_number_numpy_does_not_read_is_refused_at_its_cell(tmp_path, capsys, number):
    rows = ["id,shape,w,h,x,y", "0,box,2,2,0,0", f"1,box,2,2,{number},0"]
    status, err = run_validate(tmp_path, capsys, ("\n".join(rows) + "\n").encode())
    assert status == 2
    assert err == (
        f"{tmp_path / 'bodies.csv'}:3:11: error: row 2, column x: must be a number, not "
        f"{number!r}\n"
    )


def test_two_rows_of_one_name_are_refused_at_the_second(tmp_path, capsys):
    rows = ["id,shape,w,h,x,y,name", "0,box,2,2,0,0,a", "1,box,2,2,10,0,b", "2,box,2,2,20,0, a"]
    status, err = run_validate(tmp_path, capsys, ("\n".join(rows) + "\n").encode())
    assert status == 2
    assert err == (
        f"{tmp_path / 'bodies.csv'}:4:16: error: row 3, column name: 'a' is taken, like object 0 "
        "(row 1 of the table); names must differ, they name the objects in events.jsonl and "
        "final.csv\n"
    )
    rec = np.zeros(
        2, dtype=[(c, "f8") for c in ("id", "w", "h", "x", "y")] + [("shape", "U3"), ("name", "S4")]
    )
    rec["id"], rec["x"], rec["w"], rec["h"], rec["shape"], rec["name"] = (
        [0, 1],
        [0, 10],
        2,
        2,
        "box",
        b"b",
    )
    np.save(tmp_path / "dup.npy", rec)
    status, err = run_validate(tmp_path, capsys, (tmp_path / "dup.npy").read_bytes(), "t.npy")
    assert status == 2 and "t.npy:2:7: error: row 2, column name: 'b' is taken" in err


def test_values_in_messages_read_as_written(tmp_path, capsys):
    for column, value, said in (
        ("mass", -1.5, "must be at least 1e-15, not -1.5"),
        ("static", np.nan, "must be true or false, not nan"),
        ("fill", 2.0, "must be true or false, not 2"),
    ):
        numbers = ("id", "w", "h", "x", "y", column)
        rec = np.zeros(1, dtype=[(c, "f8") for c in numbers] + [("shape", "U3")])
        rec["w"], rec["h"], rec["shape"], rec[column] = 2, 2, "box", value
        np.save(tmp_path / "t.npy", rec)
        status, err = run_validate(tmp_path, capsys, (tmp_path / "t.npy").read_bytes(), "t.npy")
        assert (status, err) == (
            2,
            f"{tmp_path / 't.npy'}:1:6: error: row 1, column {column}: {said}\n",
        )


def test_an_npy_header_claiming_more_rows_than_the_file_holds_is_refused_unallocated(
    tmp_path, capsys
):
    """The header's claim (100,000 rows of 804 bytes, 80 MB) is held against the file's size
    before any array is made."""
    rec = np.zeros(
        1,
        dtype=[(c, "f8") for c in ("id", "w", "h", "x", "y")] + [("shape", "U3"), ("name", "U187")],
    )
    np.save(tmp_path / "t.npy", rec)
    raw = (tmp_path / "t.npy").read_bytes()
    raw = raw.replace(b"(1,)", b"(100000,)", 1)
    run_validate(tmp_path, capsys, raw, "t.npy")  # kernels and modules loaded once
    tracemalloc.start()
    try:
        status, err = run_validate(tmp_path, capsys, raw, "t.npy")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert status == 2
    assert "t.npy:1:1: error: not a whole .npy file: its header claims 100,000 row(s)" in err
    assert peak < 20 * 2**20, peak


def test_a_table_or_scenario_that_is_not_a_regular_file_is_refused_at_once(tmp_path, capsys):
    """A FIFO is refused before it is opened for a blocking read (a writer opening it after a
    while lets a waiting reader go, so this test cannot hang)."""
    fifo = tmp_path / "bodies.csv"
    os.mkfifo(fifo)
    scene = tmp_path / "scene.yaml"
    scene.write_text(HEAD.replace("MODEL", "stepped") + "objects: {file: bodies.csv}\n")
    os.mkfifo(tmp_path / "piped.yaml")

    def release(path):
        time.sleep(5)
        try:
            os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:
            pass  # no reader waits: nothing to release

    for path, said in ((scene, f"{fifo}:1:1"), (tmp_path / "piped.yaml", None)):
        waiting = fifo if said else tmp_path / "piped.yaml"
        threading.Thread(target=release, args=(waiting,), daemon=True).start()
        capsys.readouterr()
        began = time.monotonic()
        assert main(["validate", str(path)]) == 2
        assert time.monotonic() - began < 3
        where = said or f"{path}:1:1"
        assert capsys.readouterr().err == (
            f"{where}: error: cannot read the {'table' if said else 'file'}: it is a FIFO "
            "(named pipe), not a regular file\n"
        )


@pytest.mark.parametrize(
    "rows, line, col",
    [
        (['0,box,2,2,0,0,"abc', "1,box,2,2,10,0,x"], 2, 15),  # read whole, a row taken for a name
        (["0,box,2,2,0,0,x", '1,box,2,2,10,"0,y', "2,box,2,2,20,0,z"], 3, 14),
    ],
)
def test_a_quote_never_closed_is_refused_where_it_opens(tmp_path, capsys, rows, line, col):
    text = "\n".join(["id,shape,w,h,x,y,name", *rows]) + "\n"
    status, err = run_validate(tmp_path, capsys, text.encode())
    assert (status, err) == (
        2,
        f"{tmp_path / 'bodies.csv'}:{line}:{col}: error: a quoted field opens here and is never "
        'closed (a " is missing)\n',
    )
    closed = text.replace('"abc', '"abc"').replace('"0,y', '"0",y')  # closed: read as written
    status, err = run_validate(tmp_path, capsys, closed.encode())
    assert (status, err) == (0, "")


def test_a_name_that_no_output_could_write_is_refused_at_its_cell(tmp_path, capsys):
    """A .npy string may hold a lone surrogate, which no UTF-8 output can write (exit 3 at the
    first write before)."""
    numbers = [(c, "f8") for c in ("id", "w", "h", "x", "y")]
    rec = np.zeros(2, dtype=numbers + [("shape", "U3"), ("name", "U2")])
    rec["name"] = ["ok", "\ud800"]
    rec["id"], rec["x"], rec["w"], rec["h"], rec["shape"] = [0, 1], [0, 10], 2, 2, "box"
    np.save(tmp_path / "t.npy", rec)
    status, err = run_validate(tmp_path, capsys, (tmp_path / "t.npy").read_bytes(), "t.npy")
    assert (status, err) == (
        2,
        f"{tmp_path / 't.npy'}:2:7: error: row 2, column name: a name is text, not a lone "
        "surrogate U+D800\n",
    )


def test_a_header_cell_past_the_csv_field_limit_is_refused_at_its_column(tmp_path, capsys):
    """Python's csv module refuses a field of more than 131,072 characters; the header is read
    with the limit raised, so a long column name is an unknown column, not an unexpected error."""
    shown = tmp_path / "bodies.csv"
    for cell in ("n" * 200_000, '"' + "n" * 200_000 + '"'):
        text = f"id,shape,w,h,x,y,{cell}\n0,box,2,2,0,0,a\n"
        status, err = run_validate(tmp_path, capsys, text.encode())
        assert status == 2
        assert err.startswith(f"{shown}:1:18: error: unknown column 'nnnnn")
        assert len(err) < 300  # the name is cut in the message


@pytest.mark.parametrize(
    "blank",
    ["   ", "\t", " \t \f", "\u00a0"],
)
def test_a_line_of_spaces_is_a_blank_line(tmp_path, capsys, blank):
    """Blank lines are skipped (docs/scenario-format.md#objects-from-a-table), spaces or not:
    at the end, in the middle, at the end without a newline; a bad cell after one is still
    found at its own line."""
    lf = load(write(tmp_path))
    for text in (
        "\n".join(ROWS) + f"\n{blank}\n",
        "\n".join(ROWS) + f"\n{blank}",
        "\n".join(ROWS[:2] + [blank] + ROWS[2:]) + "\n",
        "\n".join(ROWS[:2] + [blank, blank] + ROWS[2:]) + f"\n{blank}\n\n{blank}\n",
    ):
        status, err = run_validate(tmp_path, capsys, text.encode())
        assert (status, err) == (0, ""), repr(text)
        same_bodies(load(tmp_path / "scene.yaml").bodies, lf.bodies)
    bad = ROWS[:2] + [blank] + ["1,circle,6,6,50,20,zz,5,,#00ff00,,false,false"]
    status, err = run_validate(tmp_path, capsys, ("\n".join(bad) + f"\n{blank}\n").encode())
    assert (status, err) == (
        2,
        f"{tmp_path / 'bodies.csv'}:4:20: error: row 2, column vx: must be a number, not 'zz'\n",
    )


def test_a_line_of_spaces_inside_a_quoted_name_stays_in_the_name(tmp_path):
    """Only a line of spaces that is a row of its own is blank; inside a quoted field it is
    part of the cell (here a name that then holds more than 100 characters)."""
    rows = ["id,shape,w,h,x,y,name", '0,box,2,2,0,0,"a', "   ", 'b"']
    with pytest.raises(ScenarioError) as info:
        load(write(tmp_path, rows=rows[:3] + [" " * 120, 'b"']))
    assert (info.value.line, info.value.col) == (2, 15)
    assert "more than 100 characters" in info.value.message
    scene = load(write(tmp_path, rows=rows))
    assert scene.bodies.n == 1


def test_the_header_is_located_as_written(tmp_path, capsys):
    """An unknown column is found where its field starts, spaces and quotes as written; a quote
    the header never closes is refused where it opens; a blank first line is said to be one."""
    shown = tmp_path / "bodies.csv"
    header = 'id, shape ,"w",h,x,y,  colour'
    status, err = run_validate(tmp_path, capsys, f"{header}\n0,box,2,2,0,0,red\n".encode())
    assert status == 2
    assert err.startswith(f"{shown}:1:{header.index('  colour') + 1}: error: unknown column")
    status, err = run_validate(tmp_path, capsys, b'id,shape,w,h,x,y,"name\n0,box,2,2,0,0,a\n')
    assert (status, err) == (
        2,
        f'{shown}:1:18: error: a quoted field opens here and is never closed (a " is missing)\n',
    )
    status, err = run_validate(tmp_path, capsys, b"  \n" + "\n".join(ROWS).encode())
    assert (status, err) == (
        2,
        f"{shown}:1:1: error: the table's first line is blank; it must name the columns\n",
    )


def test_bytes_that_are_not_utf8_are_refused_at_their_line_and_column(tmp_path, capsys):
    shown = tmp_path / "bodies.csv"
    for raw, place in (
        (b"id,shape,w,h,x,y,name\n0,box,2,2,0,0,\xe9t\xe9\n", "2:15"),
        (b"id,shape,w,h,x,y,n\xc3\xa4me,\xff\n", "1:23"),  # counted in characters
        (b"\xef\xbb\xbfid,shape,w,h,x,y\n\xff\n", "2:1"),
    ):
        status, err = run_validate(tmp_path, capsys, raw)
        assert (status, err) == (2, f"{shown}:{place}: error: the table is not UTF-8 text\n")


@pytest.mark.parametrize(
    "content, where, fragment",
    [
        (b"id,sh\x00ape,w,h,x,y\n0,box,2,2,0,0\n", "1:6", "holds a NUL character"),
        (b"id,shape,w,h,x,y\n0,box,2,2,0\x00,0\n", "2:12", "holds a NUL character"),
        (b"id,shape,w,h,x,y,name\n0,box,2,2,0,0,a\x00\n", "2:16", "holds a NUL"),  # not cut
        (b'id,shape,w,h,x,y\n0,box,2,2,0,0\n""\n', "3:1", "row 2 has 1 fields; the header"),
        (b'id,shape,w,h,x,y\n"  "\n0,box,2,2,0,0\n', "2:1", "row 1 has 1 fields; the header"),
        (b"\xef\xbb\xbfid,shape,w,h,x,y\n0,box,2,2,0,0\n", None, ""),
        (b"\xef\xbb\xbf\xef\xbb\xbfid,shape,w,h,x,y\n", "1:1", "unknown column '\\ufeffid'"),
        (b"id,shape,w,h,x,y\r0,box,2,2,0,0\r1,box,2,2,5,0\r", None, ""),
        (b"id,shape,w,h,x,y\r0,box,2,2,0,0\r1,box,2,2,5,zz\r", "3:13", "must be a number"),
        (b"id,shape,w,h,x,y\r\n0,box,2,2,0,0\r1,box,2,2,5,0\n", None, ""),
        (b"id,shape,w,h,x,y", None, ""),
        (b"id,shape,w,h,x,y\n\n \n", None, ""),
        (b"id,shape,w,h,x,y\n0,box,2,2,0\n", "2:1", "row 1 has 5 fields; the header names 6"),
        (b"id,shape,w,h,x,y\n0,box,2,2,0,0,\n", "2:1", "row 1 has 7 fields"),
        (b"id,shape,w,h,x,y\n0,box,2,2,0,0\n# c\n", "3:1", "row 2 has 1 fields"),
        (b'id,shape,w,h,x,y\n0,box,2,2,0,"0\n', "2:13", "never closed"),
        (b'id,shape,w,h,x,y,name\n0,box,2,2,0,0,"a""b"\n', None, ""),
        (b'id,shape,w,h,x,y\n0,box,"2",2, 0 ,0\n', None, ""),
        (b"id,shape,w,h,x,y\n0,box,2,2,0," + b"1" * 400 + b"\n", "2:13", "finite number"),
        (b"id,shape,w,h,x,y,name\n0,box,2,2,0,0," + b"x" * 3_000_000 + b"\n", "2:15", "100 ch"),
        (b"id,shape,w,h,x,y" + b",x" * 50_000 + b"\n", "1:18", "column 'x' appears twice"),
        (b"", "1:1", "the table is empty"),
        (b"id,shape,w,h,x,y\n" + b"\n" * 1000 + b"0,box,2,2,0,q\n", "1002:13", "must be a num"),
    ],
)
def test_a_hostile_table_is_read_or_refused_at_its_place(
    tmp_path, capsys, content, where, fragment
):
    status, err = run_validate(tmp_path, capsys, content)
    if where is None:
        assert (status, err) == (0, "")
        return
    assert status == 2
    assert err.startswith(f"{tmp_path / 'bodies.csv'}:{where}: error: ") and fragment in err, err


def test_an_npy_name_of_bytes_that_are_not_utf8_is_refused_at_its_cell(tmp_path, capsys):
    """Not replaced by U+FFFD unseen: a CSV's bytes that are not UTF-8 are refused too."""
    numbers = [(c, "f8") for c in ("id", "w", "h", "x", "y")]
    rec = np.zeros(2, dtype=numbers + [("shape", "S3"), ("name", "S4")])
    rec["name"] = [b"ok", b"a\xffb"]
    rec["id"], rec["x"], rec["w"], rec["h"], rec["shape"] = [0, 1], [0, 10], 2, 2, b"box"
    np.save(tmp_path / "t.npy", rec)
    status, err = run_validate(tmp_path, capsys, (tmp_path / "t.npy").read_bytes(), "t.npy")
    assert (status, err) == (
        2,
        f"{tmp_path / 't.npy'}:2:7: error: row 2, column name: the cell is not UTF-8 text\n",
    )
    rec["name"] = [b"ok", "é".encode()]
    np.save(tmp_path / "t.npy", rec)
    assert load(tmp_path / "scene.yaml").names == ("ok", "é")
