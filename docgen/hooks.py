"""MkDocs hooks (`hooks:` in mkdocs.yml): add the generated pages and pictures to every build.

`on_files` hands MkDocs, as files of their own that never exist in docs/, the reference pages
made from the code (docgen/reference.py), the pictures made by running the project's scenarios
(docgen/pictures.py) and the changelog (the repository's CHANGELOG.md, one copy). The navigation
in mkdocs.yml names them like any page, so `mkdocs build --strict` fails when one goes missing.
"""

from __future__ import annotations

import sys
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # MkDocs loads this file by its path: let it import its siblings
    sys.path.insert(0, str(ROOT))

from docgen import pictures, reference  # noqa: E402


def generated_pages() -> dict[str, str]:
    """Every generated page, by its path in the site's sources."""
    # the changelog's links lead into docs/ from the repository's top; on the site it sits there
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8").replace("](docs/", "](")
    return {
        "reference/commands.md": reference.commands_page(),
        "reference/schema.md": reference.schema_page(),
        "reference/settings.md": reference.settings_page(),
        "reference/exit-statuses.md": reference.exit_statuses_page(),
        "changelog.md": changelog,
    }


def on_files(files, config):
    made = {**generated_pages(), **pictures.paper_figures(), **pictures.tutorial_pictures()}
    for path, content in made.items():
        if files.get_file_from_path(path) is not None:
            raise ValueError(f"docs/{path} is generated at build time: remove the file")
        files.append(File.generated(config, path, content=content))
    return files
