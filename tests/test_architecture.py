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


#: Shipped files that differ from ../shared on purpose: file → (line in ../shared, line shipped,
#: why). The DISCON.IN names its Cp table where the package ships it (beside it); the reference
#: copy's ../IEA-15-240-RWT/ does not exist in the package, and ROSCO stops the process on it.
SHIPPED_EDITS = {
    "IEA-15-240-RWT-Monopile_DISCON.IN": (
        '"../IEA-15-240-RWT/Cp_Ct_Cq.IEA15MW.txt"      ! PerfFileName',
        '"Cp_Ct_Cq.IEA15MW.txt"                         ! PerfFileName',
        "the Cp table's path as shipped"),
}


def test_package_ships_its_data(package_data, shared_data):
    for f in shared_data.iterdir():
        shipped = package_data / f.name
        assert shipped.is_file(), f"{f.name} is not shipped in specdesign/data/iea15mw"
        ref, got = f.read_bytes(), shipped.read_bytes()
        if f.name in SHIPPED_EDITS:  # the one documented line differs, nothing else
            old, new, _ = SHIPPED_EDITS[f.name]
            assert ref.count(old.encode()) == 1 and got.count(new.encode()) == 1, f.name
            ref = ref.replace(old.encode(), new.encode())
            assert (package_data / "Cp_Ct_Cq.IEA15MW.txt").is_file()
        assert got == ref, f"{f.name} differs from ../shared"


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


# ----------------------------------------------------------------------------- layers (issue 30)
#: Imports that may stay inside a function, by the module imported (a dotted prefix), with the
#: reason: an optional dependency, or one heavy at import time that only the calling function
#: needs (a light module, e.g. the simulator or the fatigue code, then loads without it). Every
#: other import is at the top of its module. The own modules listed are heavy because they
#: import python-control at load time (checked by test_own_local_imports_are_heavy).
LOCAL_IMPORTS = {
    "control": "python-control loads matplotlib.pyplot and scipy.signal at import (3.3 s measured on the shared machine)",
    "scipy": "scipy's subpackages (optimize, interpolate, signal, linalg, stats): 0.6-2.7 s each on the same machine",
    "matplotlib": "figures only (0.4 s, 1.4 s with pyplot there); never loaded by a computation",
    "cvxpy": "the convex solvers of the feasibility certificate and the MPC (2.9 s there)",
    "sklearn": "optional extra `surrogate` (the Gaussian-process surrogate)",
    "slycot": "optional for loopshaping as a whole, needed by its H-infinity routines only",
    "IPython": "notebook display only",
    "ipywidgets": "notebook widgets only",
    "ipympl": "notebook widgets only",
    "rosco": "optional extra `rosco` (ROSCO's compiled controller and its test decks)",
    "distributed": "optional extra `cluster` (dask campaigns)",
    "dask": "optional extra `cluster` (dask campaigns)",
    "xarray": "optional: reading a campaign store back as a dataset",
    "openfast_io": "OpenFAST's input-file library: only the deck adapters use it",
    "specdesign.spec": "imports python-control at load",
    "specdesign.qft": "imports python-control at load",
    "specdesign.hinf": "imports python-control at load",
    "specdesign.session": "imports python-control at load",
    "specdesign.demo": "imports python-control at load",
    "specdesign.plots.spec": "imports python-control at load",
    "loopshaping._statespace": "imports python-control at load",
    "loopshaping.hinf": "imports python-control at load",
    "loopshaping.reduction": "imports python-control at load",
    "loopshaping.wellposed": "imports python-control at load",
}
#: Heavy third-party modules an own module listed in LOCAL_IMPORTS must load at import.
HEAVY = ("control", "cvxpy", "ipywidgets")


def _in_type_checking(node, parents):
    """Whether ``node`` sits under ``if TYPE_CHECKING:`` (an annotation, never executed)."""
    while node in parents:
        node = parents[node]
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            return True
    return False


def _imports(package):
    """(path, module, node, targets, inside a function) of every executed import in ``package``."""
    for path, modname in _modules():
        if not modname.startswith(package + "."):
            continue
        tree = ast.parse(path.read_text(), filename=str(path))
        parents = {c: n for n in ast.walk(tree) for c in ast.iter_child_nodes(n)}
        for node in ast.walk(tree):
            if not isinstance(node, (ast.Import, ast.ImportFrom)) or _in_type_checking(node, parents):
                continue
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                src = _resolve(modname, node)
                targets = [src] + [f"{src}.{a.name}" for a in node.names]  # `from pkg import module`
            up, local = node, False
            while up in parents and not local:
                up = parents[up]
                local = isinstance(up, (ast.FunctionDef, ast.AsyncFunctionDef))
            yield path, modname, node, targets, local


