"""Sweeps (`collide2d sweep`): scenarios over a matrix of settings and seeds, run on Dask.

One module per role: `matrix` (the swept keys and seeds to runs, each scenario loaded and checked
up front), `sweepfile` (the matrix kept in YAML), `runs` (one run's figures, on a worker),
`cluster` (the Dask client: an embedded LocalCluster or a running scheduler; tasks run without
losing one), `driver` (a sweep's runs on the cluster), `results` (rows sorted by parameters,
the position error against `exact`, results.csv/md and the plot), `cli` (the subcommand, and
`--workers`/`--scheduler` for `check`), `checks` (`collide2d check` on a cluster). Dask is
imported only when a sweep or a cluster check runs.
"""
