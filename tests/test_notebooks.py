"""Execute every notebook in notebooks/ headless (reduced sizes via SPECDESIGN_FAST=1).

A notebook passes when every cell runs without error; the notebooks themselves assert the
physics they show (each ends with checks on the numbers it printed). Each executed notebook is
written to build/executed/notebooks/ for the documentation site's gallery (tests/test_site.py
runs after this file and builds the site with them).
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_executes(path, tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.setenv("SPECDESIGN_FAST", "1")
    # static figures, embedded as PNG in the executed copy (the documentation's gallery shows them);
    # the interactive notebooks keep ipympl off when told so
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    monkeypatch.setenv("SPECDESIGN_STATIC_FIGURES", "1")
    # the kernel imports this checkout even when the package is not installed
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}
    )
    client.execute()
    errors = [
        out for cell in nb.cells if cell.cell_type == "code" for out in cell.get("outputs", []) if out.get("output_type") == "error"
    ]
    assert not errors, errors
    # the executed copy, outputs included, for the documentation site's gallery
    # (docs/hooks/api_pages.py shows it while the notebook is unchanged)
    import hashlib

    nb.metadata["specdesign"] = {"source_sha256": hashlib.sha256(path.read_bytes()).hexdigest()}
    out = ROOT / "build" / "executed" / "notebooks" / path.name
    out.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, out)