def _part(module):
    """The part of specdesign a module belongs to: its subpackage or top-level module."""
    parts = module.split(".")
    return parts[1] if parts[0] == "specdesign" and len(parts) > 1 and parts[1] != "__init__" else None


def test_the_parts_of_specdesign_form_no_cycle():
    # every import counts, inside functions too (only `if TYPE_CHECKING:` annotations do not):
    # each part stands on the parts below it and never on one above
    edges = {}
    for path, modname, node, targets, _ in _imports("specdesign"):
        me = _part(modname)
        for t in targets:
            other = _part(t)
            if me and other and other != me and t.startswith("specdesign."):
                edges.setdefault(me, {}).setdefault(other, f"{path.relative_to(ROOT)}:{node.lineno}")
    state, cycles = {}, []

    def visit(part, stack):
        state[part] = "open"
        stack.append(part)
        for nxt in sorted(edges.get(part, {})):
            if state.get(nxt) == "open":
                loop = stack[stack.index(nxt):] + [nxt]
                cycles.append(" -> ".join(f"{a} ({edges[a][b]})" for a, b in zip(loop, loop[1:])))
            elif nxt not in state:
                visit(nxt, stack)
        stack.pop()
        state[part] = "done"

    for part in sorted(edges):
        if part not in state:
            visit(part, [])
    assert not cycles, "import cycles between the parts of specdesign:\n" + "\n".join(cycles)
    # the layers named in issue 30: the controller representation under the turbine, the
    # linear loop and the simulator; the specification side under the designers
    for low, high in (("controller", "turbine"), ("controller", "closedloop"), ("controller", "simulate"),
                      ("turbine", "rosco"), ("closedloop", "simulate"), ("spec", "feasibility"),
                      ("feasibility", "qft"), ("validate", "cli")):
        assert low in edges.get(high, {}), f"{high} no longer stands on {low}: update this test's layers"
        assert high not in edges.get(low, {}), f"{low} imports {high} ({edges[low][high]})"


def test_no_import_inside_a_function_unless_listed():
    def listed(modname, targets):
        # a module of the importer's own part is never listed: the part's package loads it anyway,
        # so a local import there only hides a cycle between the part's modules
        def own_part(t):
            return t.split(".")[0] in PACKAGES and t.split(".")[:2] == modname.split(".")[:2]

        def ok(t):
            return any((t == p or t.startswith(p + ".")) and not own_part(t) for p in LOCAL_IMPORTS)

        # `from pkg import a, b`: the source listed, or every name imported (`from .. import spec,
        # spectral` is not excused by spec alone)
        return ok(targets[0]) or all(ok(t) for t in targets[1:]) if len(targets) > 1 else ok(targets[0])

    bad = [f"{path.relative_to(ROOT)}:{node.lineno}: {ast.unparse(node)}"
           for pkg in PACKAGES for path, modname, node, targets, local in _imports(pkg)
           if local and not (listed(modname, targets) if isinstance(node, ast.ImportFrom)
                             else all(listed(modname, [t]) for t in targets))]
    assert not bad, ("imports inside functions (move them to the top, or list the dependency in LOCAL_IMPORTS "
                     "with the reason):\n" + "\n".join(bad))


def test_own_local_imports_are_heavy():
    # an own module may be imported inside a function only if it is heavy at import time
    own = [m for m in LOCAL_IMPORTS if m.split(".")[0] in PACKAGES]
    code = ("import importlib, sys\n"
            f"importlib.import_module(sys.argv[1])\nprint(sorted(m for m in {HEAVY!r} if m in sys.modules))\n")
    light = []
    for m in own:
        out = subprocess.run([sys.executable, "-c", code, m], capture_output=True, text=True, cwd=ROOT)
        assert out.returncode == 0, out.stderr
        if out.stdout.strip() == "[]":
            light.append(m)
    assert not light, f"listed in LOCAL_IMPORTS as heavy but load none of {HEAVY}: {light} (import them at the top)"


# ----------------------------------------------------------------------------- one source per default (issue 32)
def _signatures():
    """(qualified name, inspect.Signature) of every function and method defined in both packages."""
    import importlib
    import inspect

    for path, modname in _modules():
        if modname.endswith("__main__"):
            continue
        mod = importlib.import_module(modname.removesuffix(".__init__"))
        for name, obj in vars(mod).items():
            if getattr(obj, "__module__", None) != mod.__name__:
                continue
            members = [(name, obj)]
            if inspect.isclass(obj):
                members += [(f"{name}.{k}", v) for k, v in vars(obj).items() if inspect.isfunction(v)]
            for qual, f in members:
                f = getattr(f, "py_func", f)  # numba dispatchers
                if callable(f):
                    try:
                        yield f"{modname}.{qual}", inspect.signature(f)
                    except (TypeError, ValueError):
                        continue


