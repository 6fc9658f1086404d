"""What a wheel ships, checked from pyproject.toml without building one (fast).

Issue "Nothing silently wrong": the wheel lacked specdesign.plots and specdesign.openfast, which
an editable install hides. Here every package folder of the tree must be found by
[tool.setuptools.packages.find] and every file under specdesign/data must match a package-data
glob, the way setuptools matches them. .ci/run builds the real wheel, installs it in a fresh
venv and runs the demo from outside the checkout.
"""
from __future__ import annotations

import glob
import os
import tomllib
from pathlib import Path

import pytest

import specdesign
from specdesign.__main__ import main

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = ROOT / "pyproject.toml"

pytestmark = pytest.mark.skipif(not PYPROJECT.exists(), reason="needs the source checkout")


def _setuptools_config():
    return tomllib.loads(PYPROJECT.read_text())["tool"]["setuptools"]


def test_every_package_folder_is_found():
    from setuptools import find_packages

    include = _setuptools_config()["packages"]["find"]["include"]
    found = set(find_packages(where=str(ROOT), include=include))
    in_tree = {
        ".".join(d.relative_to(ROOT).parts)
        for top in ("specdesign", "loopshaping")
        for d in [ROOT / top, *(ROOT / top).rglob("*")]
        if d.is_dir() and (d / "__init__.py").exists()
    }
    assert {"specdesign.plots", "specdesign.openfast"} <= in_tree
    assert in_tree <= found, f"not shipped: {sorted(in_tree - found)}"


def test_every_data_file_is_package_data():
    patterns = _setuptools_config()["package-data"]["specdesign"]
    pkg = ROOT / "specdesign"
    # setuptools expands package-data globs relative to the package, recursively for "**"
    shipped = {Path(p).resolve() for pat in patterns for p in glob.glob(os.path.join(pkg, pat), recursive=True)
               if Path(p).is_file()}
    data = {p.resolve() for p in (pkg / "data").rglob("*") if p.is_file() and "__pycache__" not in p.parts}
    # the run-time files the turbine model and the OpenFAST tests read, and the attribution
    for name in ("NOTICE.md", "Cp_Ct_Cq.IEA15MW.txt", "IEA-15-240-RWT-Monopile_DISCON.IN", "sample_floating_19mps.1.lin"):
        assert (pkg / "data" / "iea15mw" / name).resolve() in data
    assert data <= shipped, f"not shipped: {sorted(str(p.relative_to(pkg)) for p in data - shipped)}"


def test_version_is_answered(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"specdesign {specdesign.__version__}"
    from packaging.version import Version

    Version(specdesign.__version__)  # a valid PEP 440 version (pyproject reads it from here)
