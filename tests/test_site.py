"""The documentation site builds in strict mode and its API reference covers every public name.

One ``mkdocs build --strict`` (mkdocs.yml at the repository root) per test session, into a
temporary folder; the tests read the HTML it wrote. CI runs this through ``python -m pytest``.
"""
from __future__ import annotations

import html
import importlib
import json
import os
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest


ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("specdesign", "loopshaping")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """Build the site once; the fixture is the build's (folder, combined output)."""
    pytest.importorskip("mkdocs", reason='the docs extra is not installed: pip install -e ".[docs]"')
    pytest.importorskip("mkdocstrings")
    pytest.importorskip("mkdocs_jupyter")
    out = tmp_path_factory.mktemp("site")
    # NO_MKDOCS_2_WARNING: mkdocs-material prints a banner about its end of life on every build,
    # outside mkdocs' logging; it says nothing about this site and would hide the real output
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1", "PYTHONPATH": os.pathsep.join(
        filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    return out, r.returncode, r.stdout + r.stderr


@pytest.mark.slow  # one full site build (shared), ~20-40 s
def test_site_builds_strict_without_warnings(site):
    out, code, log = site
    warnings = [line for line in log.splitlines() if re.match(r"\s*(WARNING|ERROR)\b", line)]
    assert code == 0 and not warnings, (
        f"mkdocs build --strict failed (exit {code}); run it to see the messages:\n" + "\n".join(warnings or [log[-4000:]]))
    assert (out / "index.html").is_file()
    # every page of the nav was written, the notebook gallery included
    for page in ("getting_started", "method", "design/sensitivity", "design/specification", "design/controller",
                 "design/validation", "notebooks", "feasibility", "acceptance", "validation"):
        assert (out / page / "index.html").is_file(), page
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        assert (out / "notebooks" / nb.stem / "index.html").is_file(), f"notebook {nb.name} is not in the gallery"


