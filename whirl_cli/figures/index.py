"""``index.html`` of a figures folder: every figure with its number, caption, the studies and
the commands that made it (pure: text in, text out)."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from html import escape


@dataclass(frozen=True)
class Entry:
    """One figure of the index: its number, caption, note, image file name (None: not
    drawn), the study files behind it, the command that redraws it and, if it was not
    drawn, why."""

    figure: str
    caption: str
    note: str
    image: str | None
    studies: tuple[str, ...]
    command: str
    problem: str = ""


def index_html(entries: list[Entry], title: str, about: Mapping[str, str] | None = None
               ) -> str:
    """The page: a heading, what made the figures (``about``: name -> value, e.g. whirl's
    version, commit and engine), a contents list of thumbnails each linked to its section,
    then one section per entry in figure-number order (its image linked to full size)."""
    ordered = sorted(entries, key=lambda e: figure_order(e.figure))
    sections = "\n".join(_section(e) for e in ordered)
    made = "".join(f"<li>{escape(k)}: <code>{escape(v)}</code></li>"
                   for k, v in (about or {}).items())
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
</style>
</head>
<body>
<h1>{escape(title)}</h1>
{made}
<ul class="contents">
{contents}
</ul>
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
            f"<p>Studies: {studies}<br>Redraw: <code>{escape(entry.command)}</code></p>\n"
            "</section>")
