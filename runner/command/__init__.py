"""The command line and the project's settings: parsing, dispatch and the exit statuses.

`main` parses the command line, runs a command and maps its errors to exit statuses
(`exitcodes`); `options` holds the options shared by the commands that read scenarios, `settings`
a project's `[tool.collide2d]` table; `validate` (`validate`, `schema`), `newproject` (`init`) and
`showconfig` (`config`) are commands; `crashwatch` makes a process killed by a fatal signal say so;
`compilenotice` says on a terminal what compiles and how long it takes; `version` reads the
installed distribution's version.
The commands with a package of their own (`runner.golden`, `runner.stress`, `runner.bench`,
`runner.sweep`) are loaded by name, only when their command runs.

It may import `collide2d.engine`, `runner.lanes`, `runner.compilecost`, `runner.compiling`,
`runner.scenario`, `runner.output`, `runner.interrupt` and `runner.run`: everything below the
command line. Only `python -m collide2d` and the commands with a package of their own import it
(the exit statuses, the shared options, the settings, the version).
"""
