"""Objects to arrays: placement inside the world and apart, and the palette."""

from __future__ import annotations

from scenario_text import BASE, check_refused, objects

from collide2d.runner.scenario.load import loads

# ----------------------------------------------------------------------------- placement


def test_object_outside_the_world():
    text = objects(
        "{shape: box, size: 10, position: [0, 0]}", "{shape: box, size: 10, position: [91, 0]}"
    )
    err = check_refused(text, "{shape", "objects[1] lies outside the world", nth=1)
    assert "[91, 101) x [0, 10)" in err.message and "[0, 100) x [0, 80)" in err.message
    text = objects("{shape: box, size: 10, position: [0, -1]}")
    check_refused(text, "{shape", "objects[0] lies outside the world")
    # touching the far walls is inside
    assert loads(objects("{shape: box, size: 10, position: [90, 70]}")).bodies.n == 1


def test_polygon_outside_the_world_by_its_pixels():
    # points reach x = -1 from position 0
    text = objects("{shape: polygon, points: [[-1, 0], [5, 0], [0, 5]], position: [0, 0]}")
    check_refused(text, "{shape", "objects[0] lies outside the world")


def test_overlap_names_the_pair_and_both_lines():
    text = objects(
        "{shape: box, size: 10, position: [0, 0]}",
        "{shape: box, size: 10, position: [50, 50]}",
        "{shape: box, size: 10, position: [5, 5]}",
    )
    err = check_refused(text, "{shape", "objects[2] (line 6) overlaps objects[0] (line 4)", nth=2)
    assert "[5, 15) x [5, 15)" in err.message and "[0, 10) x [0, 10)" in err.message


def test_touching_boxes_do_not_overlap():
    sc = loads(
        objects(
            "{shape: box, size: 10, position: [0, 0]}",
            "{shape: box, size: 10, position: [10, 0]}",
            "{shape: box, size: 10, position: [0, 10]}",
            "{shape: circle, diameter: 10, position: [10, 10]}",
        )
    )
    assert sc.bodies.n == 4


def test_shapes_overlap_as_their_boxes():
    # a triangle's box [0, 10) x [0, 10) covers a box in the corner its outline never reaches
    text = objects(
        "{shape: polygon, points: [[0, 0], [9, 0], [0, 9]], position: [0, 0]}",
        "{shape: box, size: 2, position: [8, 8]}",
    )
    check_refused(text, "{shape", "objects[1] (line 5) overlaps objects[0] (line 4)", nth=1)


def test_stepped_float_positions_overlap_exactly():
    head = BASE + "model: stepped\n"
    ok = objects(
        "{shape: box, size: 10, position: [0.5, 0]}",
        "{shape: box, size: 10, position: [10.5, 0]}",
        head=head,
    )
    assert loads(ok).bodies.n == 2
    bad = ok.replace("10.5", "10.25")
    check_refused(bad, "{shape", "overlaps", nth=1)


# ----------------------------------------------------------------------------- palette


def test_palette_in_order_of_first_appearance():
    text = (
        objects(
            "{shape: box, size: 2, position: [0, 0], color: blue}",
            "{shape: box, size: 2, position: [4, 0], color: red}",
            "{shape: box, size: 2, position: [8, 0], color: [0, 0, 255]}",
            "{shape: box, size: 2, position: [12, 0], color: black}",
            head="version: 1\nworld: {width: 100, height: 80, background: '#101010'}\n",
        )
        + "generate:\n  - {count: 2, shape: box, size: 2, color: red}\n"
        + ("  - {count: 1, shape: box, size: 2, color: lime}\n")
    )
    sc = loads(text)
    assert sc.palette.tolist() == [[16, 16, 16], [0, 0, 255], [255, 0, 0], [0, 0, 0], [0, 255, 0]]
    # an object drawn in the background's colour still has its own row: row 0 is the background
    assert sc.bodies.looks.color.tolist() == [1, 2, 1, 3, 2, 2, 4]


def test_palette_holds_256_rows():
    def text(k: int) -> str:
        lines = [
            f"{{shape: box, size: 1, position: [{i % 64}, {i // 64}], color: [{i % 256}, "
            f"{i // 256}, 7]}}"
            for i in range(k)
        ]
        return objects(*lines, head="version: 1\nworld: {width: 64, height: 64}\n")

    assert loads(text(255)).palette.shape == (256, 3)
    big = text(256)
    check_refused(big, "[255, 0, 7]", "too many colours: the palette holds 256")
