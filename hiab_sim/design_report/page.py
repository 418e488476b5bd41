"""HTML building blocks of the design report: escaped text, tables, embedded figures, the page shell.

Everything the page needs is inside it: the style sheet inline, the figures as base64 ``data:`` URIs,
no script, font or link to the network, so the file opens the same anywhere and prints as it shows.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Iterable, Sequence
from pathlib import Path

CSS = """
body { font-family: "DejaVu Sans", Arial, sans-serif; max-width: 60rem; margin: 2rem auto; padding: 0 1rem;
       color: #1b1b1b; line-height: 1.45; }
h1 { font-size: 1.7rem; border-bottom: 2px solid #009e73; padding-bottom: .3rem; }
h2 { font-size: 1.25rem; margin-top: 2rem; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: .6rem 0 1rem; font-size: .9rem; }
th, td { border: 1px solid #bbb; padding: .25rem .55rem; text-align: left; vertical-align: top; }
th { background: #eef5f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.answer { background: #eef8f4; border-left: 4px solid #009e73; padding: .6rem 1rem; }
.note { color: #555; font-size: .88rem; }
figure { margin: 1rem 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: .85rem; color: #444; }
@media print { body { margin: 0; max-width: none; } h2 { break-after: avoid; } figure, table { break-inside: avoid; } }
"""


def esc(text: object) -> str:
    """HTML-escaped text."""
    return html.escape(str(text))


def num(value: float | None, fmt: str = ".1f", unit: str = "") -> str:
    """A formatted number with its unit, or an en dash for a missing value."""
    if value is None:
        return "–"
    return f"{value:{fmt}}" + (f" {unit}" if unit else "")


def table(header: Sequence[str], rows: Iterable[Sequence[object]], numeric: Sequence[int] = ()) -> str:
    """An HTML table; the columns in ``numeric`` are right-aligned."""
    head = "".join(f"<th>{esc(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = "".join(
            f'<td class="num">{esc(v)}</td>' if i in numeric else f"<td>{esc(v)}</td>" for i, v in enumerate(row)
        )
        body.append(f"<tr>{cells}</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def figure(path: Path, caption: str) -> str:
    """The PNG at ``path`` embedded as a data URI, with its caption (empty when the file does not exist)."""
    if not path.is_file():
        return ""
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (
        f'<figure><img src="data:image/png;base64,{data}" alt="{esc(caption)}">'
        f"<figcaption>{esc(caption)}</figcaption></figure>"
    )


def paragraph(text: str, css: str = "") -> str:
    """A paragraph of escaped text."""
    return f'<p class="{css}">{esc(text)}</p>' if css else f"<p>{esc(text)}</p>"


def section(title: str, *parts: str) -> str:
    """A titled section of already-built HTML parts (empty parts are dropped)."""
    kept = "".join(p for p in parts if p)
    return f"<section><h2>{esc(title)}</h2>{kept}</section>" if kept else ""


def document(title: str, body: Sequence[str]) -> str:
    """The whole page: UTF-8, inline style, no external reference."""
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{esc(title)}</title><style>{CSS}</style></head>"
        f"<body><h1>{esc(title)}</h1>{''.join(b for b in body if b)}</body></html>\n"
    )
