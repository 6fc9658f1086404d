"""Documentation in the code (issue 13): numpydoc docstrings on every public name of
loopshaping, and their Examples run."""
from __future__ import annotations

import doctest
import importlib
import inspect
import warnings

import pytest

MODULES = ("qft", "templates", "specs", "bounds", "freqresp", "controller", "nichols", "auto", "check",
           "interactive", "hinf", "wellposed", "reduction")
CODES = {"GL08", "PR01", "PR02", "RT01"}  # no docstring, undocumented/unknown parameters, no Returns


def _public(module):
    mod = importlib.import_module(f"loopshaping.{module}")
    return [(module, name) for name in mod.__all__
            if inspect.isfunction(getattr(mod, name)) or inspect.isclass(getattr(mod, name))]


@pytest.mark.parametrize("module,name", [p for m in MODULES for p in _public(m)])
def test_numpydoc(module, name):
    validate = pytest.importorskip("numpydoc.validate").validate
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        errors = [(c, msg) for c, msg in validate(f"loopshaping.{module}.{name}")["errors"] if c in CODES]
    assert not errors, errors


@pytest.mark.parametrize("module", MODULES)
def test_examples_run(module):
    mod = importlib.import_module(f"loopshaping.{module}")
    res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0
