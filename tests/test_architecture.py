"""Architecture rules: loopshaping is generic and never imports specdesign; data is shipped."""
import subprocess
import sys


def test_loopshaping_never_imports_specdesign():
    code = (
        "import importlib, pkgutil, sys, loopshaping\n"
        "for m in pkgutil.iter_modules(loopshaping.__path__):\n"
        "    importlib.import_module('loopshaping.' + m.name)\n"
        "bad = [k for k in sys.modules if k == 'specdesign' or k.startswith('specdesign.')]\n"
        "assert not bad, bad\n"
        "print('ok', len([k for k in sys.modules if k.startswith('loopshaping')]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("ok")


def test_package_ships_its_data(package_data, shared_data):
    for f in shared_data.iterdir():
        shipped = package_data / f.name
        assert shipped.is_file(), f"{f.name} is not shipped in specdesign/data/iea15mw"
        assert shipped.read_bytes() == f.read_bytes(), f"{f.name} differs from ../shared"


# ----------------------------------------------------------------------------- one home per concept (issue 13)
import ast  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("specdesign", "loopshaping")
#: Modules over MAX_LINES that are one cohesive algorithm, with the reason (issue 13: "no module
#: over ~500 lines unless it is one cohesive algorithm").
MAX_LINES = 500
COHESIVE = {}


def _modules():
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            yield path, ".".join(path.relative_to(ROOT).with_suffix("").parts)


def _resolve(modname, node):
    """The absolute module an ImportFrom names (relative imports resolved)."""
    if not node.level:
        return node.module or ""
    parts = modname.split(".")
    is_pkg = parts[-1] == "__init__"
    base = parts[:-1] if is_pkg else parts[:-1]
    base = base[: len(base) - (node.level - 1)] if node.level > 1 else base
    return ".".join(base + ([node.module] if node.module else []))


def test_no_module_imports_a_private_name_from_another():
    # A private name (_x) is a module's own business: what another module needs is public
    # there (issue 13). Checked on every `from M import _x` and every `M._x` where M is a
    # module of ours bound by an import; dunders are not private.
    bad = []
    for path, modname in _modules():
        tree = ast.parse(path.read_text(), filename=str(path))
        ours = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                src = _resolve(modname, node)
                if src.split(".")[0] not in PACKAGES:
                    continue
                for a in node.names:
                    if a.name.startswith("_") and not a.name.startswith("__"):
                        bad.append(f"{path.relative_to(ROOT)}:{node.lineno}: from {src} import {a.name}")
                    else:
                        ours.add(a.asname or a.name)  # maybe a module (from . import spec)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] in PACKAGES:
                        ours.add(a.asname or a.name.split(".")[0])
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in ours
                    and node.attr.startswith("_") and not node.attr.startswith("__")):
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value.id}.{node.attr}")
    assert not bad, "private names used across modules:\n" + "\n".join(bad)


def _code_lines(path) -> int:
    """Lines of code: not blank, not a comment, not inside a docstring (documentation is not size)."""
    text = path.read_text()
    tree = ast.parse(text)
    doc = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
                doc.update(range(first.lineno, first.end_lineno + 1))
    return sum(1 for i, line in enumerate(text.splitlines(), 1)
               if i not in doc and line.strip() and not line.strip().startswith("#"))


def test_modules_stay_small_unless_cohesive():
    big = {modname: n for path, modname in _modules() if (n := _code_lines(path)) > MAX_LINES}
    unexplained = {m: n for m, n in big.items() if m not in COHESIVE}
    assert not unexplained, f"modules over {MAX_LINES} lines (split them, or list them in COHESIVE with the reason): {unexplained}"


def test_every_public_module_declares_all():
    missing = []
    for path, modname in _modules():
        if any(p.startswith("_") and p != "__init__" for p in modname.split(".")) or modname.endswith("__main__"):
            continue
        if modname in ("specdesign.__init__", "loopshaping.__init__"):  # namespaces: a docstring and __version__
            continue
        tree = ast.parse(path.read_text())
        if not any(isinstance(n, (ast.Assign, ast.AnnAssign)) and any(
                isinstance(t, ast.Name) and t.id == "__all__" for t in (n.targets if isinstance(n, ast.Assign) else [n.target]))
                for n in tree.body):
            missing.append(modname)
    assert not missing, f"public modules without __all__: {missing}"


def test_every_name_in_all_exists():
    import importlib

    absent = [f"{modname}.{n}" for path, modname in _modules()
              if not any(p.startswith("_") and p != "__init__" for p in modname.split("."))
              for n in getattr(importlib.import_module(modname.removesuffix(".__init__")), "__all__", ())
              if not hasattr(importlib.import_module(modname.removesuffix(".__init__")), n)]
    assert not absent, absent


def test_no_module_chooses_the_matplotlib_backend():
    # the command line chooses it once (specdesign.cli); a library module that calls
    # matplotlib.use would override a notebook's widget backend
    bad = [f"{path.relative_to(ROOT)}:{n.lineno}" for path, modname in _modules() if modname != "specdesign.cli"
           for n in ast.walk(ast.parse(path.read_text()))
           if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr == "use"
           and isinstance(n.func.value, ast.Name) and n.func.value.id in ("matplotlib", "mpl")]
    assert not bad, bad
