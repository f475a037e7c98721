"""What the runner writes and shows, and where: files written whole, folders swapped in whole.

`options` says which files a run writes, `files` writes them (PNG frames, GIF, event log, final
state, summary), each whole through a temporary name; `filebatch` writes a few files all or
nothing; `folder` keeps one run per output folder (the lock, the staging folder) and `swap` swaps a
staged folder in whole; `budget` decides before the first tick what a run's frames will cost;
`overlay` draws the debug overlays into frames (`rests` follows what rests on what for one of
them); `viewerdata` and `viewerpage` make the run viewer; `progress` is the bar on a terminal;
`escape` makes text safe for a terminal, a page, an XML file or a spreadsheet cell.

It may import `collide2d.engine` (drawing) and `runner.scenario` (what a scenario asks of its
outputs) and nothing else of the runner: the run, the command line and the commands under it
import it, never the other way.
"""
