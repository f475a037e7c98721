"""The report page's event log diff: the golden's and the run's events aligned, as a table.

Input: the two event logs (`serialize.parse_events`) and the scenario's object names. Output: the
rows of a side-by-side table where an event the run inserted or dropped shifts nothing after it.
The logs are aligned as sequences (`difflib.SequenceMatcher` over each event's fields but its
time `t`, so that events within the time tolerance still pair up): matching events share a row,
an event only one side has stands opposite an empty cell, and a changed event stands beside the
one it replaced. The common start and end are set aside before aligning, and at most
`ALIGN_WINDOW` events of each side after the first difference are aligned (the rest is counted),
so that a long log costs little.

Every difference is shown with `CONTEXT` matching rows before and after; longer runs of matching
events are folded into one row that expands (the page's script) when it holds at most what is
left of `EXPAND_ROWS`, else it says how many events it holds and points to the full logs. Objects
are named by their `name` where they have one, with their id (`box (#0)`); every text goes
through the page's HTML escaping.
"""

from __future__ import annotations

import difflib
import html
import json
from dataclasses import dataclass

from collide2d.runner.output.escape import one_line, visible

# Matching rows shown before and after each difference.
CONTEXT = 3
# The most events of each side aligned after the common start.
ALIGN_WINDOW = 5_000
# The most folded rows the page holds, hidden until expanded.
EXPAND_ROWS = 2_000
SAME, CHANGED, DROPPED, INSERTED = "same", "changed", "dropped", "inserted"
# The fields an event is shown by; the others are written after them.
_SHOWN = ("tick", "type", "a", "b", "id")


@dataclass(frozen=True)
class Row:
    """One row: golden event index `i` and run event index `j` (0-based; None for an empty cell)
    and what the row is (SAME, CHANGED, DROPPED: only in the golden, INSERTED: only in the run)."""

    i: int | None
    j: int | None
    kind: str


def _key(ev: dict) -> str:
    return json.dumps({k: v for k, v in ev.items() if k != "t"}, sort_keys=True)


def align(expected: list, actual: list) -> tuple[list[Row], int, int]:
    """The aligned rows of two event logs, and how many events of each side were left out past
    the aligned window (golden, run)."""
    n_e, n_a = len(expected), len(actual)
    lo = 0
    while lo < min(n_e, n_a) and expected[lo] == actual[lo]:
        lo += 1
    tail = 0
    while tail < min(n_e, n_a) - lo and expected[n_e - 1 - tail] == actual[n_a - 1 - tail]:
        tail += 1
    if max(n_e, n_a) - tail > lo + ALIGN_WINDOW:
        tail = 0  # the window ends before the common end: the rest is left to the full logs
    end_e, end_a = min(n_e - tail, lo + ALIGN_WINDOW), min(n_a - tail, lo + ALIGN_WINDOW)
    left_e, left_a = n_e - tail - end_e, n_a - tail - end_a
    rows = [Row(k, k, SAME) for k in range(lo)]
    keys_e = [_key(e) for e in expected[lo:end_e]]
    keys_a = [_key(a) for a in actual[lo:end_a]]
    matcher = difflib.SequenceMatcher(None, keys_e, keys_a, autojunk=False)
    for op, i0, i1, j0, j1 in matcher.get_opcodes():
        i0, i1, j0, j1 = i0 + lo, i1 + lo, j0 + lo, j1 + lo
        if op == "equal":
            rows.extend(
                Row(i, j, SAME if expected[i] == actual[j] else CHANGED)
                for i, j in zip(range(i0, i1), range(j0, j1), strict=True)
            )
            continue
        pairs = min(i1 - i0, j1 - j0) if op == "replace" else 0
        rows.extend(Row(i0 + k, j0 + k, CHANGED) for k in range(pairs))
        rows.extend(Row(i, None, DROPPED) for i in range(i0 + pairs, i1))
        rows.extend(Row(None, j, INSERTED) for j in range(j0 + pairs, j1))
    rows.extend(Row(n_e - tail + k, n_a - tail + k, SAME) for k in range(tail))
    return rows, left_e, left_a


