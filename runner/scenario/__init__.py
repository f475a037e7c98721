"""Reading and checking a scenario file, from its bytes to the arrays a model runs.

`load` joins the rest: a file in, a checked `Scenario` out. The file is read safely and its YAML
composed into a located node tree (`parse`), or a long object list read by column (`fastlane`);
`nodes` reads typed, located values; `physics` the model section and the world's gravity,
restitution and friction, held against the model; `objects` reads listed objects and `generate`
blocks, `generate` places generated boxes, `table` and `tableread` read objects from CSV or `.npy`
tables, and every rule an object must follow, whichever of those it comes from, is written once in
`rules` (names, sizes, masses, speeds, restitution and friction, the paper model's whole numbers,
inside the world, overlap at the start); `sections` reads the output and golden sections, `frames`
the rule of which frames a run draws, `colors` the colours; `limits` holds the bounds on what a file
may ask for, `schema` the JSON Schema, and `assemble` turns the checked objects into arrays.

It may import `collide2d.engine` (the world's arrays, the models' rules) and `runner.lanes` (the
lane of the kernels a load runs) and nothing else of the runner: the run, the writers and the
command line read scenarios, never the other way.
"""
