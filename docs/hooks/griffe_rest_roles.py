"""Griffe extension: the docstrings' Sphinx roles (``:func:`x```) become cross-references.

The docstrings are numpydoc, written for ``help()`` and Sphinx; mkdocstrings renders Markdown,
where ``:func:`name``` would show as raw markup. Each role becomes a link to the object it
names, resolved the way Python resolves the name in the docstring's scope (the module's own
names and its imports): ``:func:`shape_to_target``` in ``specdesign.spec`` links to
``specdesign.spec.shape_to_target``; ``~a.b.c`` shows ``c``. A target in ``specdesign`` or
``loopshaping`` is a required link, so a broken one fails the strict build; a name outside
them (``json.dumps``, ``ValueError``) is shown as code without a link. Doctest blocks outside
an Examples section, and reST literal blocks (``text::`` + an indented block), are fenced as code;
reST simple tables become Markdown tables, and numpydoc "See Also" entries a list of links.
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


def literal_blocks(text: str) -> str:
    """reST literal blocks (a paragraph ending in ``::``, then an indented block) as fenced code;
    Markdown would show the ``::`` and read the block by its indentation alone."""
    lines, out, i = text.split("\n"), [], 0
    while i < len(lines):
        line = lines[i]
        out.append(line)
        i += 1
        if not (line.rstrip().endswith("::") and line.strip() != "::" and i < len(lines) and not lines[i].strip()):
            continue
        base = len(line) - len(line.lstrip())
        j = i + 1
        while j < len(lines) and (not lines[j].strip() or len(lines[j]) - len(lines[j].lstrip()) > base):
            j += 1
        block = lines[i + 1:j]
        while block and not block[-1].strip():
            block.pop()
        if not block:
            continue
        out[-1] = line.rstrip()[:-1]  # "Layout of ``path``::" → "Layout of ``path``:"
        cut = min(len(b) - len(b.lstrip()) for b in block if b.strip())
        pad = " " * base
        out += ["", pad + "```text", *[pad + b[cut:] for b in block], pad + "```", ""]
        i = j
    return "\n".join(out)


BORDER = re.compile(r"\s*=+( +=+)+\s*")


def simple_tables(text: str) -> str:
    """reST simple tables (columns under ``====  ====`` borders) as Markdown tables; a row whose
    first cell is empty continues the row above. Markdown would run the cells into one line."""
    lines, out, i = text.split("\n"), [], 0
    while i < len(lines):
        if not BORDER.fullmatch(lines[i]):
            out.append(lines[i])
            i += 1
            continue
        j = i
        while j < len(lines) and lines[j].strip():
            j += 1
        borders = [k for k in range(i, j) if BORDER.fullmatch(lines[k])]
        if len(borders) < 2:  # a lone rule, not a table: left as written
            out += lines[i:j]
            i = j
            continue
        spans = [(m.start(), m.end()) for m in re.finditer(r"=+", lines[i])]
        starts = [a for a, _ in spans] + [None]

        def cells(line):
            return [line[starts[c]:starts[c + 1]].strip() if starts[c] < len(line) else ""
                    for c in range(len(spans))]

        def rows(a, b):
            got = []
            for line in lines[a + 1:b]:
                row = cells(line)
                if got and not row[0]:
                    got[-1] = [f"{x} {y}".strip() for x, y in zip(got[-1], row)]
                else:
                    got.append(row)
            return got

        if len(borders) >= 3:
            head, body = rows(borders[0], borders[1]), rows(borders[1], borders[2])
        else:
            head, body = [[""] * len(spans)], rows(borders[0], borders[-1])
        head = [" ".join(c).strip() for c in zip(*head)] if head else [""] * len(spans)
        md = lambda row: "| " + " | ".join(c.replace("|", "\\|") for c in row) + " |"
        if out and out[-1].strip():
            out.append("")
        out += [md(head), "|" + "---|" * len(spans), *map(md, body), ""]
        i = j
    return "\n".join(out)


SEE_ALSO_ITEM = re.compile(r"(?P<names>~?[\w.]+(?:\s*,\s*~?[\w.]+)*)\s*(?::\s*(?P<desc>.*))?")


def see_also(obj: griffe.Object, text: str) -> str:
    """A numpydoc "See Also" section (``name : description`` lines) as a list of links; griffe
    would run its entries together into one paragraph."""
    lines, out, i = text.split("\n"), [], 0
    while i < len(lines):
        out.append(lines[i])
        if not (lines[i].strip() == "See Also" and i + 1 < len(lines) and re.fullmatch(r"\s*-{3,}\s*", lines[i + 1])):
            i += 1
            continue
        out.append(lines[i + 1])
        base = len(lines[i]) - len(lines[i].lstrip())
        i += 2
        items = []
        while i < len(lines) and not (i + 1 < len(lines) and lines[i].strip()
                                      and re.fullmatch(r"\s*-{3,}\s*", lines[i + 1])):
            line = lines[i]
            indent = len(line) - len(line.lstrip())
            m = SEE_ALSO_ITEM.fullmatch(line.strip())
            if line.strip() and indent == base and m:
                items.append([m["names"], m["desc"] or ""])
            elif line.strip() and items:
                items[-1][1] = f"{items[-1][1]} {line.strip()}".strip()
            elif line.strip():
                break  # not a See Also list after all: leave the rest as written
            i += 1
        for names, desc in items:
            links = []
            for name in (n.strip() for n in names.split(",")):
                path = _resolve(obj, name.lstrip("~"))
                shown = f"`{name.lstrip('~').rsplit('.', 1)[-1] if name.startswith('~') else name}`"
                links.append(f"[{shown}][{_canonical(obj, path)}]" if path else shown)
            out.append(" " * base + "- " + ", ".join(links) + (f": {desc}" if desc else ""))
        out.append("")
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
                obj.docstring.value = simple_tables(literal_blocks(fence_doctests(_convert(obj, see_also(obj, obj.docstring.value)))))
            stack.extend(m for m in obj.members.values() if not m.is_alias)
