"""Objects to arrays: the checked objects and blocks of a scenario become `Bodies` and a palette.

The objects come checked but for their overlap (`runner.scenario.rules`): no two listed objects
or table rows may overlap at the start (touching is fine; under `geometry: exact` overlap is judged
by the real shapes, so circles racked tightly in touching boxes are legal); then each generate
block is drawn by `runner.scenario.generate` around them; the
per-object arrays hold the listed objects first, then each block's objects, in id order (an object's
restitution and friction their defaults, 1 and 0, where not given). Colours are
indexed into a palette of at most PALETTE_SIZE rows: row 0 the background, then each distinct object
colour in order of first use.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.models import MODEL_NAMES, options_of, shapes_of
from collide2d.engine.noroom import no_room, no_room_message
from collide2d.engine.world import KIND_NAMES, Bodies, Looks, WorldSpec
from collide2d.runner import lanes
from collide2d.runner.scenario import generate, rules
from collide2d.runner.scenario.nodes import Nodes
from collide2d.runner.scenario.objects import Block, Listed, fault_error
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
        check_table_placement(table, geometry)
    else:
        pos = np.array([o.pos for o in listed], np.float64).reshape(-1, 2)
        size = np.array([o.size for o in listed], np.float64).reshape(-1, 2)
        check_placement(reader, listed, pos, size, geometry)

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

    if blocks and geometry == "exact" and (pair := generate.first_overlap(pos, size)) is not None:
        raise reader.error(
            blocks[0].node,
            f"generate places objects around the listed objects' boxes, which must not overlap "
            f"here: {_who(listed, pair[1])} and {_who(listed, pair[0])} (shapes that only touch "
            "are legal "
            "without generate)",
        )
    try:
        specs = [b.spec for b in blocks]
        drawn = generate.generate(world.width, world.height, pos, size, specs) if blocks else []
    except generate.PlacementError as exc:
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
    contact = []  # restitution, friction: NaN where not given, so the object's default
    for k, default in enumerate((rules.DEFAULT_RESTITUTION, rules.DEFAULT_FRICTION)):
        if table is not None:
            written = (table.restitution, table.friction)[k]
            written = np.full(n_listed, np.nan) if written is None else written
        else:
            written = [o.contact[k] for o in listed]
        values = per_object(written, [b.contact[k] for b in blocks], np.float64)
        contact.append(np.where(np.isnan(values), default, values))
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
        restitution=contact[0],
        friction=contact[1],
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


def check_placement(reader: Nodes, listed: list[Listed], pos, size, geometry: str = "box") -> None:
    """No two listed objects overlapping at the start (runner.scenario.rules.first_overlap):
    boxes, or under `geometry` "exact" the real shapes; inside the world was checked with the
    other rules (runner.scenario.objects.ObjectReader.check)."""
    if not listed:
        return
    shapes = None
    if geometry == "exact":
        polys = [o.verts for o in listed if o.verts is not None]
        nverts = [0 if o.verts is None else o.verts.shape[0] for o in listed]
        shapes = {
            "kind": np.array([o.kind for o in listed], np.int8),
            "vert_start": np.concatenate([[0], np.cumsum(nverts)]).astype(np.int64),
            "verts": np.concatenate(polys).astype(np.int64)
            if polys
            else np.zeros((0, 2), np.int64),
        }
    found = rules.first_overlap(pos, size, shapes)
    if found is not None:
        raise fault_error(reader, listed, found, "objects")


def check_room(reader, world, bodies, geometry, names, listed, lines, table=None) -> None:
    """Refuse, at the object, a moving object with no room on an axis it moves on (the exact
    model would collide it again and again with no time passing; engine.models.exact)."""
    with lanes.objects(bodies.n):
        found = no_room(world, bodies, geometry)
    if not found:
        return
    i = found[0].obj
    message = reader.prefix(reader.model_from) + no_room_message(found, bodies, names)
    if i < len(listed):
        raise reader.error(listed[i].node, message)
    if table is not None and i < table.n:
        raise table.error(i, "x", message)
    raise ScenarioError(reader.path, lines[i], 1, message)


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


def _who(listed, i: int) -> str:
    """objects[i], with its name when it has one: `objects[3] (ball)`."""
    name = None if isinstance(listed, _TableRows) else listed[i].name
    return f"objects[{i}]" + (f" ({name})" if name else "")


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


def check_table_placement(table, geometry: str = "box") -> None:
    """No two objects of a table overlapping at the start (runner.scenario.rules.first_overlap),
    refused at the later one's x cell; inside the world was checked with the other rules
    (runner.scenario.table.checked)."""
    shapes = None
    if geometry == "exact":
        shapes = {"kind": table.kind, "vert_start": np.zeros(table.n + 1, np.int64)}
        shapes["verts"] = np.zeros((0, 2), np.int64)
    found = rules.first_overlap(table.pos, table.size, shapes)
    if found is not None:
        a = found.other
        named = f"{table.names[a]}, " if table.names[a] else ""
        other = f"object {a} ({named}row {a + 1})"
        raise table.error(found.row, "x", found.text.format(other=other))


def check_plugin(reader: Nodes, model: str, geometry: str, bodies: Bodies, lines, top) -> None:
    """Under a model plugin (engine.models.protocol), the scenario holds only what the model says
    it takes: `geometry: exact` only when it takes `geometry`, objects only of its `SHAPES` (the
    first of another shape is refused at its line)."""
    if model in MODEL_NAMES:
        return
    if geometry != "box" and "geometry" not in options_of(model):
        raise reader.error(
            top["model"][1], f"the model '{model}' does not take geometry '{geometry}'"
        )
    takes = shapes_of(model)
    kinds = [KIND_NAMES.index(s) for s in takes]
    bad = np.flatnonzero(~np.isin(bodies.kind, kinds))
    if len(bad):
        i = int(bad[0])
        raise ScenarioError(
            reader.path,
            lines[i],
            1,
            f"object {i} is a {KIND_NAMES[bodies.kind[i]]}, a shape the model '{model}' does not "
            f"take (it takes {', '.join(takes) or 'none'})",
        )