def _hooks():
    import importlib.util

    spec = importlib.util.spec_from_file_location("api_pages", ROOT / "docs" / "hooks" / "api_pages.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.slow
def test_the_gallery_shows_the_executed_notebooks_outputs(site):
    # tests/test_notebooks.py (which runs before this file) writes each notebook it executed,
    # figures included, to build/executed/; the gallery shows that copy while it is fresh
    out = site[0]
    hooks = _hooks()
    fresh = [nb for nb in hooks.notebooks() if hooks.executed_copy(nb) is not None]
    if not fresh:
        pytest.skip("no executed notebook copies: run tests/test_notebooks.py first (the full suite does)")
    for nb in fresh:
        page = (out / "notebooks" / nb.stem / "index.html").read_text()
        assert "jp-OutputArea-output" in page, f"{nb.name}: executed, but its page shows no output"
    n_png = sum(json.loads(hooks.executed_copy(nb).read_text()).__str__().count("image/png") for nb in fresh)
    assert n_png > 0  # at least one figure among the executed notebooks
    # a notebook changed after its execution is shown as stored, not with stale outputs (on copies)
    import shutil
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "src" / fresh[0].name
        src.parent.mkdir()
        shutil.copy(fresh[0], src)
        (Path(tmp) / "exec" / "notebooks").mkdir(parents=True)
        shutil.copy(hooks.executed_copy(fresh[0]), Path(tmp) / "exec" / "notebooks" / fresh[0].name)
        hooks.EXECUTED = Path(tmp) / "exec"
        assert hooks.executed_copy(src) is not None
        src.write_bytes(src.read_bytes() + b"\n")
        assert hooks.executed_copy(src) is None


def _public_names():
    """(module, name) for every name in the ``__all__`` of every public module of both packages,
    found by walking the packages (independently of the site's own page generator)."""
    pairs = []
    for pkg in PACKAGES:
        mod = importlib.import_module(pkg)
        names = [pkg] + [m.name for m in pkgutil.walk_packages(mod.__path__, pkg + ".")]
        for name in names:
            if any(part.startswith("_") for part in name.split(".")):
                continue
            module = importlib.import_module(name)
            pairs += [(name, n) for n in getattr(module, "__all__", ())]
            pairs.append((name, None))
    return pairs


def _api_html(out: Path) -> str:
    return "".join(p.read_text(encoding="utf-8") for p in sorted((out / "api").rglob("*.html")))


@pytest.mark.slow  # one full site build (shared), ~20-40 s
def test_api_reference_covers_every_public_name(site):
    out, code, _ = site
    assert code == 0, "the site did not build; see test_site_builds_strict_without_warnings"
    ids = set(re.findall(r'\sid="([^"]+)"', _api_html(out)))
    pairs = _public_names()
    modules = {m for m, n in pairs if n is None}
    assert {"specdesign.spectral", "loopshaping.qft", "specdesign.cli"} <= modules  # the walk found them
    missing_pages = sorted(m for m in modules
                           if not (out / "api" / Path(*m.split("."))).joinpath("index.html").is_file())
    assert not missing_pages, f"public modules without an API page: {missing_pages}"
    # each name has an anchor at its module's path: rendered there by mkdocstrings, or (a name a
    # package re-exports) an anchor beside the link to the module that documents it
    missing = sorted(f"{m}.{n}" for m, n in pairs if n is not None and f"{m}.{n}" not in ids)
    assert not missing, f"{len(missing)} public names missing from the API reference: {missing[:30]}"


def test_api_pages_render_each_public_object_once_and_list_all():
    # issue 32: the API pages are the public surface __all__ declares, each object documented
    # once. Read from the generated page sources (no site build): a page renders the names of its
    # ``members:`` line and links the rest of its __all__ to the one page that renders them.
    hooks = _hooks()
    modules = hooks.public_modules()
    assert {"specdesign.hinf.specs", "loopshaping.qft", "loopshaping.bounds"} <= set(modules)
    rendered, links, problems = {}, [], []
    for m in modules:
        text = hooks._page(m, modules)
        names = list(getattr(importlib.import_module(m), "__all__", ()))
        members = re.search(r"^ +members: (.*)$", text, flags=re.M)  # none: mkdocstrings renders __all__
        own = names if members is None else [] if members.group(1) == "false" else [
            n.strip() for n in members.group(1).strip("[]").split(",")]
        linked = re.findall(r"\[`([^`]+)`\]\[([\w.]+)\.\1\]", text)
        if sorted(own + [n for n, _ in linked]) != sorted(names):
            problems.append(f"{m}: page lists {sorted(own + [n for n, _ in linked])}, __all__ is {sorted(names)}")
        obj = importlib.import_module(m)
        for n in own:
            rendered.setdefault((n, id(getattr(obj, n))), []).append(m)
        links += [(m, n, where) for n, where in linked]
    problems += [f"{n} rendered on {pages}" for (n, _), pages in rendered.items() if len(pages) > 1]
    for m, n, where in links:
        if where not in rendered.get((n, id(getattr(importlib.import_module(m), n))), []):
            problems.append(f"{m}.{n} links to {where}, which does not render that object")
    assert not problems, "\n".join(problems)


@pytest.mark.slow  # one full site build (shared), ~20-40 s
def test_api_reference_has_no_raw_rest_markup(site):
    """The numpydoc docstrings use Sphinx roles, literal blocks and simple tables; the site
    turns them into links, code and tables, not raw text."""
    out, code, _ = site
    assert code == 0
    page = re.sub(r"<script.*?</script>", "", _api_html(out), flags=re.S)
    text = html.unescape(re.sub(r"<[^>]+>", "", page))
    raw = [text[max(0, m.start() - 40):m.end() + 40]
           for m in re.finditer(r":(?:func|class|meth|attr|data|mod|obj|exc):`|\w``?::\n|={3,} +={3,}", text)]
    assert not raw, raw[:5]
    # a doctest outside an Examples section, read as Markdown, becomes nested block quotes
    assert not re.search(r"<blockquote>\s*<blockquote>", page)


# ----------------------------------------------------------------------------- the docstring conversions
def _roles():
    pytest.importorskip("griffe", reason='the docs extra is not installed: pip install -e ".[docs]"')
    sys.path.insert(0, str(ROOT / "docs" / "hooks"))
    try:
        return importlib.import_module("griffe_rest_roles")
    finally:
        sys.path.pop(0)


def test_rest_literal_blocks_and_simple_tables_become_markdown():
    g = _roles()
    text = "Layout of ``path``::\n\n    a.json   settings\n    b.csv    index\n\nAfter."
    assert g.literal_blocks(text) == ("Layout of ``path``:\n\n```text\na.json   settings\nb.csv    index\n```\n\nAfter.")
    table = ("Elements:\n\n====  ======  ====\nkind  params  f\n====  ======  ====\ngain  k       k\n"
             "notch omega,   N(s)\n      zeta\n====  ======  ====\n\nAfter.")
    assert g.simple_tables(table).split("\n")[2:7] == [
        "| kind | params | f |", "|---|---|---|", "| gain | k | k |", "| notch | omega, zeta | N(s) |", ""]
    assert g.simple_tables("a\n==== ====\nb") == "a\n==== ====\nb"  # a lone rule is not a table


def test_doctests_are_fenced_outside_examples_only():
    g = _roles()
    text = "Use:\n\n>>> f(1)\n2\n\nExamples\n--------\n>>> f(2)\n3"
    assert g.fence_doctests(text) == "Use:\n\n```pycon\n>>> f(1)\n2\n```\n\nExamples\n--------\n>>> f(2)\n3"


# ----------------------------------------------------------------------------- offline: no CDN, math as math
def test_math_hook_renders_every_kind_of_equation_and_refuses_bad_tex():
    pytest.importorskip("latex2mathml", reason='the docs extra is not installed: pip install -e ".[docs]"')
    sys.path.insert(0, str(ROOT / "docs" / "hooks"))
    try:
        math = importlib.import_module("mathml")
    finally:
        sys.path.pop(0)
    page = ('<p><span class="arithmatex">\\(a &lt; b\\)</span></p><div class="arithmatex">\\[x^2\\]</div>'
            '<div class="jp-Cell"><div class="jp-RenderedMarkdown jp-MarkdownOutput"><p>$y_1$ and $$z$$</p>'
            '<div>nested</div></div></div><pre>$not math$</pre>')
    out = math.render_math(page)
    assert out.count("<math") == 4 and 'display="block"' in out and "&lt;" not in out.split("<math")[1][:40]
    assert "$not math$" in out  # outside a notebook's Markdown cell, a dollar is text
    assert "arithmatex" not in out and "$y_1$" not in out
    with pytest.raises(ValueError, match="cannot render"):
        math.render_math('<span class="arithmatex">\\(\\phi\'\'^2\\)</span>', where="x.md")


@pytest.mark.slow  # shares the site build; starts Debian's chromium
def test_site_renders_equations_and_figures_with_the_network_off(site):
    # the issue "Layers without cycles ... docs that work offline": every request that is not a
    # file of the built site is refused, and the page still shows MathML equations laid out by
    # the browser (height > 0) and, on a notebook page, its figures
    import shutil

    out, code, _ = site
    assert code == 0
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        pytest.skip("Debian's chromium is not installed (apt-get install -y chromium; .ci/run does it)")
    from playwright.sync_api import sync_playwright

    refused = []

    def only_files(route):
        if route.request.url.startswith("file://"):
            route.continue_()
        else:
            refused.append(route.request.url)
            route.abort()

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=chromium, headless=True,
                               args=["--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu"])
        try:
            page = b.new_page()
            page.route("**/*", only_files)
            page.goto((out / "turbines" / "index.html").as_uri())
            boxes = page.eval_on_selector_all("math", "els => els.map(e => e.getBoundingClientRect().height)")
            assert len(boxes) >= 10 and min(boxes) > 0, boxes
            text = page.inner_text("article")
            assert "\\int" not in text and "$" not in text  # no raw TeX left on the page (the page has no dollar amounts)
            hooks = _hooks()
            fresh = [nb for nb in hooks.notebooks() if hooks.executed_copy(nb) is not None]
            if fresh:  # the gallery shows executed copies only after tests/test_notebooks.py ran
                page.goto((out / "notebooks" / fresh[0].stem / "index.html").as_uri())
                sizes = page.eval_on_selector_all(
                    "img", "els => els.filter(e => e.src.startsWith('data:image/png')).map(e => e.naturalWidth)")
                assert sizes and min(sizes) > 0
        finally:
            b.close()
    assert not refused, f"the site asked the network for {refused[:5]}"


def test_the_widget_loader_from_a_cdn_is_removed_from_notebook_pages():
    sys.path.insert(0, str(ROOT / "docs" / "hooks"))
    try:
        offline = importlib.import_module("offline")
    finally:
        sys.path.pop(0)
    page = ("<p>a</p><script>\n(function() {\n  function addWidgetsRenderer() {\n    var s = "
            "'https://unpkg.com/@jupyter-widgets/html-manager@*/dist/embed-amd.js';\n  }\n}());\n</script><p>b</p>")
    assert offline.strip_widget_loader(page) == "<p>a</p><p>b</p>"
    with pytest.raises(ValueError, match="unpkg"):
        offline.strip_widget_loader('<script src="https://unpkg.com/x.js"></script>')
