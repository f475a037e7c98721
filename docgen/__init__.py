"""The docs site's generators, run by MkDocs at build time (`mkdocs.yml` names `docgen/hooks.py`).

The reference pages that describe code are made from that code on every build, never edited by
hand: the commands and options from the argument parser (`reference.commands_page`), the scenario
format from its JSON Schema (`reference.schema_page`), the `[tool.collide2d]` keys from the
settings reader and the limits (`reference.settings_page`), the exit statuses from their module
(`reference.exit_statuses_page`). The pictures of the tutorial and of the explanations are made
by running the project's own scenarios (`pictures`). Nothing here is installed with collide2d.
"""
