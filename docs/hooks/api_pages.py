"""MkDocs hook: one API-reference page per public module of ``specdesign`` and ``loopshaping``.

The pages are generated at build time from the packages themselves, so a new module or a new
name in a module's ``__all__`` is documented without editing the site: each page is rendered by
mkdocstrings from the module's ``__all__``, each public object on one page only (:func:`home`:
the module that defines it); a module (package or leaf) that re-exports a name defined elsewhere
shows a link to that one place (rendering it twice would give two anchors for one object).
``tests/test_site.py`` checks that every name of every ``__all__`` has an anchor and that each
object is rendered once.
"""
from __future__ import annotations

import ast
import functools
import importlib
from pathlib import Path

from mkdocs.plugins import event_priority
from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("specdesign", "loopshaping")


def _all_names(module: str) -> list[str]:
    """The module's ``__all__`` (imported: a package may build it, e.g. from a table of lazy names)."""
    return list(getattr(importlib.import_module(module), "__all__", []))


@functools.cache
def public_modules() -> dict[str, tuple[Path, bool]]:
    """Module name → (source file, is a package) for every module without a private part."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            is_pkg = parts[-1] == "__init__"
            if is_pkg:
                parts.pop()
            if any(p.startswith("_") for p in parts) or parts[-1] == "__main__":
                continue
            out[".".join(parts)] = (path, is_pkg)
    return dict(sorted(out.items()))


def _page_path(module: str) -> str:
    return "api/" + module.replace(".", "/") + ".md"


@functools.cache
def _top_level_names(module: str) -> frozenset[str]:
    """The names ``module``'s source binds at its top level (def, class or assignment)."""
    names = set()
    for node in ast.parse(public_modules()[module][0].read_text(encoding="utf-8")).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        names.update(n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name))
    return frozenset(names)


def home(module: str, name: str, modules: dict) -> str | None:
    """The one public leaf module whose page renders ``module.name``: the leaf that defines the
    object (its ``__module__``, or for a constant the leaf whose source assigns it) when it
    exports it, else the first leaf exporting the same object, the module's own submodules
    first; None when no other leaf exports it (``module`` renders it itself)."""
    obj = getattr(importlib.import_module(module), name)
    leaves = [m for m in modules if not modules[m][1]]
    exports = [m for m in leaves if name in _all_names(m) and getattr(importlib.import_module(m), name) is obj]
    defined = getattr(obj, "__module__", None)
    ordered = ([defined] + [m for m in exports if name in _top_level_names(m)] + [m for m in exports if m.startswith(module + ".")]
               + exports)
    return next((m for m in ordered if m in exports), None)


def rendered(module: str, modules: dict) -> tuple[list[str], dict[str, str]]:
    """(names ``module``'s page renders, {name: the module whose page renders it} for the rest of
    its ``__all__``): every public object is rendered on one page only, and linked from the others."""
    own, linked = [], {}
    for name in _all_names(module):
        where = home(module, name, modules)
        if where is None or where == module:
            own.append(name)
        else:
            linked[name] = where
    return own, linked


def _page(module: str, modules: dict) -> str:
    is_pkg = modules[module][1]
    own, linked = rendered(module, modules)
    text = f"# `{module}`\n\n::: {module}\n    options:\n      show_root_heading: false\n"
    text += "      members: " + ("[" + ", ".join(own) + "]" if own else "false") + "\n\n"
    subs = [m for m in modules if m.startswith(module + ".") and m.count(".") == module.count(".") + 1]
    if is_pkg and subs:
        text += "## Submodules\n\n" + "".join(f"- [`{m}`]({Path(_page_path(m)).relative_to(Path(_page_path(module)).parent)})\n"
                                               for m in subs) + "\n"
    if linked:
        text += "## Names exported here\n\nEach is documented in its own module:\n\n"
        for name, where in linked.items():
            # an empty anchor (autorefs registers it): a reference to the re-exported name lands here
            text += f"- [](){{#{module}.{name}}}[`{name}`][{where}.{name}] (`{where}`)\n"
    return text


def _nav_paths(nav) -> set[str]:
    """Every page path the navigation names."""
    if isinstance(nav, str):
        return {nav}
    if isinstance(nav, dict):
        return set().union(*(_nav_paths(v) for v in nav.values()))
    if isinstance(nav, list):
        return set().union(set(), *(_nav_paths(v) for v in nav))
    return set()


def _section(nav: list, title: str) -> list:
    """The item list of the top-level section ``title`` (created at the end if absent)."""
    for item in nav:
        if isinstance(item, dict) and title in item:
            return item[title]
    nav.append({title: []})
    return nav[-1][title]


def on_config(config):
    """Complete the navigation: a reference note (``docs/*.md``) or a notebook that mkdocs.yml
    does not list yet goes at the end of its section (titled by its first heading), and the API
    reference is appended, packages before their modules."""
    nav = config["nav"]
    listed = _nav_paths(nav)
    docs = Path(config["docs_dir"])
    for page in sorted(docs.glob("*.md")):
        if page.name not in listed:
            _section(nav, "Reference notes").append(page.name)
    for nb in notebooks():
        if f"notebooks/{nb.name}" not in listed:
            _section(nav, "Notebooks").append(f"notebooks/{nb.name}")
    modules = public_modules()
    api = []
    for pkg in PACKAGES:
        api.append({pkg: [{m: _page_path(m)} for m in modules if m == pkg or m.startswith(pkg + ".")]})
    nav.append({"API reference": api})
    return config


def notebooks() -> list[Path]:
    """The shipped notebooks (``notebooks/*.ipynb``), in order."""
    return sorted((ROOT / "notebooks").glob("*.ipynb"))


#: Where tests/test_notebooks.py writes each notebook it executed (with its outputs), under
#: ``notebooks/``; the site shows that copy while it is fresh (executed from the notebook as it is).
EXECUTED = ROOT / "build" / "executed"


def source_digest(path: Path) -> str:
    """SHA-256 of a notebook file's bytes: an executed copy records the digest of its source."""
    import hashlib

    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def executed_copy(nb: Path) -> Path | None:
    """The executed copy of ``nb`` if it was executed from the notebook as it is now, else None."""
    import json

    copy = EXECUTED / "notebooks" / nb.name
    if not copy.is_file():
        return None
    try:
        meta = json.loads(copy.read_text()).get("metadata", {}).get("specdesign", {})
    except (OSError, ValueError):
        return None
    return copy if meta.get("source_sha256") == source_digest(nb) else None


# before mkdocs-jupyter's on_files (priority 0), which turns the notebooks added here into pages
@event_priority(50)
def on_files(files, config):
    """Add the generated API pages and the notebooks, read where they live (nothing copied into docs/)."""
    modules = public_modules()
    for m in modules:
        files.append(File.generated(config, _page_path(m), content=_page(m, modules)))
    for nb in notebooks():
        # with its outputs when the tests executed this very notebook, else as stored (no outputs)
        src = EXECUTED if executed_copy(nb) is not None else ROOT
        files.append(File(f"notebooks/{nb.name}", src_dir=str(src), dest_dir=config["site_dir"],
                          use_directory_urls=config["use_directory_urls"]))
    return files
