"""Golden comparison: pure functions that decide whether a run still matches its golden
(docs/goldens.md#comparison-rules).

Inputs are plain data: event objects (the dicts of `engine.events.event_dict`, as events.jsonl holds
them), final states as (n, 4) float64 rows x, y, vx, vy, and frames as (H, W, 3) uint8 RGB. Outputs
are `None` (a match) or a record of the first difference with its message. Nothing here reads or
writes files.

The rules, with τ = the scenario's `time_tolerance` in seconds:

- **Events**: the same number of events, in the same order; each pair of events has the same type,
  ids, side or axis and overlap sizes (`xdiff`, `ydiff`), and times within τ: |Δt| <= τ. With τ = 0
  the tick must match too; with τ > 0 the tick follows the time and is not compared on its own (an
  event moved by less than τ may cross a tick boundary).
- **Final state**: the same number of objects; for each object and axis c in {x, y}, with
  s = max(|v_c golden|, |v_c run|) in px/s, the bound is b = τ·(s + 1): the position may differ by
  b pixels (an event shifted by τ moves an object by at most τ·s) and the velocity by b px/s (τ also
  serves as the relative tolerance of a speed). τ = 0 is exact equality; NaN never matches.
- **Frames**: compared as decoded pixels, first by hash (identical frames stop there), then pixel
  by pixel. A pixel differs when its largest channel difference exceeds `color_threshold` (0 to
  255); a frame fails when more than `max_diff_pixels` pixels differ. Both default to 0, so the
  default is exact. Frames of different sizes fail on their own, before any pixel is compared.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from collide2d.runner.golden.serialize import pixel_sha256

FINAL_COLUMNS = ("x", "y", "vx", "vy")
# The event fields whose values are times (compared within τ) or follow from the time.
_TIME_FIELD = "t"
_TICK_FIELD = "tick"


def event_label(ev: dict) -> str:
    """A short name for an event: `tick 6, pair, 0-1` or `tick 9, wall, 3`."""
    if ev.get("type") == "pair":
        ids = f"{ev.get('a')}-{ev.get('b')}"
    else:
        ids = str(ev.get("id"))
    return f"tick {ev.get('tick')}, {ev.get('type')}, {ids}"


@dataclass(frozen=True)
class EventMismatch:
    """The first event where golden and run part: index is 0-based; expected/actual are None past
    the end of their sequence."""

    index: int
    expected: dict | None
    actual: dict | None
    reason: str
    n_expected: int
    n_actual: int

    def message(self) -> str:
        ref = self.expected if self.expected is not None else self.actual
        lines = [
            f"events: first divergence at event #{self.index + 1} ({event_label(ref)}): "
            f"{self.reason} (golden {self.n_expected} events, run {self.n_actual})",
            f"  expected: {_event_text(self.expected)}",
            f"  actual:   {_event_text(self.actual)}",
        ]
        return "\n".join(lines)


def _event_text(ev: dict | None) -> str:
    return "(none)" if ev is None else json.dumps(ev)


def compare_events(expected: list, actual: list, time_tolerance: float) -> EventMismatch | None:
    """The first event where `actual` leaves `expected` (lists of event dicts), or None.

    time_tolerance: seconds, >= 0 (see the module's rules).
    """
    tol = float(time_tolerance)
    n_e, n_a = len(expected), len(actual)
    for k in range(min(n_e, n_a)):
        reason = _event_difference(expected[k], actual[k], tol)
        if reason:
            return EventMismatch(k, expected[k], actual[k], reason, n_e, n_a)
    if n_e > n_a:
        return EventMismatch(n_a, expected[n_a], None, "missing from the run", n_e, n_a)
    if n_a > n_e:
        return EventMismatch(n_e, None, actual[n_e], "not in the golden", n_e, n_a)
    return None


def _event_difference(e: dict, a: dict, tol: float) -> str:
    """'' when the events match, else what differs."""
    skip = {_TIME_FIELD} if tol == 0 else {_TIME_FIELD, _TICK_FIELD}
    keys = [k for k in e if k not in skip] + [k for k in a if k not in e and k not in skip]
    differ = [k for k in keys if e.get(k) != a.get(k)]
    if differ:
        return ", ".join(differ) + (" differs" if len(differ) == 1 else " differ")
    te, ta = _number(e.get(_TIME_FIELD)), _number(a.get(_TIME_FIELD))
    if te is None or ta is None:
        return "" if e.get(_TIME_FIELD) == a.get(_TIME_FIELD) else "t differs"
    dt = abs(ta - te)
    if not dt <= tol:
        return f"t differs by {dt:.6g} s, past time_tolerance {tol:g} s"
    return ""


def _number(x) -> float | None:
    """`x` as a float when it is a number (not a bool), else None."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return None
    try:
        return float(x)
    except OverflowError:
        return None


@dataclass(frozen=True)
class FinalMismatch:
    """Final states that part: either the object counts differ, or `count` values lie past their
    bound, the first at object `obj`, column `column`."""

    n_expected: int
    n_actual: int
    count: int = 0
    obj: int = -1
    column: str = ""
    expected: float = 0.0
    actual: float = 0.0
    allowed: float = 0.0

    def message(self) -> str:
        if self.n_expected != self.n_actual:
            return f"final state: golden has {self.n_expected} objects, the run {self.n_actual}"
        return (
            f"final state: {self.count} value(s) past tolerance, first object {self.obj} "
            f"{self.column}: expected {self.expected!r}, actual {self.actual!r} "
            f"(allowed ±{self.allowed:g})"
        )


def final_bounds(expected: np.ndarray, actual: np.ndarray, time_tolerance: float) -> np.ndarray:
    """(n, 4) allowed |difference| of x, y, vx, vy: τ·(max(|v_c golden|, |v_c run|) + 1) per axis,
    the same bound for a position (px) and its velocity (px/s). expected, actual: (n, 4) float64."""
    speed = np.maximum(np.abs(expected[:, 2:4]), np.abs(actual[:, 2:4]))
    bound = float(time_tolerance) * (speed + 1.0)
    return np.concatenate([bound, bound], axis=1)


def compare_final(expected, actual, time_tolerance: float) -> FinalMismatch | None:
    """None when the final states match (see the module's rules), else the first difference.

    expected, actual: (n, 4) float64 rows x, y (px), vx, vy (px/s); time_tolerance: seconds.
    """
    e = np.asarray(expected, dtype=np.float64).reshape(-1, 4)
    a = np.asarray(actual, dtype=np.float64).reshape(-1, 4)
    if e.shape != a.shape:
        return FinalMismatch(e.shape[0], a.shape[0])
    # Values near the float64 limits may overflow to inf here: that is a difference, not a warning.
    with np.errstate(over="ignore", invalid="ignore"):
        if float(time_tolerance) == 0.0:
            bad = ~(e == a)
            bounds = np.zeros_like(e)
        else:
            bounds = final_bounds(e, a, time_tolerance)
            bad = ~(np.abs(a - e) <= bounds)
    if not bad.any():
        return None
    i, c = (int(v) for v in np.argwhere(bad)[0])
    return FinalMismatch(
        e.shape[0],
        a.shape[0],
        count=int(bad.sum()),
        obj=i,
        column=FINAL_COLUMNS[c],
        expected=float(e[i, c]),
        actual=float(a[i, c]),
        allowed=float(bounds[i, c]),
    )


@dataclass(frozen=True)
class FrameDiff:
    """How one frame compares.

    expected_size, actual_size  (width, height)
    n_diff      pixels whose largest channel difference exceeds the colour threshold
    n_changed   pixels with any difference at all (n_diff <= n_changed)
    bbox        (x0, y0, x1, y1) inclusive box of the differing pixels, None when there are none
    max_delta   the largest channel difference, 0 to 255
    mask        (H, W) bool, the differing pixels (None when sizes differ or the hashes agreed)
    changed     (H, W) bool, the pixels with any difference (same None cases)
    """

    frame: int
    expected_size: tuple
    actual_size: tuple
    color_threshold: int
    max_diff_pixels: int
    n_diff: int = 0
    n_changed: int = 0
    bbox: tuple | None = None
    max_delta: int = 0
    mask: np.ndarray | None = None
    changed: np.ndarray | None = None

    @property
    def size_mismatch(self) -> bool:
        return self.expected_size != self.actual_size

    @property
    def passed(self) -> bool:
        return not self.size_mismatch and self.n_diff <= self.max_diff_pixels

    def message(self) -> str:
        if self.size_mismatch:
            (we, he), (wa, ha) = self.expected_size, self.actual_size
            return f"frame {self.frame}: size differs: golden {we}x{he}, run {wa}x{ha}"
        text = (
            f"frame {self.frame}: {self.n_diff} pixel(s) differ (colour threshold "
            f"{self.color_threshold}, budget {self.max_diff_pixels})"
        )
        if self.bbox is not None:
            x0, y0, x1, y1 = self.bbox
            text += f" within x {x0}..{x1}, y {y0}..{y1}; largest channel difference "
            text += str(self.max_delta)
        return text


def compare_frame(
    frame: int,
    expected: np.ndarray,
    actual: np.ndarray,
    *,
    color_threshold: int = 0,
    max_diff_pixels: int = 0,
    expected_sha256: str | None = None,
) -> FrameDiff:
    """Compare frame `frame` of the golden (`expected`) and of the run (`actual`), both
    (H, W, 3) uint8 RGB. `expected_sha256` (the manifest's pixel hash) allows the fast path: when
    the run's pixels hash the same, no pixel is compared."""
    e_size = (int(expected.shape[1]), int(expected.shape[0]))
    a_size = (int(actual.shape[1]), int(actual.shape[0]))
    common = dict(
        frame=int(frame),
        expected_size=e_size,
        actual_size=a_size,
        color_threshold=int(color_threshold),
        max_diff_pixels=int(max_diff_pixels),
    )
    if e_size != a_size:
        return FrameDiff(**common)
    if expected_sha256 is not None and pixel_sha256(actual) == expected_sha256:
        return FrameDiff(**common)
    delta = np.abs(expected.astype(np.int16) - actual.astype(np.int16)).max(axis=2)
    changed = delta > 0
    mask = delta > int(color_threshold)
    bbox = None
    if mask.any():
        ys = np.flatnonzero(mask.any(axis=1))
        xs = np.flatnonzero(mask.any(axis=0))
        bbox = (int(xs[0]), int(ys[0]), int(xs[-1]), int(ys[-1]))
    return FrameDiff(
        **common,
        n_diff=int(mask.sum()),
        n_changed=int(changed.sum()),
        bbox=bbox,
        max_delta=int(delta.max()) if delta.size else 0,
        mask=mask,
        changed=changed,
    )
