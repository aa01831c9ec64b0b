"""``index.html`` of a figures folder: every figure with its number, caption, the studies and
sheet that made it, the thesis's numbers beside whirl's, and the command that redraws them
(pure: text in, text out)."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from html import escape
from typing import NamedTuple


@dataclass(frozen=True)
class Entry:
    """One figure of the index: its number, caption, note, image file name (None: not
    drawn), the study files behind it, its sheet file and, if it was not drawn, why."""

    figure: str
    caption: str
    note: str
    image: str | None
    studies: tuple[str, ...]
    sheet: str
    problem: str = ""


class Comparison(NamedTuple):
    """One row of the table of numbers: a figure's quantity as the thesis gives it (``value``,
    or a range ``between``; neither: not recovered) and whirl's (None: not found, ``problem``
    says why), its unit, the point type compared, the relative difference (None: no thesis
    value) and where whirl's is stored (study: branch)."""

    figure: str
    name: str
    value: float | None
    between: tuple[float, float] | None
    unit: str
    point: str
    whirl: float | None = None
    difference: float | None = None
    where: str = ""
    problem: str = ""


def index_html(entries: list[Entry], title: str, about: Mapping[str, str] | None = None,
               numbers: tuple[Comparison, ...] = (), redraw: str = "") -> str:
    """The page: a heading, what made the figures (``about``: name -> value, e.g. whirl's
    version, commit and engine) and the command that redraws them (``redraw``), a contents
    list of thumbnails each linked to its section, the table of ``numbers`` (in figure
    order), then one section per entry in figure-number order (its image linked to full
    size)."""
    ordered = sorted(entries, key=lambda e: figure_order(e.figure))
    sections = "\n".join(_section(e) for e in ordered)
    shown = {**(about or {}), **({"redraw": redraw} if redraw else {})}
    made = "".join(f"<li>{escape(k)}: <code>{escape(v)}</code></li>"
                   for k, v in shown.items())
    made = f"<ul class=\"about\">{made}</ul>" if made else ""
    contents = "\n".join(_thumbnail(e) for e in ordered)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{escape(title)}</title>
<style>
body {{ font-family: sans-serif; max-width: 72em; margin: 2em auto; padding: 0 1em; }}
section {{ border-top: 1px solid #ccc; padding: 1em 0; }}
img {{ max-width: 100%; }}
code {{ background: #f4f4f4; padding: 0 0.3em; }}
.problem {{ color: #b00; }}
.contents {{ display: flex; flex-wrap: wrap; gap: 0.6em; list-style: none; padding: 0; }}
.contents li {{ width: 10em; text-align: center; font-size: small; }}
.contents img {{ width: 10em; border: 1px solid #ccc; }}
table.numbers {{ border-collapse: collapse; }}
.numbers th, .numbers td {{ border-bottom: 1px solid #ddd; padding: 0.2em 0.6em; }}
.numbers td.n {{ text-align: right; font-variant-numeric: tabular-nums; }}
</style>
</head>
<body>
<h1>{escape(title)}</h1>
{made}
<ul class="contents">
{contents}
</ul>
{numbers_table(numbers)}
{sections}
</body>
</html>
"""


def figure_order(figure: str) -> tuple:
    """Sort key of a figure number: "3.3" before "3.12" before "3.12a" (each part by its
    number, then its letter)."""
    parts = [re.fullmatch(r"(\d*)(.*)", part).groups() for part in figure.split(".")]
    return tuple((int(digits) if digits else -1, rest) for digits, rest in parts)


def _thumbnail(entry: Entry) -> str:
    """One item of the contents: the figure's thumbnail (or its number if not drawn), linked
    to its section."""
    shown = (f'<img src="{escape(entry.image)}" alt="figure {escape(entry.figure)}"><br>'
             if entry.image else "")
    return (f'<li><a href="#fig{escape(entry.figure)}">{shown}Figure {escape(entry.figure)}'
            "</a></li>")


def _section(entry: Entry) -> str:
    studies = ", ".join(f"<code>{escape(s)}</code>" for s in entry.studies)
    body = (f'<a href="{escape(entry.image)}"><img src="{escape(entry.image)}" '
            f'alt="figure {escape(entry.figure)}"></a>'
            if entry.image else f'<p class="problem">not drawn: {escape(entry.problem)}</p>')
    note = (f"<p><em>Differs from the thesis: {escape(entry.note)}</em></p>" if entry.note
            else "")
    return (f'<section id="fig{escape(entry.figure)}">\n<h2>Figure {escape(entry.figure)}</h2>\n'
            f"<p>{escape(entry.caption)}</p>\n{note}\n{body}\n"
            f"<p>Studies: {studies}<br>Sheet: <code>{escape(entry.sheet)}</code></p>\n"
            "</section>")


def numbers_table(rows: tuple[Comparison, ...]) -> str:
    """The table of the thesis's numbers beside whirl's, in figure order ("" for no rows):
    each whirl value also exact in its cell's ``data-value``."""
    if not rows:
        return ""
    body = "\n".join(_row(r) for r in sorted(rows, key=lambda r: figure_order(r.figure)))
    return ('<h2 id="numbers">The thesis\'s numbers and whirl\'s</h2>\n<table class="numbers">\n'
            "<tr><th>figure</th><th>quantity</th><th>point</th><th>thesis</th><th>whirl</th>"
            "<th>unit</th><th>difference</th><th>whirl's from</th></tr>\n"
            f"{body}\n</table>")


def _row(row: Comparison) -> str:
    if row.between is not None:
        thesis = f"{row.between[0]:g} to {row.between[1]:g}"
    else:
        thesis = "not recovered" if row.value is None else f"{row.value:g}"
    if row.whirl is None:
        whirl = f'<td class="problem">{escape(row.problem)}</td>'
    else:
        whirl = f'<td class="n" data-value="{row.whirl!r}">{row.whirl:.4g}</td>'
    difference = ("" if row.difference is None else
                  "within" if row.between is not None and row.difference == 0 else
                  f"{100 * row.difference:+.1f} %")
    cells = [f'<td><a href="#fig{escape(row.figure)}">{escape(row.figure)}</a></td>',
             f"<td>{escape(row.name)}</td>", f"<td>{escape(row.point)}</td>",
             f'<td class="n">{escape(thesis)}</td>', whirl, f"<td>{escape(row.unit)}</td>",
             f'<td class="n">{escape(difference)}</td>', f"<td>{escape(row.where)}</td>"]
    return "<tr>" + "".join(cells) + "</tr>"
