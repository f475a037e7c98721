"""Objects to arrays: the checked objects and blocks of a scenario become `Bodies` and a palette.

Listed objects are checked first (each inside the world, no two overlapping; touching is fine; under
`geometry: exact` overlap is judged by the real shapes, so circles racked tightly in touching boxes
are legal), then each generate block is drawn by `runner.scenario.generate` around them; the
per-object arrays hold the listed objects first, then each block's objects, in id order. Colours are
indexed into a palette of at most PALETTE_SIZE rows: row 0 the background, then each distinct object
colour in order of first use.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from collide2d.engine.world import Bodies, Looks, WorldSpec
from collide2d.runner import lanes
from collide2d.runner.scenario import generate as gen
from collide2d.runner.scenario.nodes import Nodes, fmt
from collide2d.runner.scenario.objects import Block, Listed
from collide2d.runner.scenario.parse import ScenarioError

PALETTE_SIZE = 256  # palette rows: the background and up to 255 object colours


def bodies(
    reader: Nodes,
    listed: list[Listed],
    blocks: list[Block],
    world: WorldSpec,
    background,
    geometry: str = "box",
    table=None,
):
    """(Bodies, names, lines, palette) of the listed objects, or the rows of a `table`
    (runner.scenario.table, checked already but for overlaps), then the generate blocks; starting
    overlap judged by the real shapes under `geometry` exact."""
    if table is not None:
        listed = _TableRows(table, reader)
    n_listed = len(listed)
    if table is not None:
        pos, size = table.pos, table.size
        check_table_placement(table)
    else:
        pos = np.array([o.pos for o in listed], np.float64).reshape(-1, 2)
        size = np.array([o.size for o in listed], np.float64).reshape(-1, 2)
        check_placement(reader, listed, pos, size, world, geometry)

    palette = [background]
    index: dict[tuple[int, int, int], int] = {}

    def color_index(rgb, node) -> int:
        if rgb not in index:
            if len(palette) >= PALETTE_SIZE:
                said = (
                    f"too many colours: the palette holds {PALETTE_SIZE} "
                    f"(the background and {PALETTE_SIZE - 1} object "
                    "colours)"
                )
                if isinstance(node, _RowNode):
                    raise node.table.error(node.row, "color", said)
                raise reader.error(node, said)
            index[rgb] = len(palette)
            palette.append(rgb)
        return index[rgb]

    if table is not None:
        _, where = np.unique(table.color_of, return_index=True)
        to_palette = [
            color_index(rgb, _RowNode(table, r)) for rgb, r in zip(table.colors, where, strict=True)
        ]
        listed_colors = np.asarray(to_palette, np.int64)[table.color_of]
    else:
        listed_colors = [color_index(o.color, o.color_node or o.node) for o in listed]
    block_colors = [color_index(b.color, b.color_node or b.node) for b in blocks]

    if blocks and geometry == "exact" and (pair := gen.first_overlap(pos, size)) is not None:
        raise reader.error(
            blocks[0].node,
            f"generate places objects around the listed objects' boxes, which must not overlap "
            f"here: objects[{pair[1]}] and objects[{pair[0]}] (shapes that only touch are legal "
            "without generate)",
        )
    try:
        specs = [b.spec for b in blocks]
        drawn = gen.generate(world.width, world.height, pos, size, specs) if blocks else []
    except gen.PlacementError as exc:
        raise reader.error(blocks[exc.block].node, f"generate[{exc.block}]: {exc}") from None

    counts = [b.spec.count for b in blocks]
    n = n_listed + sum(counts)
    rep = np.array(counts, np.int64)

    def per_object(listed_values, block_values, dtype):
        a = np.asarray(listed_values, dtype).reshape(n_listed)
        b = np.repeat(np.asarray(block_values, dtype).reshape(len(blocks)), rep)
        return np.concatenate([a, b])

    def column(name):
        return getattr(table, name) if table is not None else [getattr(o, name) for o in listed]

    kind = per_object(column("kind"), [b.kind for b in blocks], np.int8)
    static = per_object(column("static"), [b.static for b in blocks], bool)
    mass = per_object(column("mass"), [b.mass for b in blocks], np.float64)
    mass[static] = np.inf
    color = per_object(listed_colors, block_colors, np.uint8)
    fill = per_object(column("fill"), [b.fill for b in blocks], bool)
    all_pos = np.concatenate([pos] + [d[0] for d in drawn]).reshape(n, 2)
    all_vel = np.concatenate(
        [np.array(column("vel"), np.float64).reshape(-1, 2)] + [d[1] for d in drawn]
    ).reshape(n, 2)
    block_size = [
        np.broadcast_to(np.asarray(b.spec.size, np.float64), (c, 2))
        for b, c in zip(blocks, counts, strict=True)
    ]
    all_size = np.concatenate([size] + block_size).reshape(n, 2)
    nverts = np.zeros(n, np.int64)
    polys = []
    if table is None:
        nverts[:n_listed] = [0 if o.verts is None else o.verts.shape[0] for o in listed]
        polys = [o.verts for o in listed if o.verts is not None]
    vert_start = np.concatenate([[0], np.cumsum(nverts)]).astype(np.int64)
    verts = np.concatenate(polys).astype(np.int64) if polys else np.zeros((0, 2), np.int64)
    bodies = Bodies(
        kind=kind,
        pos=all_pos,
        size=all_size,
        vel=all_vel,
        mass=mass,
        static=static,
        vert_start=vert_start,
        verts=verts,
        looks=Looks(color=color, fill=fill),
    )

    if table is not None:
        names: list = list(table.names)
        lines: list = (
            list(table.lines)
            if table.lines is not None
            else [reader.root.start_mark.line + 1 if reader.root is not None else 1] * n_listed
        )
    else:
        names = [o.name for o in listed]
        lines = [o.node.start_mark.line + 1 for o in listed]
    for b, c in zip(blocks, counts, strict=True):
        names.extend([f"{b.name}-{j}" for j in range(c)] if b.name is not None else [None] * c)
        lines.extend([b.node.start_mark.line + 1] * c)
    check_names(reader, names, listed, blocks, lines)
    return bodies, tuple(names), tuple(lines), np.array(palette, np.uint8).reshape(-1, 3)


def check_placement(
    reader: Nodes, listed: list[Listed], pos, size, world: WorldSpec, geometry: str = "box"
) -> None:
    """Every listed box inside the world, no two overlapping (touching is fine): no two boxes,
    or under `geometry` "exact" no two real shapes."""
    if not listed:
        return
    end = pos + size
    outside = np.any((pos < 0) | (end > np.array([world.width, world.height])), axis=1)
    if outside.any():
        i = int(np.argmax(outside))
        raise reader.error(
            listed[i].node,
            f"objects[{i}] lies outside the world: its box "
            f"{_box_text(pos[i], size[i])} must fit in [0, {world.width}) x "
            f"[0, {world.height})",
        )
    found = gen.first_overlap(pos, size)
    if found is not None and geometry == "exact":
        found = _first_shape_overlap(listed, pos, size)
    if found is not None:
        a, b = found
        la = listed[a].node.start_mark.line + 1
        lb = listed[b].node.start_mark.line + 1
        raise reader.error(
            listed[b].node,
            f"objects[{b}] (line {lb}) overlaps objects[{a}] "
            f"(line {la}) at the start: "
            f"{'shapes in boxes' if geometry == 'exact' else 'boxes'} "
            f"{_box_text(pos[b], size[b])} and "
            f"{_box_text(pos[a], size[a])}",
        )


def _first_shape_overlap(listed: list[Listed], pos, size) -> tuple[int, int] | None:
    """The first pair (a, b) in (b, a) order whose exact shapes overlap with positive area."""
    n = len(listed)
    with lanes.objects(n):
        return _shape_overlap(listed, pos, size)


def _shape_overlap(listed: list[Listed], pos, size) -> tuple[int, int] | None:
    from collide2d.engine.broadphase import METHOD_SWEEP, find_pairs
    from collide2d.engine.contact import penetration
    from collide2d.engine.shapes import build_cores

    n = len(listed)
    polys = [o.verts for o in listed if o.verts is not None]
    nverts = [0 if o.verts is None else o.verts.shape[0] for o in listed]
    shapes = SimpleNamespace(
        kind=np.array([o.kind for o in listed], np.int8),
        size=size,
        vert_start=np.concatenate([[0], np.cumsum(nverts)]).astype(np.int64),
        verts=np.concatenate(polys).astype(np.int64) if polys else np.zeros((0, 2), np.int64),
    )
    cores = build_cores(shapes, "exact")
    pairs = find_pairs(METHOD_SWEEP, pos, pos + size, np.ones(n, bool))

    def shape(i):
        core = slice(cores.start[i], cores.start[i + 1])
        return (
            cores.shape[i],
            size[i, 0],
            size[i, 1],
            cores.radius[i],
            cores.verts[core],
            cores.normals[core],
        )

    for a, b in sorted(pairs.tolist(), key=lambda p: (p[1], p[0])):
        q = pos[b] - pos[a]
        if penetration(q[0], q[1], *shape(a), *shape(b))[0] > 0:
            return a, b
    return None


def check_names(reader: Nodes, names, listed, blocks, lines) -> None:
    """No two objects share a name (a generate block's `name` names its objects NAME-0, ...); a
    repeat is refused at the later object: its node, its table cell, or its block's line."""
    table = listed.table if isinstance(listed, _TableRows) else None
    seen: dict[str, int] = {}
    for i, name in enumerate(names):
        if name is None:
            continue
        if name in seen:
            j = seen[name]
            first = f"row {j + 1} of the table" if table is not None and j < table.n else None
            first = first or f"line {lines[j]}"
            said = (
                f"like object {j} ({first}); names must differ, they name the objects in "
                "events.jsonl and final.csv"
            )
            if table is not None and i < table.n:
                raise table.error(i, "name", f"{name!r} is taken, {said}")
            if i < len(listed):
                raise reader.error(listed[i].node, f"objects[{i}] is named {name!r}, {said}")
            raise ScenarioError(
                reader.path, lines[i], 1, f"a generated object is named {name!r}, {said}"
            )
        seen[name] = i


def _box_text(p, s) -> str:
    """The half-open box [x, x+w) x [y, y+h) as text."""
    x0, x1 = fmt(float(p[0])), fmt(float(p[0] + s[0]))
    y0, y1 = fmt(float(p[1])), fmt(float(p[1] + s[1]))
    return f"[{x0}, {x1}) x [{y0}, {y1})"


class _TableRows:
    """A table standing where the list of objects would be: its length, for the counts."""

    def __init__(self, table, reader):
        self.table = table

    def __len__(self) -> int:
        return self.table.n


class _RowNode:
    """A table row standing where a YAML node would be in an error (a colour past the palette)."""

    def __init__(self, table, row):
        self.table, self.row = table, row


def check_table_placement(table) -> None:
    """No two boxes of a table overlapping (touching is fine); inside the world was checked by
    column when the table was read."""
    found = gen.first_overlap(table.pos, table.size)
    if found is not None:
        a, b = found
        raise table.error(
            b,
            "x",
            f"object {b} overlaps object {a} at the start: boxes "
            f"{_box_text(table.pos[b], table.size[b])} and "
            f"{_box_text(table.pos[a], table.size[a])}",
        )