def test_shared_defaults_have_one_source():
    # the defaults several signatures share are module constants, used by identity, so changing
    # one changes all; a literal copy (1.9 here, 2.0 there) fails this test
    from specdesign import closedloop, fatigue
    from specdesign.qft import SPEED_RELAX_DB

    # parameter → its constants: a float default must be one of them
    shared = {
        "max_sensitivity": (closedloop.MAX_SENSITIVITY, closedloop.DESIGN_MAX_SENSITIVITY,
                            closedloop.CERTIFICATE_MAX_SENSITIVITY),
        "m": (fatigue.TOWER_M,),
    }
    copies = [f"{qual}({p}={sig.parameters[p].default!r})" for qual, sig in _signatures() for p in shared
              if p in sig.parameters and isinstance(sig.parameters[p].default, float)
              and not any(sig.parameters[p].default is c for c in shared[p])]
    # QFT's relaxation ladder, wherever it is the default (other ladders are other defaults)
    copies += [f"{qual}(speed_relax_db={sig.parameters['speed_relax_db'].default!r})" for qual, sig in _signatures()
               if "speed_relax_db" in sig.parameters and sig.parameters["speed_relax_db"].default == SPEED_RELAX_DB
               and sig.parameters["speed_relax_db"].default is not SPEED_RELAX_DB]
    assert not copies, "defaults written as literals instead of their module constant:\n" + "\n".join(copies)


def _named_constants():
    """Parameter name → [(constant's qualified name, value)] for every public upper-case module
    constant (a number or a tuple) of both packages, keyed by its name lower-cased without a
    ``DEFAULT_`` prefix (SLACK_DB → slack_db, DEFAULT_DECAY_RATE → decay_rate)."""
    import importlib

    out = {}
    for path, modname in _modules():
        if modname.endswith("__main__"):
            continue
        mod = importlib.import_module(modname.removesuffix(".__init__"))
        for node in ast.parse(path.read_text()).body:
            for target in node.targets if isinstance(node, ast.Assign) else []:
                for n in ast.walk(target):
                    v = getattr(mod, n.id, None) if isinstance(n, ast.Name) else None
                    if n.__class__ is ast.Name and n.id.isupper() and not n.id.startswith("_") and (
                            isinstance(v, (float, int, tuple)) and not isinstance(v, bool)):
                        out.setdefault(n.id.removeprefix("DEFAULT_").lower(), []).append((f"{modname}.{n.id}", v))
    return out


def test_a_named_default_is_used_by_every_signature_that_shares_it():
    # wherever a module constant names a default (its name is the parameter's, e.g. SLACK_DB and
    # slack_db, or listed below), a signature with that parameter and that value uses the constant
    # itself, in specdesign and in loopshaping (which has its own constants: it never imports
    # specdesign); a literal copy of the value fails here
    from specdesign import closedloop, fatigue, wind

    named = _named_constants()
    for param, const in (("m", "TOWER_M"), ("blade_m", "BLADE_M")):
        named.setdefault(param, []).append((f"specdesign.fatigue.{const}", getattr(fatigue, const)))
    named.setdefault("min_decay", []).append(("specdesign.closedloop.MIN_DECAY_RATE", closedloop.MIN_DECAY_RATE))
    # a simulated record's length is IEC 61400-1's 10-minute record, the one a spectral DEL counts over
    named.setdefault("duration", []).append(("specdesign.wind.RECORD_LENGTH", wind.RECORD_LENGTH))
    copies = []
    for qual, sig in _signatures():
        for p in sig.parameters.values():
            d = p.default
            if p.name not in named or isinstance(d, bool) or not isinstance(d, (float, int, tuple)):
                continue
            same = [c for c, v in named[p.name] if type(v) is type(d) and v == d]
            if same and not any(v is d for _, v in named[p.name]):
                copies.append(f"{qual}({p.name}={d!r}): use {' or '.join(sorted(set(same)))}")
    assert not copies, "defaults written as literals where a module constant names them:\n" + "\n".join(copies)


def test_ordered_constants_stay_ordered():
    # the certificate is stricter than the designs that fit it, which are stricter than the
    # feasibility verdict (each keeps margin on the next); all are sensitivity peaks above 1
    from specdesign import closedloop

    assert 1.0 < closedloop.CERTIFICATE_MAX_SENSITIVITY < closedloop.DESIGN_MAX_SENSITIVITY
    assert closedloop.DESIGN_MAX_SENSITIVITY <= closedloop.MAX_SENSITIVITY


