"""Boxes without overlap: the start-overlap check and the objects of a scenario's `generate` blocks.

Both rest on one uniform grid over the world: every box is linked into each cell it covers, and a
query looks only at the boxes linked into the cells of the box asked about. Two boxes *overlap* when
both of their half-open intervals `[x, x+w)`, `[y, y+h)` intersect with positive length; boxes that
only touch do not.

`first_overlap(pos, size)` takes (n, 2) float64 top-left corners and sizes (px) and finds the first
box, in id order, that overlaps an earlier one: `(a, b)` with `a < b`, `b` the smallest such id and
`a` the smallest id it overlaps; `None` when no two boxes overlap. Its cost grows with n and with
how many boxes share a cell, never with n^2 for boxes of similar sizes.

`generate(width, height, fixed_pos, fixed_size, blocks)` places each block's boxes at whole-pixel
positions inside the `width` x `height` world so that no box overlaps the fixed boxes or any box
placed before it, and draws their velocities (px/s). Each block draws from its own
`numpy.random.default_rng(seed)` (PCG64, so the same objects on every platform), in this order:

1. positions: batches of `POSITION_BATCH` candidates `rng.integers(0, [width - w + 1,
   height - h + 1], size=(POSITION_BATCH, 2))`, column 0 the x and column 1 the y of the top-left
   corner; candidates are tried in order, and each object takes the first one that overlaps
   nothing placed before it (the next object starts from the candidate after it);
2. velocities, once every position of the block is placed, as `(count, 2)` arrays:
   - `speed: S`: `rng.integers(0, 2, size=(count, 2))` picks the signs, velocity `(+-S, +-S)`;
   - `speed: {min: a, max: b}`: magnitudes `rng.uniform(a, b, size=count)`, then angles
     `rng.uniform(0, 2*pi, size=count)`, velocity `magnitude * (cos, sin)`; with `whole` (the
     paper model) each component is rounded to the nearest integer, halves up (`floor(v + 0.5)`);
   - `velocity: {min: [vx0, vy0], max: [vx1, vy1]}`: `rng.uniform(min, max, size=(count, 2))`, or
     with `whole` `rng.integers(min, max, size=(count, 2), endpoint=True)`;
   - neither: zero velocity, nothing drawn.

A block gives up with `PlacementError` when one object fails `MAX_DRAWS_PER_OBJECT` candidates in a
row, when the block has used `MAX_DRAWS_PER_OBJECT_AVERAGE * count + MAX_DRAWS_PER_OBJECT`
candidates, or at once when the boxes' total area is larger than the world's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from collide2d.engine.jit import njit
from collide2d.engine.sort import median as median_of
from collide2d.runner import lanes

# Candidate positions drawn per batch from a block's generator (fixed: it is part of the stream).
POSITION_BATCH = 4096
# Failed candidates in a row for one object before its block gives up.
MAX_DRAWS_PER_OBJECT = 10_000
# Candidates a block may use on average per object (plus MAX_DRAWS_PER_OBJECT) before giving up.
MAX_DRAWS_PER_OBJECT_AVERAGE = 100
# The grid has at most about this many cells per box (it bounds the grid's memory).
GRID_CELLS_PER_BOX = 4
# Smallest grid cell side, px.
GRID_MIN_CELL = 1.0

_OK = 0
_FULL = 1
_STUCK = 2


class PlacementError(Exception):
    """A generate block's boxes could not all be placed without overlap.

    block: index of the block; placed: boxes of it placed; draws: candidates it used.
    """

    def __init__(self, block: int, count: int, size, world, placed: int, draws: int, why: str):
        self.block = block
        self.count = count
        self.placed = placed
        self.draws = draws
        w, h = size
        width, height = world
        super().__init__(
            f"cannot place {count} boxes of {w}x{h} without overlap in {width}x{height} ({why})"
        )


@dataclass(frozen=True)
class BlockSpec:
    """One validated generate block.

    count           boxes to place
    size            (w, h) whole pixels
    seed            seed of the block's numpy.random.default_rng
    speed           S: velocity (+-S, +-S) px/s with random signs
    speed_range     (a, b): magnitude uniform in [a, b] px/s, direction uniform in angle
    velocity_range  ((vx0, vy0), (vx1, vy1)): each component uniform between min and max px/s
    whole           draw whole-number velocity components (the paper model)
    """

    count: int
    size: tuple[int, int]
    seed: int = 0
    speed: float | None = None
    speed_range: tuple[float, float] | None = None
    velocity_range: tuple[tuple[float, float], tuple[float, float]] | None = None
    whole: bool = False


# ----------------------------------------------------------------------------- grid kernels


@njit(cache=True)
def _cells(lo, length, cell, ncell):
    """First and last cell index (clipped to 0..ncell-1) covering [lo, lo + length), lo >= 0."""
    first = int(math.floor(lo / cell))
    last = int(math.ceil((lo + length) / cell)) - 1
    if first > ncell - 1:
        first = ncell - 1
    if first < 0:
        first = 0
    if last > ncell - 1:
        last = ncell - 1
    if last < first:
        last = first
    return first, last


@njit(cache=True)
def _query(x, y, w, h, pos, size, ox, oy, cell, gx, gy, head, nxt, item):
    """Smallest id among the linked boxes overlapping box (x, y, w, h), or -1."""
    best = -1
    cx0, cx1 = _cells(x - ox, w, cell, gx)
    cy0, cy1 = _cells(y - oy, h, cell, gy)
    for cy in range(cy0, cy1 + 1):
        for cx in range(cx0, cx1 + 1):
            k = head[cy * gx + cx]
            while k >= 0:
                j = item[k]
                if (best < 0 or j < best) and (
                    x < pos[j, 0] + size[j, 0]
                    and pos[j, 0] < x + w
                    and y < pos[j, 1] + size[j, 1]
                    and pos[j, 1] < y + h
                ):
                    best = j
                k = nxt[k]
    return best


@njit(cache=True)
def _insert(i, pos, size, ox, oy, cell, gx, gy, head, nxt, item, used):
    """Link box i into every cell it covers; False (and nothing linked) when out of room."""
    cx0, cx1 = _cells(pos[i, 0] - ox, size[i, 0], cell, gx)
    cy0, cy1 = _cells(pos[i, 1] - oy, size[i, 1], cell, gy)
    need = (cx1 - cx0 + 1) * (cy1 - cy0 + 1)
    if used[0] + need > nxt.shape[0]:
        return False
    for cy in range(cy0, cy1 + 1):
        for cx in range(cx0, cx1 + 1):
            k = used[0]
            c = cy * gx + cx
            item[k] = i
            nxt[k] = head[c]
            head[c] = k
            used[0] = k + 1
    return True


@njit(cache=True)
def _sweep(start, stop, pos, size, ox, oy, cell, gx, gy, head, nxt, item, used):
    """Link boxes start..stop-1 in order, stopping at the first that overlaps a linked one.

    Returns (status, i, j): (_OK, stop, -1) when all are linked; (_OK, i, j) when box i overlaps
    box j (j the smallest such id); (_FULL, i, -1) when box i did not fit in the link arrays.
    """
    for i in range(start, stop):
        j = _query(
            pos[i, 0],
            pos[i, 1],
            size[i, 0],
            size[i, 1],
            pos,
            size,
            ox,
            oy,
            cell,
            gx,
            gy,
            head,
            nxt,
            item,
        )
        if j >= 0:
            return _OK, i, j
        if not _insert(i, pos, size, ox, oy, cell, gx, gy, head, nxt, item, used):
            return _FULL, i, -1
    return _OK, stop, -1


@njit(cache=True)
def _place(
    cands, w, h, start, stop, fails, max_fails, pos, size, cell, gx, gy, head, nxt, item, used
):
    """Try candidate corners cands (k, 2) in order for boxes start, start+1, ... (< stop) of w x h.

    Returns (next box, failures in a row, candidates used, status): status _FULL leaves the
    candidate that found no room unused; _STUCK when `max_fails` failures came in a row.
    """
    i = start
    k = 0
    while k < cands.shape[0] and i < stop:
        x = float(cands[k, 0])
        y = float(cands[k, 1])
        if _query(x, y, w, h, pos, size, 0.0, 0.0, cell, gx, gy, head, nxt, item) >= 0:
            k += 1
            fails += 1
            if fails >= max_fails:
                return i, fails, k, _STUCK
            continue
        pos[i, 0] = x
        pos[i, 1] = y
        size[i, 0] = w
        size[i, 1] = h
        if not _insert(i, pos, size, 0.0, 0.0, cell, gx, gy, head, nxt, item, used):
            return i, fails, k, _FULL
        k += 1
        i += 1
        fails = 0
    return i, fails, k, _OK


@njit(cache=True)
def _count_links(pos, size, ox, oy, cell, gx, gy):
    """Total cells covered by the boxes (the links a grid of them needs)."""
    total = 0
    for i in range(pos.shape[0]):
        cx0, cx1 = _cells(pos[i, 0] - ox, size[i, 0], cell, gx)
        cy0, cy1 = _cells(pos[i, 1] - oy, size[i, 1], cell, gy)
        total += (cx1 - cx0 + 1) * (cy1 - cy0 + 1)
    return total


# ----------------------------------------------------------------------------- the grid


class _Grid:
    """Cells of side `cell` px over [ox, ox + extent_x) x [oy, oy + extent_y), with link arrays."""

    def __init__(self, ox, oy, extent_x, extent_y, cell, capacity):
        self.ox = float(ox)
        self.oy = float(oy)
        self.cell = float(cell)
        self.gx = max(1, math.ceil(extent_x / cell))
        self.gy = max(1, math.ceil(extent_y / cell))
        self.head = np.full(self.gx * self.gy, -1, np.int64)
        capacity = max(16, int(capacity))
        self.nxt = np.empty(capacity, np.int64)
        self.item = np.empty(capacity, np.int64)
        self.used = np.zeros(1, np.int64)

    def grow(self):
        """Double the link arrays (links already made stay valid)."""
        n = self.nxt.shape[0]
        self.nxt = np.concatenate([self.nxt, np.empty(n, np.int64)])
        self.item = np.concatenate([self.item, np.empty(n, np.int64)])

    def args(self):
        return (
            self.ox,
            self.oy,
            self.cell,
            self.gx,
            self.gy,
            self.head,
            self.nxt,
            self.item,
            self.used,
        )

    def sweep(self, start, stop, pos, size):
        """Link boxes start..stop-1; (i, j) of the first overlap found, or None."""
        i = start
        while True:
            status, i, j = _sweep(i, stop, pos, size, *self.args())
            if status == _FULL:
                self.grow()
                continue
            return None if j < 0 else (int(i), int(j))


def cell_size(extent_x: float, extent_y: float, max_sides: np.ndarray) -> float:
    """Grid cell side (px) for boxes with these larger sides in an extent_x x extent_y area.

    About the median box's larger side, so a box covers few cells, but never so small that the
    grid has more than GRID_CELLS_PER_BOX cells per box.
    """
    n = max(1, int(max_sides.shape[0]))
    median = median_of(max_sides) if max_sides.shape[0] else GRID_MIN_CELL
    sparse = math.sqrt(max(extent_x, 1.0) * max(extent_y, 1.0) / (GRID_CELLS_PER_BOX * n))
    return max(GRID_MIN_CELL, median, sparse)


APART_MAX_PER_CELL = 4  # _apart gives up (the kernel decides) past this many boxes in a cell
_APART_MAX_COORD = 2.0**40  # and past coordinates this large (their rounding against a cell)


def _apart(pos: np.ndarray, size: np.ndarray) -> bool:
    """True only when no two boxes overlap, found with numpy alone (no kernel to load): each box
    goes to the cell of its corner on a grid of the largest side (and a little more, for
    rounding), so two boxes that overlap sit in the same or neighbouring cells, and every such
    pair is tested as `_query` tests it. False when they may overlap or the scene does not suit
    the test (crowded cells, huge coordinates): `first_overlap` then asks the kernel."""
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(size))):
        return False
    if np.max(np.abs(pos)) > _APART_MAX_COORD or np.max(size) > _APART_MAX_COORD:
        return False
    lo = pos.min(axis=0)
    cell = float(np.max(size)) * 1.01 + 1e-9
    c = np.floor((pos - lo) / cell).astype(np.int64)
    gx = int(c[:, 0].max()) + 3
    key = (c[:, 1] + 1) * gx + (c[:, 0] + 1)
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    if sorted_key.shape[0] > APART_MAX_PER_CELL:
        crowded = sorted_key[APART_MAX_PER_CELL:] == sorted_key[:-APART_MAX_PER_CELL]
        if crowded.any():
            return False
    x0, y0 = pos[:, 0], pos[:, 1]
    x1, y1 = pos[:, 0] + size[:, 0], pos[:, 1] + size[:, 1]
    for dx, dy in ((0, 0), (1, 0), (-1, 1), (0, 1), (1, 1)):
        target = sorted_key + dy * gx + dx  # for the boxes in cell order (sorted: a fast search)
        start = np.searchsorted(sorted_key, target, "left")
        stop = np.searchsorted(sorted_key, target, "right")
        for slot in range(APART_MAX_PER_CELL):
            has = start + slot < stop
            if not has.any():
                break
            i = order[has]
            j = order[start[has] + slot]
            if dx == 0 and dy == 0:
                i, j = i[i != j], j[i != j]
            hit = (x0[i] < x1[j]) & (x0[j] < x1[i]) & (y0[i] < y1[j]) & (y0[j] < y1[i])
            if hit.any():
                return False
    return True


def first_overlap(pos, size) -> tuple[int, int] | None:
    """First overlapping pair (a, b), a < b, among boxes at pos (n, 2) of size (n, 2), px.

    b is the smallest id that overlaps an earlier box and a the smallest id it overlaps; None when
    no two boxes overlap (touching is not overlapping). Coordinates must be finite.
    """
    pos = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 2)
    size = np.ascontiguousarray(size, dtype=np.float64).reshape(-1, 2)
    n = pos.shape[0]
    if n < 2 or _apart(pos, size):
        return None
    lo = pos.min(axis=0)
    hi = (pos + size).max(axis=0)
    extent = hi - lo
    cell = cell_size(extent[0], extent[1], size.max(axis=1))
    with lanes.objects(n):
        grid = _Grid(lo[0], lo[1], extent[0], extent[1], cell, 0)
        links = _count_links(pos, size, grid.ox, grid.oy, grid.cell, grid.gx, grid.gy)
        cap = min(links, 4 * n + grid.gx * grid.gy)
        grid = _Grid(lo[0], lo[1], extent[0], extent[1], cell, cap)
        found = grid.sweep(0, n, pos, size)
    if found is None:
        return None
    b, a = found
    return a, b


# ----------------------------------------------------------------------------- generation


def draw_velocities(rng: np.random.Generator, spec: BlockSpec) -> np.ndarray:
    """(count, 2) float64 velocities, px/s, drawn from rng as the module docstring says."""
    n = spec.count
    if spec.speed is not None:
        signs = rng.integers(0, 2, size=(n, 2))
        return (2.0 * signs - 1.0) * float(spec.speed) + 0.0  # speed 0: no negative zeros
    if spec.speed_range is not None:
        a, b = spec.speed_range
        mag = rng.uniform(float(a), float(b), size=n)
        ang = rng.uniform(0.0, 2.0 * math.pi, size=n)
        vel = mag[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)
        if spec.whole:
            vel = np.floor(vel + 0.5)
        return vel + 0.0  # no negative zeros
    if spec.velocity_range is not None:
        lo = np.asarray(spec.velocity_range[0], np.float64)
        hi = np.asarray(spec.velocity_range[1], np.float64)
        if spec.whole:
            ints = rng.integers(
                lo.astype(np.int64), hi.astype(np.int64), size=(n, 2), endpoint=True
            )
            return ints.astype(np.float64)
        return rng.uniform(lo, hi, size=(n, 2)) + 0.0
    return np.zeros((n, 2))


def generate(
    width: int, height: int, fixed_pos, fixed_size, blocks: Sequence[BlockSpec]
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Place and draw every block's boxes; one (pos (count, 2), vel (count, 2)) per block.

    width, height: the world, px. fixed_pos, fixed_size: (m, 2) boxes already there (they must lie
    inside the world and not overlap each other: ValueError otherwise). Positions are whole pixels
    inside the world, overlapping neither the fixed boxes nor each other. Raises PlacementError
    when a block's boxes cannot be placed.
    """
    total = len(fixed_pos) + sum(int(b.count) for b in blocks)
    with lanes.objects(total):
        return _generate(width, height, fixed_pos, fixed_size, blocks)


