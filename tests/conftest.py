"""Shared fixtures.

`shared_data` points at ../shared/data/iea15mw when the checkout sits beside it; tests that
need it skip otherwise. Everything the package needs at run time is shipped in
specdesign/data, so only cross-checks against the original files use this fixture.
"""
from __future__ import annotations

import os
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def shared_data() -> Path:
    path = Path(os.environ.get("SPECDESIGN_SHARED", ROOT.parent / "shared")) / "data" / "iea15mw"
    if not path.is_dir():
        pytest.skip("../shared/data/iea15mw is not beside this checkout")
    return path


@pytest.fixture(scope="session")
def package_data() -> Path:
    return ROOT / "specdesign" / "data" / "iea15mw"
