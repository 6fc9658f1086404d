"""MkDocs hook: notebook pages that ask nothing of the network.

nbconvert's template (through mkdocs-jupyter) appends, on every page whose notebook saved
widget state, a script that loads the Jupyter widgets' HTML manager from unpkg.com to redraw
the sliders. Without a kernel they do nothing, and offline the request fails; the page keeps
the figures the notebook saved. The loader is removed here, whole, and a build fails if a page
still names a CDN script.
"""
from __future__ import annotations

import re

_WIDGET_LOADER = re.compile(r"<script>\s*\(function\(\) \{\s*function addWidgetsRenderer\(\).*?</script>", re.S)


def strip_widget_loader(html: str) -> str:
    """``html`` without nbconvert's widget-manager loader (the one script that reaches a CDN)."""
    out = _WIDGET_LOADER.sub("", html)
    if "unpkg.com" in out:
        raise ValueError("a page still loads a script from unpkg.com: the widget loader changed shape")
    return out


def on_post_page(output, page, config):
    return strip_widget_loader(output)
