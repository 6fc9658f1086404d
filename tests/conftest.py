"""Shared fixtures.

`shared_data` points at ../shared/data/iea15mw when the checkout sits beside it; tests that
need it skip otherwise. Everything the package needs at run time is shipped in
specdesign/data, so only cross-checks against the original files use this fixture.
"""
from __future__ import annotations

import os
import sys
import textwrap
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
def benchmark_script():
    """``load(name)``: the script ``benchmarks/<name>.py`` as a module (not run as ``__main__``),
    with its folder on ``sys.path`` while it loads: the scripts import their neighbours."""
    import importlib.util

    def load(name):
        folder = str(ROOT / "benchmarks")
        sys.path.insert(0, folder)
        try:
            spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        finally:
            sys.path.remove(folder)
        return module

    return load


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


# A fake OpenFAST for campaign tests (tests/test_openfast_campaign.py, tests/test_forward_campaign.py):
# a Python script that counts its calls, reads the case's input files (``keys``: value then
# name, as OpenFAST's), runs a test's own body (which fills ``ch``: channel → (unit, series) and
# ``t``) and writes them as a binary .outb (file ID 3) that the campaign reads back. Bodies use
# str.format's doubled braces.
_FAKE_HEAD = textwrap.dedent('''\
    #!{python}
    import ctypes, math, re, struct, sys
    from pathlib import Path
    import numpy as np
    fst = Path(sys.argv[1]); root = fst.stem
    with open("{calls}", "a") as f:
        f.write(root + "\\n")
    def keys(p):
        out = {{}}
        for line in Path(p).read_text().splitlines():
            t = line.split()
            if len(t) > 1:
                out.setdefault(t[1], t[0].strip('"'))
        return out
''')
_FAKE_TAIL = textwrap.dedent('''\
    names = ["Time"] + list(ch); units = ["(s)"] + [u for u, _ in ch.values()]
    data = np.column_stack([a for _, a in ch.values()])
    b = struct.pack("h", 3) + struct.pack("i", data.shape[1]) + struct.pack("i", t.size)
    b += struct.pack("d", t[0]) + struct.pack("d", dt)
    b += struct.pack("i", 4) + b"fake"
    b += b"".join(n.ljust(10).encode() for n in names) + b"".join(u.ljust(10).encode() for u in units)
    b += data.astype("<f8").tobytes()
    Path(root + ".outb").write_bytes(b)
    print("OpenFAST terminated normally.")
''')


@pytest.fixture
def fake_openfast(tmp_path, monkeypatch):
    """``make(body) -> (OpenFASTInstall, calls file)``: the fake OpenFAST running ``body`` (a
    dedented script fragment, see ``_FAKE_HEAD``) and a fake TurbSim; winds cached in tmp_path."""
    from specdesign.openfast import OpenFASTInstall  # needs openfast_io (optional): only when a test asks

    def make(body: str):
        calls = tmp_path / "calls.txt"
        calls.write_text("")
        exe = tmp_path / "openfast"
        exe.write_text((_FAKE_HEAD + textwrap.dedent(body) + _FAKE_TAIL).format(python=sys.executable, calls=calls))
        exe.chmod(0o755)
        ts = tmp_path / "turbsim"
        ts.write_text('#!/bin/sh\nroot="${1%.inp}"\necho bts > "$root.bts"\n')
        ts.chmod(0o755)
        monkeypatch.setenv("SPECDESIGN_TURBSIM_CACHE", str(tmp_path / "winds"))
        return OpenFASTInstall(exe, ts, "5.0.0"), calls
    return make
