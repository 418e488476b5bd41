"""The documentation site: the nav takes the model pages that exist, the CLI reference is complete, the README short."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import yaml

from hiab_sim.cli import build_parser
from hiab_sim.docs_site.cli_reference import cli_markdown
from hiab_sim.docs_site.nav import SECTION, nav_pages, with_model_pages

ROOT = Path(__file__).resolve().parents[1]


def _nav() -> list[object]:
    config = yaml.load((ROOT / "mkdocs.yml").read_text(), Loader=yaml.BaseLoader)  # no mkdocs tags in the file
    return list(config["nav"])


def test_every_page_of_the_nav_exists_or_is_generated() -> None:
    """Each page mkdocs.yml names is a file of docs/ or one of the hook's generated reference pages."""
    generated = {"reference/cli.md", "reference/file-formats.md", "reference/results.md", "reference/tests.md"}
    for page in nav_pages(_nav()):
        assert (ROOT / "docs" / page).is_file() or page in generated, page


def test_model_pages_join_the_nav_when_present_and_leave_no_trace_when_absent(tmp_path: Path) -> None:
    """Top-level pages the nav does not name go under one section, model pages first in their order."""
    nav = _nav()
    for name in ("index.md", "validation.md", "design-notes.md", "getting-started.md"):
        (tmp_path / name).write_text(f"# {name}\n")
    assert with_model_pages(nav, tmp_path) == nav
    (tmp_path / "zeta.md").write_text("# Zeta checks\n")
    (tmp_path / "plant.md").write_text("# The plant\n")
    (tmp_path / "machine.md").write_text("intro without a heading\n")
    (tmp_path / "machines").mkdir()
    (tmp_path / "machines" / "excavator.md").write_text("# The excavator\n")
    section = next(item for item in with_model_pages(nav, tmp_path) if isinstance(item, dict) and SECTION in item)
    assert section[SECTION] == [
        {"Machine": "machine.md"},
        {"The plant": "plant.md"},
        {"Zeta checks": "zeta.md"},
        {"The excavator": "machines/excavator.md"},
    ]


def test_cli_reference_names_every_subcommand_and_option() -> None:
    """The generated CLI page has a section per subcommand and every option string of its parser."""
    page = cli_markdown()
    parser = build_parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, sub in subparsers.choices.items():
        assert f"## `hiab-sim {name}`" in page
        for action in sub._actions:
            for option in action.option_strings:
                if option not in ("-h", "--help"):
                    assert f"`{option}`" in page, (name, option)


def test_readme_is_short_and_keeps_the_two_setup_commands() -> None:
    """README.md is under 150 lines and its set-up commands are exactly scripts/main.sh and scripts/test.sh."""
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) < 150
    blocks = re.findall(r"```bash\n(.*?)```", readme, flags=re.S)
    assert "bash scripts/main.sh\n" in blocks and "bash scripts/test.sh\n" in blocks
    assert (ROOT / ".ci" / "run").read_text().strip().endswith("bash scripts/test.sh")


def test_readme_links_resolve() -> None:
    """Every relative link of README.md points to a file of the repository."""
    readme = (ROOT / "README.md").read_text()
    for target in re.findall(r"\]\(([^)#]+)\)", readme):
        if not target.startswith("http"):
            assert (ROOT / target).exists(), target