def object_name(i, names) -> str:
    """`box (#0)` for an object named box, `#3` for one without a name (or an id not in
    `names`)."""
    try:
        k = int(i)
    except (TypeError, ValueError):
        return str(i)
    name = names[k] if 0 <= k < len(names) else None
    return f"{one_line(name)} (#{k})" if name else f"#{k}"


def label(ev: dict, names) -> str:
    """`tick 6, pair, box (#0) + ball (#1)` or `tick 9, wall, #3`."""
    if ev.get("type") == "pair":
        who = f"{object_name(ev.get('a'), names)} + {object_name(ev.get('b'), names)}"
    else:
        who = object_name(ev.get("id"), names)
    return f"tick {ev.get('tick')}, {ev.get('type')}, {who}"


def _h(text) -> str:
    return html.escape(visible(str(text)))


def _cell(ev, names) -> str:
    if ev is None:
        return "<i>(none)</i>"
    extra = {k: v for k, v in ev.items() if k not in _SHOWN}
    tail = " ".join(f"{k}={json.dumps(v)}" for k, v in extra.items())
    return f"{_h(label(ev, names))} <small>{_h(tail)}</small>"


def _row(r: Row, expected, actual, names, cls: str, hidden: bool = False) -> str:
    e = expected[r.i] if r.i is not None else None
    a = actual[r.j] if r.j is not None else None
    num = lambda k: "" if k is None else str(k + 1)  # noqa: E731
    attrs = f' class="{cls}"' + (" hidden" if hidden else "")
    return (
        f"<tr{attrs}><td>{num(r.i)}</td><td>{_cell(e, names)}</td><td>{num(r.j)}</td>"
        f"<td>{_cell(a, names)}</td></tr>"
    )


def table(expected: list, actual: list, names, caption: str, links: str = "") -> str:
    """The `<table class="events">` of the aligned logs: differences with their context, folds
    between them; `caption` (HTML) heads it, `links` (HTML) follows a fold too long to expand."""
    rows, left_e, left_a = align(expected, actual)
    differs = [k for k, r in enumerate(rows) if r.kind != SAME]
    shown = set()
    for k in differs:
        shown.update(range(max(0, k - CONTEXT), min(len(rows), k + CONTEXT + 1)))
    counts = {kind: sum(r.kind == kind for r in rows) for kind in (CHANGED, DROPPED, INSERTED)}
    tally = ", ".join(f"{n} {kind}" for kind, n in counts.items() if n)
    out = [
        f'<table class="events"><caption>{caption}{"; " + _h(tally) if tally else ""}</caption>',
        "<tr><th>#</th><th>golden</th><th>#</th><th>this run</th></tr>",
    ]
    budget = EXPAND_ROWS
    k, fold = 0, 0
    first = differs[0] if differs else -1
    while k < len(rows):
        if k in shown:
            kind = "first" if k == first else rows[k].kind
            out.append(_row(rows[k], expected, actual, names, kind))
            k += 1
            continue
        end = k
        while end < len(rows) and end not in shown:
            end += 1
        n = end - k
        where = "before" if k == 0 else ("after" if end == len(rows) else "between")
        text = f"… {n} matching event{'s' if n != 1 else ''} {where}"
        if n <= budget:
            budget -= n
            out.append(
                f'<tr class="gap" data-fold="{fold}"><td colspan="4"><button type="button" '
                f'class="unfold" data-fold="{fold}">{_h(text)} (show)</button></td></tr>'
            )
            out.extend(
                _row(rows[m], expected, actual, names, f"same folded fold-{fold}", hidden=True)
                for m in range(k, end)
            )
            fold += 1
        else:
            out.append(f'<tr class="gap"><td colspan="4">{_h(text)} {links}</td></tr>')
        k = end
    if left_e or left_a:
        out.append(
            f'<tr class="gap"><td colspan="4">… {left_e} more golden and {left_a} more run events '
            f"past the first {ALIGN_WINDOW:,} differing ones {links}</td></tr>"
        )
    out.append("</table>")
    return "\n".join(out)
