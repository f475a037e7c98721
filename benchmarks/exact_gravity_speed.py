"""The exact model's events per second under gravity against the same scene without it.

The scenes and timings of `collide2d bench --part gravity` (runner/bench/gravity/exact.py),
with the size, ticks and rounds chosen here: a gas of N boxes (default 10,000) run for the same
ticks without gravity and with 400 px/s², in turns, each after a tick that loads the kernels; then
1,000 balls of restitution 0.9 dropped onto the floor. Prints the median events per second of
each and the ratio under gravity / without. Usage:

    python benchmarks/exact_gravity_speed.py [--n 10000] [--ticks 600] [--rounds 3]
"""

from __future__ import annotations

import argparse

from collide2d.runner.bench.gravity import exact


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--ticks", type=int, default=600)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    exact.gravity_rate(exact.gas(100), exact.GAS_G, 2)  # compile both paths once
    flat, falling = exact.gas_rates(args.n, args.ticks, args.rounds)
    print(f"{args.n:,} boxes, {args.ticks} ticks, medians of {args.rounds} rounds:")
    print(f"  without gravity  {flat:,.0f} events/s")
    print(f"  gravity {exact.GAS_G:g}      {falling:,.0f} events/s   ratio {falling / flat:.3f}")
    rate, events, seconds = exact.gravity_rate(exact.balls(1000), exact.BALLS_G, 300)
    print(f"1,000 balls, e 0.9, dropped: {events:,} events in {seconds:.3f} s ({rate:,.0f}/s)")


if __name__ == "__main__":
    main()
