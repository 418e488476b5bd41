"""mkdocs hooks: the generated reference pages and the "Models and checks" section (see mkdocs.yml).

The reference pages are written from the code at build time, never by hand: the file formats from the
loaders' field specs, ``result.json`` / ``trajectory.npz`` from the result types, the CLI from the
argparse parsers and the test catalogue from the tests' docstrings.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files

from hiab_sim.docs_site.check_catalogue import check_catalogue_markdown
from hiab_sim.docs_site.cli_reference import cli_markdown
from hiab_sim.docs_site.file_formats import file_formats_markdown
from hiab_sim.docs_site.nav import with_model_pages
from hiab_sim.docs_site.result_schema import result_schema_markdown

ROOT = Path(__file__).resolve().parents[1]


def on_config(config: Any) -> Any:
    """Add the "Models and checks" section for the top-level pages the nav does not name."""
    config["nav"] = with_model_pages(config["nav"], Path(config["docs_dir"]))
    return config


def on_files(files: Files, config: Any) -> Files:
    """Add the generated reference pages."""
    pages = {
        "reference/cli.md": cli_markdown(),
        "reference/file-formats.md": file_formats_markdown(),
        "reference/results.md": result_schema_markdown(),
        "reference/tests.md": check_catalogue_markdown(ROOT / "tests"),
    }
    for uri, text in pages.items():
        files.append(File.generated(config, uri, content=text))
    return files
