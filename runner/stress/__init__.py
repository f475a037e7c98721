"""The `stress` command: hostile scenes run under every model, invariants checked every tick.

Input: the scene list built in code (`scenes.scenes(quick)`), each a `Scene` of engine arrays (a
`WorldSpec`, `Bodies`, a tick count, the models it applies to). Output: one `CaseResult` per scene
and model with its figures (ticks run, events, largest energy and momentum drift, largest
penetration, run time) and a verdict, written as `OUT/stress/report.md` and `report.json` (each
through a temporary name and a rename, runner.output.files) and summed up on stdout; the exit status
is 1 when an invariant broke, else 0.

One module per concept:
- `scenes`: the hostile scenes (`Scene`, `scenes(quick)`);
- `checks`: the bounds and the per-tick checks (`tick_figures`, `exact_round`, `Checker`);
- `cases`: one scene under one model, checked tick by tick and run again for the same bytes
  (`run_case`, `run_suite`, `CaseResult`, the verdicts);
- `report`: the console lines and the report files;
- `cli`: the subcommand; it loads the other modules only when `collide2d stress` runs.

Each case runs its model one tick at a time and after every tick checks, with one small numba
kernel (`checks.tick_figures`) and the sort-and-sweep kernel `engine.invariants.max_penetration`:
- the state is finite and every object lies inside the world (within `INSIDE_TOL_PX`), static
  objects have not moved;
- energy and momentum within the model's bound: `exact` keeps kinetic energy to `EXACT_ENERGY_TOL`
  (relative) and, in scenes without static objects, momentum through every tick without a wall event
  to `EXACT_MOMENTUM_TOL`; `stepped` to the looser `STEPPED_*` bounds; `paper` keeps every velocity
  component's size exactly (only its sign changes);
- under `exact`, no two boxes overlap by more than `PENETRATION_TOL_PX` after a tick, and the
  movers of a scene with a `room` (a ring of static walls) stay in it (nothing tunnels);
- positions round to pixels exactly as `floor(x + 1/2)` (engine.picture.raster.round_positions,
checked
  against exact arithmetic);
- no hang: a runaway stops with a clear error (the exact model's event cap, the stepped model's fold
  limit); a scene that expects one counts it as a pass, any other scene as a failure;
- the same bytes twice: the case runs again in one call per `CHUNK_TICKS` and must end with the same
  positions, velocities and event records, byte for byte.

`--quick` runs the same scenes shorter and smaller; it fits in well under a minute.

It may import what the command line may (`collide2d.engine`, `runner.lanes`, `runner.compiling`,
`runner.scenario`, `runner.output`, `runner.run`) and the command line's shared parts
(`runner.command`: exit statuses); the command line loads it by name.
"""
