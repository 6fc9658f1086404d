"""Documentation in the code (issue 13): every public name of both packages has a numpydoc
docstring (summary, documented parameters, Returns), and every Examples section runs.

Public names are those in each public module's ``__all__`` (tests/test_architecture.py checks
that every public module has one), classes with their own public methods. Checked with
numpydoc's validator: GL08 no docstring, PR01 a parameter not documented, PR02 a documented
parameter that does not exist, RT01 no Returns section.
"""
from __future__ import annotations

import doctest
import importlib
import inspect
import pkgutil

import pytest

PACKAGES = ("specdesign", "loopshaping")
CODES = {"GL08", "PR01", "PR02", "RT01"}


def _public_modules():
    out = []
    for pkg in PACKAGES:
        root = importlib.import_module(pkg)
        out.append(pkg)
        for info in pkgutil.walk_packages(root.__path__, prefix=f"{pkg}."):
            if not any(part.startswith("_") for part in info.name.split(".")):
                out.append(info.name)
    return sorted(out)


MODULES = _public_modules()


def _documented_names(modname):
    """Qualified names of the public functions and classes a module defines or re-exports, and
    the public methods and properties its classes define."""
    mod = importlib.import_module(modname)
    for name in getattr(mod, "__all__", ()):
        obj = getattr(mod, name)
        if not (inspect.isfunction(obj) or inspect.isclass(obj)):
            continue
        if obj.__module__ != modname:  # a re-export: checked in its home module
            continue
        yield f"{modname}.{name}"
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for attr, v in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(v) or isinstance(v, (classmethod, staticmethod, property))):
                    yield f"{modname}.{name}.{attr}"


@pytest.mark.parametrize("modname", MODULES)
def test_public_names_have_numpydoc_docstrings(modname):
    validate = pytest.importorskip("numpydoc.validate").validate
    bad = {}
    for qual in _documented_names(modname):
        errs = sorted({c for c, _ in validate(qual)["errors"] if c in CODES})
        if errs:
            bad[qual] = errs
    assert not bad, bad


@pytest.mark.parametrize("modname", MODULES)
def test_examples_run(modname):
    mod = importlib.import_module(modname)
    res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert res.failed == 0, f"{res.failed} of {res.attempted} examples of {modname} failed"


def test_an_overriding_method_takes_its_sources_docstring_with_its_note():
    # issue 32: documented once. The note goes after the summary, where numpydoc reads an
    # extended summary; the parameters stay the source's
    from numpydoc.docscrape import FunctionDoc

    from specdesign._docs import docstring_of

    class Base:
        def step(self, dt):
            """One step.

            Parameters
            ----------
            dt : float
                Step, s.
            """

    class Child(Base):
        @docstring_of(Base, note="The child also counts its steps.")
        def step(self, dt):
            pass

    doc = FunctionDoc(Child.step)
    assert doc["Summary"] == ["One step."] and doc["Extended Summary"] == ["The child also counts its steps."]
    assert [p.name for p in doc["Parameters"]] == ["dt"]

    def again(self, dt):  # Base has none: refused when the class is defined, naming both
        pass

    with pytest.raises(AttributeError, match="Base.again has no docstring to give .*again"):
        docstring_of(Base)(again)
