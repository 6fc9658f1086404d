"""MkDocs hook: equations rendered to MathML when the site is built, so pages need no script or CDN.

Browsers render MathML natively (MathML Core: Chromium 109+, Firefox, Safari), so a page shows
its equations offline with system fonts. Two sources of TeX reach the HTML:

- the Markdown pages and docstrings, through ``pymdownx.arithmatex`` in generic mode:
  ``<span class="arithmatex">\\(…\\)</span>`` and ``<div class="arithmatex">\\[…\\]</div>``;
- the notebooks' Markdown cells (mkdocs-jupyter), which keep ``$…$`` and ``$$…$$`` as text inside
  ``<div class="jp-RenderedMarkdown …">``; only those blocks are searched, never code or outputs.

TeX that ``latex2mathml`` cannot convert fails the build (``mkdocs build --strict`` in the tests),
naming the page and the expression: an equation never silently shows as raw TeX.
"""
from __future__ import annotations

import html
import re

from latex2mathml.converter import convert

_ARITHMATEX = re.compile(
    r'<(?P<tag>span|div) class="arithmatex">\s*(?:\\\((?P<inline>.*?)\\\)|\\\[(?P<block>.*?)\\\])\s*</(?P=tag)>',
    re.S)
_DOLLARS = re.compile(r"(?<![\\$])\$\$(?P<block>.+?)\$\$|(?<![\\$])\$(?P<inline>[^$\n]+?)\$(?!\$)", re.S)
_MARKDOWN_CELL = re.compile(r'<div class="[^"]*\bjp-RenderedMarkdown\b[^"]*"[^>]*>')
_DIV = re.compile(r"<(/?)div\b", re.I)


def to_mathml(tex: str, block: bool, where: str) -> str:
    """One TeX expression (HTML-escaped as it stands in the page) as a MathML element."""
    source = html.unescape(tex).strip()
    try:
        return convert(source, display="block" if block else "inline")
    except Exception as exc:  # latex2mathml raises its own exception classes and plain ones alike
        raise ValueError(f"{where}: cannot render the equation {source!r} as MathML ({exc})") from exc


def _arithmatex(text: str, where: str) -> str:
    return _ARITHMATEX.sub(
        lambda m: to_mathml(m["inline"] if m["inline"] is not None else m["block"], m["block"] is not None, where),
        text)


def _dollars(text: str, where: str) -> str:
    return _DOLLARS.sub(
        lambda m: to_mathml(m["inline"] if m["inline"] is not None else m["block"], m["block"] is not None, where),
        text)


def _cell_end(text: str, start: int) -> int:
    """Index just past the ``</div>`` that closes the div opened before ``start``."""
    depth = 1
    for m in _DIV.finditer(text, start):
        depth += -1 if m[1] else 1
        if depth == 0:
            return m.end()
    return len(text)


def render_math(text: str, where: str = "page") -> str:
    """Every equation of an HTML page as MathML (arithmatex markup and notebook Markdown cells)."""
    text = _arithmatex(text, where)
    out, pos = [], 0
    for m in _MARKDOWN_CELL.finditer(text):
        if m.start() < pos:  # a cell nested in one already converted
            continue
        end = _cell_end(text, m.end())
        out += [text[pos:m.end()], _dollars(text[m.end():end], where)]
        pos = end
    out.append(text[pos:])
    return "".join(out)


def on_post_page(output, page, config):
    return render_math(output, where=page.file.src_uri)
