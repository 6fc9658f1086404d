"""Griffe extension: the docstrings' Sphinx roles (``:func:`x```) become cross-references.

The docstrings are numpydoc, written for ``help()`` and Sphinx; mkdocstrings renders Markdown,
where ``:func:`name``` would show as raw markup. Each role becomes a link to the object it
names, resolved the way Python resolves the name in the docstring's scope (the module's own
names and its imports): ``:func:`shape_to_target``` in ``specdesign.spec`` links to
``specdesign.spec.shape_to_target``; ``~a.b.c`` shows ``c``. A target in ``specdesign`` or
``loopshaping`` is a required link, so a broken one fails the strict build; a name outside
them (``json.dumps``, ``ValueError``) is shown as code without a link. Doctest blocks outside
an Examples section are fenced as code (Markdown would read ``>>>`` as block quotes).
"""
from __future__ import annotations

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?P<role>func|class|meth|attr|data|mod|obj|exc|const):`(?P<target>[^`]+)`")
OURS = ("specdesign", "loopshaping")


def _resolve(obj: griffe.Object, target: str) -> str | None:
    """The full path of ``target`` in the scope of ``obj``, or None outside our packages."""
    if target.split(".")[0] in OURS:
        return target
    head, _, rest = target.partition(".")
    scope = obj
    while scope is not None:
        try:
            path = scope.resolve(head)
        except (griffe.NameResolutionError, AttributeError, KeyError):
            scope = scope.parent
            continue
        path = f"{path}.{rest}" if rest else path
        return path if path.split(".")[0] in OURS else None
    return None


def _canonical(obj: griffe.Object, path: str) -> str:
    """The path where the object is documented: a name re-exported by a package (an alias,
    ``specdesign.turbine.TurbineModel.linearize``) becomes its defining module's path."""
    try:
        return obj.modules_collection[path].canonical_path
    except (KeyError, ValueError, AttributeError, griffe.AliasResolutionError, griffe.CyclicAliasError):
        return path  # not loaded (the other package) or not found: left as written, checked by autorefs


def fence_doctests(text: str) -> str:
    """Doctest blocks outside an Examples section as fenced ``pycon`` code.

    Griffe reads ``>>>`` blocks as code only in an Examples section; elsewhere (a module's
    "Typical use:" paragraph) Markdown would show them as nested block quotes.
    """
    lines, out, section, i = text.split("\n"), [], "", 0
    while i < len(lines):
        line = lines[i]
        if i + 1 < len(lines) and line.strip() and re.fullmatch(r"\s*-{3,}\s*", lines[i + 1]):
            section = line.strip()
        if line.lstrip().startswith(">>>") and section not in ("Examples", "Example"):
            indent = line[: len(line) - len(line.lstrip())]
            block = []
            while i < len(lines) and lines[i].strip():
                block.append(lines[i])
                i += 1
            out += [f"{indent}```pycon", *block, f"{indent}```"]
            continue
        out.append(line)
        i += 1
    return "\n".join(out)


def _convert(obj: griffe.Object, text: str) -> str:
    def link(m: re.Match) -> str:
        target = m["target"].strip()
        shown = target.lstrip("~")
        if target.startswith("~"):
            shown = shown.rsplit(".", 1)[-1]
        path = _resolve(obj, target.lstrip("~"))
        if path is not None:
            path = _canonical(obj, path)
        if m["role"] in ("func", "meth"):
            shown += "()"
        code = f"`{shown}`"
        return f"[{code}][{path}]" if path else code
    return ROLE.sub(link, text)


class RestRoles(griffe.Extension):
    """Rewrite the roles of every docstring of a package once it is loaded."""

    def on_package(self, *, pkg: griffe.Module, **kwargs) -> None:  # noqa: D102
        stack = [pkg]
        while stack:
            obj = stack.pop()
            if obj.docstring is not None:
                obj.docstring.value = fence_doctests(_convert(obj, obj.docstring.value))
            stack.extend(m for m in obj.members.values() if not m.is_alias)
