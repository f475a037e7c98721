"""Reading and checking a scenario file: safe YAML, the fast lane, typed nodes, objects,
generate blocks, tables, the output and golden sections, frame rules, colours, limits, the
JSON Schema, and the assembly into arrays.

It may import `collide2d.engine` (the world's arrays, the models' rules) and nothing else of the
runner: the command line, the run and the writers read scenarios, never the other way."""
