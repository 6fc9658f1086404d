"""Notebooks are kept in git without outputs or execution counts.

Outputs are large, machine-specific and stale as soon as the code changes; the notebooks are
executed by tests/test_notebooks.py instead. The fix for a failure is nbstripout (a dev tool).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
FIX = ("strip it before committing: `nbstripout notebooks/*.ipynb` (nbstripout is in the dev extra; "
       "`nbstripout --install` in the checkout strips on every commit)")


def stored_outputs(path: Path) -> list[str]:
    """What a notebook file keeps that it should not: one line per code cell with outputs or an
    execution count (cells numbered from 0, as nbformat indexes them)."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    found = []
    for i, cell in enumerate(nb.get("cells", [])):
        if cell.get("cell_type") != "code":
            continue
        if cell.get("outputs"):
            found.append(f"cell {i}: {len(cell['outputs'])} output(s)")
        if cell.get("execution_count") is not None:
            found.append(f"cell {i}: execution_count {cell['execution_count']}")
    return found


def test_there_are_notebooks():
    assert len(NOTEBOOKS) >= 7


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_has_no_outputs(path):
    found = stored_outputs(path)
    assert not found, f"{path.relative_to(ROOT)} is committed with outputs ({'; '.join(found[:5])}); {FIX}"


def test_the_check_catches_outputs_and_the_advised_fix_removes_them(tmp_path):
    """The checker flags an executed notebook, and the command the message gives clears it."""
    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("nbstripout")
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell("1 + 1", execution_count=3)
    cell.outputs = [nbformat.v4.new_output("execute_result", data={"text/plain": "2"}, execution_count=3)]
    nb.cells = [nbformat.v4.new_markdown_cell("# t"), cell]
    path = tmp_path / "executed.ipynb"
    nbformat.write(nb, path)
    assert stored_outputs(path) == ["cell 1: 1 output(s)", "cell 1: execution_count 3"]
    r = subprocess.run([sys.executable, "-m", "nbstripout", str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert stored_outputs(path) == []
    assert nbformat.read(path, as_version=4).cells[1].source == "1 + 1"  # the code is kept