def _generate(width, height, fixed_pos, fixed_size, blocks):
    fixed_pos = np.asarray(fixed_pos, np.float64).reshape(-1, 2)
    fixed_size = np.asarray(fixed_size, np.float64).reshape(-1, 2)
    m = fixed_pos.shape[0]
    counts = [int(b.count) for b in blocks]
    total = m + sum(counts)

    area = float(np.sum(fixed_size[:, 0] * fixed_size[:, 1]))
    for index, spec in enumerate(blocks):
        w, h = spec.size
        if w > width or h > height:
            raise PlacementError(
                index,
                spec.count,
                spec.size,
                (width, height),
                0,
                0,
                "a box is larger than the world",
            )
        area += float(spec.count) * w * h
        if area > float(width) * float(height):
            raise PlacementError(
                index,
                spec.count,
                spec.size,
                (width, height),
                0,
                0,
                "their area is more than the world's free area",
            )

    sides = [fixed_size.max(axis=1)] if m else []
    sides += [np.full(c, float(max(b.size))) for b, c in zip(blocks, counts, strict=True) if c]
    max_sides = np.concatenate(sides) if sides else np.zeros(0)
    cell = cell_size(width, height, max_sides)
    pos = np.zeros((total, 2))
    size = np.zeros((total, 2))
    pos[:m] = fixed_pos
    size[:m] = fixed_size
    probe = _Grid(0.0, 0.0, width, height, cell, 0)
    links = _count_links(fixed_pos, fixed_size, 0.0, 0.0, cell, probe.gx, probe.gy)
    for spec in blocks:
        w, h = spec.size
        links += spec.count * (math.ceil(w / cell) + 1) * (math.ceil(h / cell) + 1)
    grid = _Grid(0.0, 0.0, width, height, cell, min(links, 4 * total + probe.gx * probe.gy))
    if grid.sweep(0, m, pos, size) is not None:
        raise ValueError("the fixed boxes overlap")

    out = []
    start = m
    for index, spec in enumerate(blocks):
        rng = np.random.default_rng(spec.seed)
        stop = start + spec.count
        w, h = spec.size
        budget = MAX_DRAWS_PER_OBJECT_AVERAGE * spec.count + MAX_DRAWS_PER_OBJECT
        i, fails, draws = start, 0, 0
        high = np.array([width - w + 1, height - h + 1], np.int64)
        while i < stop:
            cands = rng.integers(0, high, size=(POSITION_BATCH, 2))
            k = 0
            while True:
                i, fails, used, status = _place(
                    cands[k:],
                    float(w),
                    float(h),
                    i,
                    stop,
                    fails,
                    MAX_DRAWS_PER_OBJECT,
                    pos,
                    size,
                    grid.cell,
                    grid.gx,
                    grid.gy,
                    grid.head,
                    grid.nxt,
                    grid.item,
                    grid.used,
                )
                k += used
                draws += used
                if status != _FULL:
                    break
                grid.grow()
            why = None
            if status == _STUCK:
                why = f"{MAX_DRAWS_PER_OBJECT} draws in a row found no room"
            elif i < stop and draws >= budget:
                why = f"no room left after {draws} draws"
            if why is not None:
                raise PlacementError(
                    index,
                    spec.count,
                    spec.size,
                    (width, height),
                    i - start,
                    draws,
                    f"placed {i - start}; {why}",
                )
        out.append((pos[start:stop].copy(), draw_velocities(rng, spec)))
        start = stop
    return out
