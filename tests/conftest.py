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


@pytest.fixture(scope="session")
def openfast():
    """OpenFAST for the tests that run it (``specdesign.openfast.OpenFASTInstall``).

    With ``SPECDESIGN_OPENFAST_SOURCE`` (CI: the vendored source tarball, whose build ``.ci/run``
    starts in the background before the suite) it is ``build_openfast(source)``: that waits for
    a build in progress (its lock) and returns at once from the cache. Otherwise the OpenFAST a
    user has (``find_openfast``). Skipped when there is none, failed instead when
    ``SPECDESIGN_REQUIRE_OPENFAST=1``.
    """
    from specdesign.openfast import OpenFASTNotFound, build_openfast, find_openfast

    required = os.environ.get("SPECDESIGN_REQUIRE_OPENFAST") == "1"
    source = os.environ.get("SPECDESIGN_OPENFAST_SOURCE")
    try:
        return build_openfast(source) if source else find_openfast()
    except (OpenFASTNotFound, RuntimeError, ValueError) as e:
        if required:
            pytest.fail(f"SPECDESIGN_REQUIRE_OPENFAST=1 but no OpenFAST: {e}")
        pytest.skip(f"no OpenFAST: {e}")


def pytest_collection_modifyitems(config, items):
    # the tests that run OpenFAST go last: in CI its build (started in the background by
    # .ci/run) has the rest of the suite's time to finish, and one `python -m pytest -q` runs all
    items.sort(key=lambda item: "openfast" in getattr(item, "fixturenames", ()))


@pytest.fixture(scope="session")
def rosco_cases():
    """The rosco package's Test_Cases folder (skipped without the package)."""
    from specdesign.rosco import rosco_test_cases

    try:
        return rosco_test_cases()
    except ModuleNotFoundError as e:
        pytest.skip(f"the rosco package is not installed ({e})")


@pytest.fixture(scope="session")
def discon_in(rosco_cases):
    """The rosco package's DISCON.IN of the IEA 15 MW monopile (skipped without the package)."""
    return rosco_cases / "IEA-15-240-RWT/IEA-15-240-RWT-Monopile/IEA-15-240-RWT-Monopile_DISCON.IN"
