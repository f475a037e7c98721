"""The gravity part of `collide2d bench` (`--part gravity`): the stepped model's settling path
against pymunk under gravity (`pile`), the stepped and exact models and pymunk against the closed
forms of PHYSICS.md (`closed`), and the exact model's events per second under gravity (`exact`).
"""

from __future__ import annotations


def part(quick: bool, echo) -> list[dict]:
    """The part's rows: the piles (1,000; and 10,000 unless quick), the closed forms, then the
    exact model's."""
    from collide2d.runner.bench.gravity import closed, exact, pile

    rows: list[dict] = []
    for n in (1000,) if quick else (1000, 10_000):
        rows += pile.timings(n, echo)
    return rows + closed.closed_forms(echo) + exact.gravity(quick, echo)