# ----------------------------------------------------------------------------- one name, one meaning (issue 32)
#: Public names that specdesign and loopshaping both export for different objects, with the
#: reason. Empty: closedloop's closed_loop_poles is turbine_loop_poles (loopshaping.interactive
#: keeps its own), wind's synthesize is gaussian_series (loopshaping.hinf.synthesize is H∞).
SHARED_NAMES: dict = {}


def test_no_public_name_means_two_things_across_the_packages():
    import importlib

    homes = {}
    for path, modname in _modules():
        if any(p.startswith("_") and p != "__init__" for p in modname.split(".")) or modname.endswith("__main__"):
            continue
        mod = importlib.import_module(modname.removesuffix(".__init__"))
        for name in getattr(mod, "__all__", ()):
            homes.setdefault(name, {}).setdefault(modname.split(".")[0], {})[id(getattr(mod, name))] = modname
    clashes = {name: {pkg: sorted(ids.values()) for pkg, ids in by.items()} for name, by in homes.items()
               if len(by) == 2 and not set(by["specdesign"]) & set(by["loopshaping"]) and name not in SHARED_NAMES}
    assert not clashes, f"one public name, two objects (rename one, or list it in SHARED_NAMES with why): {clashes}"


# ----------------------------------------------------------------------------- warnings (issue 32)
def test_no_warning_is_silenced_wholesale():
    # only named categories, in the narrowest block, with the reason beside it: a bare
    # simplefilter("ignore") would also hide the DeprecationWarnings the tests make errors and
    # every numerical warning of the block
    bad = []
    for path, _ in _modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in ("simplefilter", "filterwarnings") and node.args
                    and isinstance(node.args[0], ast.Constant) and node.args[0].value == "ignore"):
                continue
            position = 1 if node.func.attr == "simplefilter" else 2  # where `category` goes
            if len(node.args) <= position and not any(k.arg == "category" for k in node.keywords):
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not bad, "warnings silenced without a category: " + ", ".join(bad)


# ----------------------------------------------------------------------------- complexity (issue 32)
import pytest  # noqa: E402

#: The convention for a public function graded E by radon: a line of its docstring (in its Notes
#: section) starts with this, followed by why splitting the function would hurt.
COMPLEXITY_REASON = "Complexity:"
#: Public functions allowed above grade D for now, by qualified name, with the reason (each one
#: an open piece of work, not a permanent exception).
COMPLEXITY_PENDING: dict[str, str] = {}


def _complexity():
    """(qualified name, radon grade, docstring) of every public function and method of the packages:
    not underscored (a method's class neither; dunders count), in a module without a private part."""
    radon = pytest.importorskip("radon.complexity", reason="radon is in the dev extra: pip install -e '.[dev]'")
    for path, modname in _modules():
        if any(p.startswith("_") and p != "__init__" for p in modname.split(".")):
            continue
        text = path.read_text()
        docs = {(n.name, n.lineno): ast.get_docstring(n) or "" for n in ast.walk(ast.parse(text))
                if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
        for block in radon.cc_visit(text):
            members = [(None, block)] if not hasattr(block, "methods") else [(block.name, m) for m in block.methods]
            for cls, f in members:
                names = [f.name] if cls is None else [cls, f.name]
                if any(n.startswith("_") and not (n.startswith("__") and n.endswith("__")) for n in names):
                    continue
                qual = ".".join([modname.removesuffix(".__init__")] + names)
                yield qual, radon.cc_rank(f.complexity), f.complexity, docs.get((f.name, f.lineno), "")


def test_no_public_function_is_too_complex_without_a_reason():
    # radon's grades: A-B simple, C-D more complex, E very complex, F error-prone. No public
    # function is F; an E says in its docstring why splitting it would hurt (a "Complexity:" line)
    too = []
    for qual, grade, cc, doc in _complexity():
        if qual in COMPLEXITY_PENDING:
            continue
        has_reason = any(line.strip().startswith(COMPLEXITY_REASON) for line in doc.splitlines())
        if grade == "F" or (grade == "E" and not has_reason):
            too.append(f"{qual}: {grade} ({cc})")
    assert not too, ("public functions above radon grade D (split them; an E may instead give the reason in a "
                     f"'{COMPLEXITY_REASON}' line of its docstring):\n" + "\n".join(too))
    assert all(q in {q for q, *_ in _complexity()} for q in COMPLEXITY_PENDING), "a pending entry no longer exists"
