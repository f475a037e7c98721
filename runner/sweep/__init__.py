"""Sweeps (`collide2d sweep`): scenarios over a matrix of settings and seeds, run on Dask.

One module per role: `matrix` (the swept keys and values, each combination's scenario loaded),
`plan` (every combination checked up front, none kept loaded; the runs in sorted order),
`seedcheck` (each run's seed checked in the background, ahead of the runs), `reseed` (a loaded
scenario drawn again for another seed), `sweepfile` (the matrix kept in YAML), `worker` (one
run's figures, on a worker), `cluster` (the Dask client: an embedded LocalCluster or a running
scheduler; tasks run without losing one), `driver` (a sweep's runs on the cluster, a window at a
time), `results` (rows sorted by parameters, the position error against `exact`, results.csv/md
and the plot), `folder` (OUT/sweep/ locked and swapped in whole), `cli` (the subcommand, and
`--workers`/`--scheduler` for `check`), `checks` (`collide2d check` on a cluster). Dask is
imported only when a sweep or a cluster check runs.

It may import what the command line may (`collide2d.engine`, `runner.lanes`, `runner.compiling`,
`runner.scenario`, `runner.output`, `runner.interrupt`, `runner.run`), the command line's shared
parts (`runner.command`: options, settings, exit statuses, the crash watcher) and `runner.bench`
(the position error, the plots); the command line loads it by name, `check` on a cluster too.
"""
