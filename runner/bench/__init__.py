"""The `bench` command: how fast each model runs, and how far from the reference it lands.

Input: the command line (`collide2d bench [--quick] [--peers] [--part P] [--n N] [--out DIR]`),
the benchmark scenarios `scenarios/bench_*.yaml` and the standard scene built here. Output, under
`OUT/bench/` (each file written whole through a temporary name): `bench.csv` (one row per
measurement, the columns of `report.COLUMNS`), `bench.md` (the same as tables, with the headline
ratios first) and, when matplotlib is installed (the optional `plot` extra), `scaling.png` and
`runtime_vs_error.png`. Progress goes to stderr unless `--quiet`; the headline table to stdout.

The parts, each selectable with `--part`:
- scaling: the standard scene (N boxes 10x10 px covering 5 % of a 4:3 world, speeds 10-100 px/s in
  random directions, 60 fps, seed 1) under each model at each N: steps/s measured through
  `collide2d run` as a user runs it, in a subprocess, start-up excluded by subtracting a 1-tick run
  (`--in-process` times `runner.run.drive` instead, the same way); body-steps/s; events/s (events
  per tick of a logged run times steps/s); the time per step of each stage (move, broad phase,
  narrow phase, response, from `Model.profile`, where the model has stages) and the time to
  render one frame.
- error: each benchmark scenario under each model at a full ladder (fps 1 to 240; stepped also at
  1 to 64 substeps), each run on the bodies its model loads and against the exact model on those
  bodies: position error at 1 s and 10 s (quick: 1 s and 2 s), the time the pair events first
  part from the reference's, missed collisions, collision-count error, energy drift, deepest
  penetration and run time; a Pareto chart per scene. Then how sensitive each scene is (the exact
  model against itself with velocities nudged by 1e-9 px/s) and a scan of glancing contacts of two
  boxes at one substep (the largest speed that tunnels).
- peers: with `--peers` and pymunk installed (the optional `bench` extra), pymunk steps the same
  standard scene in the same run, timed in turn with the stepped model's scaling runs (one pymunk
  run in each of their rounds, `peers.PymunkTimer`), and the stepped model's ratio to it is
  printed.
- skips: for each thing a run skips when a scene does not need it, the same work with and
  without the skip, and the saving (time without / time with), with its range.
- targets: the paper's section IV demo headless (ticks/s through the model's `advance`) and the
  wall time of `collide2d run` on a small scenario once kernels are cached.
- paper, exact, raster (only when asked for with `--part`): the paper model on the section IV demo
  headless with and without the event log and through `runner.run.drive`; the exact model's
  events/s on a two-body chain and on the standard scene; `Renderer.draw` frames/s, a GIF's and a
  PNG frame's time on the section IV demo's boxes.
- jit (only with `--part jit`): `collide2d run` under `--jit on`, `off` and `auto`, each in a fresh
  process from an empty kernel cache, on the bundled scenarios, the bench's scenes and scenes of
  10 to 5,000 bodies over 10 to 100,000 ticks: wall times and `auto` over the faster lane.
- gravity (only with `--part gravity`): a settling pile under the stepped model against pymunk, the
  closed forms of a bounce and a slide for the stepped and exact models and pymunk, and the exact
  model's events/s under gravity (the package `gravity`).

One module per concept: `scenes` (the standard scene and where the benchmark scenarios are),
`timing` (how a run is timed), one module per part (`scaling`, `peers`, `error`, `skips`,
`targets` (and jit), `paper`, `exact`, `raster`, `stages`, `load`) and the package `gravity`,
`goals` (the figures held to), `report` (bench.csv and bench.md),
`plots` (the PNG plots) and `cli` (the subcommand; it loads the parts only when `collide2d bench`
runs).

Timings that are compared (error, skips, targets) go through `timing.measure`: calibrated so
that each measure lasts at least 0.5 s, medians of 5 interleaved repeats (A/B/A) with min-max,
noisy past a 20 % spread; the headline rows give each target and whether it was met. Quote ratios
from one run: absolute times move with the machine and its load. `--quick` shrinks every part
(small N, short runs and measures, in-process timing) to seconds, for tests.

It may import what the command line may (`collide2d.engine`, `runner.lanes`, `runner.compiling`,
`runner.scenario`, `runner.output`, `runner.run`) and the command line's shared parts
(`runner.command`: options, exit statuses); the command line loads it by name.
"""
