"""The command-line reference, generated from the argparse parsers of :mod:`hiab_sim.cli`."""

from __future__ import annotations

import argparse

from hiab_sim.docs_site.markdown import cell, table


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _argument_rows(parser: argparse.ArgumentParser) -> list[tuple[str, str, str]]:
    rows = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction) or action.help == argparse.SUPPRESS:
            continue
        if action.option_strings:
            name = ", ".join(f"`{o}`" for o in action.option_strings)
            if action.nargs != 0:
                name += f" `{action.metavar or action.dest.upper()}`"
        else:
            name = f"`{action.metavar or action.dest}`"
        choices = "" if action.choices is None else " (one of " + ", ".join(f"`{c}`" for c in action.choices) + ")"
        default = action.default
        shown = "" if default in (None, False, argparse.SUPPRESS) or action.nargs == 0 else f"`{default}`"
        rows.append((name, (action.help or "") + choices, shown))
    return rows


def cli_markdown(parser: argparse.ArgumentParser | None = None) -> str:
    """One section per subcommand: usage, description, arguments (help, choices, default), epilog."""
    if parser is None:
        from hiab_sim.cli import build_parser

        parser = build_parser()
    parts = [
        "# Command line",
        "",
        "Generated from the argparse parsers of `hiab_sim.cli` (one module per subcommand). Every command "
        "prints bad input on one line and exits with status 2, without a traceback and without a "
        "half-written file; a solver failure exits 1, a study with no feasible point within its bounds 3.",
        "",
        f"```text\n{parser.format_usage().strip()}\n```",
    ]
    for name, sub in _subparsers(parser).items():
        parts += ["", f"## `hiab-sim {name}`", "", f"```text\n{sub.format_usage().strip()}\n```", ""]
        if sub.description:
            parts += [cell(sub.description), ""]
        rows = _argument_rows(sub)
        if rows:
            parts.append(table(("argument", "meaning", "default"), rows))
        if sub.epilog:
            parts += ["", cell(sub.epilog)]
    return "\n".join(parts) + "\n"
