"""Finding and building OpenFAST: the cache, the environment variable, the errors. Fake
executables (shell scripts printing a version) and a fake CMake project stand in for the real
ones: no Fortran is compiled here (the real build is .ci/run's, tests/test_openfast_run.py runs it)."""
import os
import platform
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

from specdesign.openfast import install
from specdesign.openfast.install import (OpenFASTInstall, OpenFASTNotFound, build_openfast, check_deck_version,
                                         find_openfast)


def _fake_exe(path: Path, version="5.0.0"):
    path.parent.mkdir(parents=True, exist_ok=True)
    # the banner OpenFAST prints for -v (its version line has this form)
    path.write_text(f"#!/bin/sh\necho ' OpenFAST-v{version}'\necho ' Compiled on today'\n")
    path.chmod(0o755)
    return path


@pytest.fixture
def clean_env(monkeypatch, tmp_path):
    """No SPECDESIGN_OPENFAST, a PATH without openfast, an empty cache."""
    monkeypatch.delenv("SPECDESIGN_OPENFAST", raising=False)
    monkeypatch.setenv("SPECDESIGN_OPENFAST_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("PATH", "/usr/bin:/bin")
    if shutil.which("openfast"):
        pytest.skip("an openfast on /usr/bin shadows the cache")
    return tmp_path


def test_env_variable_names_the_executable(clean_env, monkeypatch):
    exe = _fake_exe(clean_env / "of" / "openfast", "4.1.2")
    _fake_exe(clean_env / "of" / "turbsim", "4.1.2")
    monkeypatch.setenv("SPECDESIGN_OPENFAST", str(exe))
    found = find_openfast()
    assert found.openfast == exe.resolve() and found.turbsim == (clean_env / "of" / "turbsim").resolve()
    assert found.version == "4.1.2" and found.version_tuple == (4, 1, 2)


def test_env_variable_names_a_folder_with_bin(clean_env, monkeypatch):
    _fake_exe(clean_env / "of" / "bin" / "openfast")
    _fake_exe(clean_env / "of" / "bin" / "turbsim")
    monkeypatch.setenv("SPECDESIGN_OPENFAST", str(clean_env / "of"))
    assert find_openfast().version == "5.0.0"


def test_env_variable_pointing_nowhere_says_how_to_fix(clean_env, monkeypatch):
    monkeypatch.setenv("SPECDESIGN_OPENFAST", str(clean_env / "nope"))
    with pytest.raises(OpenFASTNotFound, match="does not exist.*specdesign openfast build SOURCE"):
        find_openfast()


def test_path_then_cache(clean_env, monkeypatch):
    with pytest.raises(OpenFASTNotFound, match="no OpenFAST found.*openfast build SOURCE.*SPECDESIGN_OPENFAST"):
        find_openfast()
    entry = clean_env / "cache" / "0123456789abcdef"
    _fake_exe(entry / "bin" / "openfast")
    _fake_exe(entry / "bin" / "turbsim")
    (entry / "manifest.json").write_text('{"version": "5.0.0"}')
    assert find_openfast().openfast == (entry / "bin" / "openfast").resolve()
    # PATH comes before the cache
    _fake_exe(clean_env / "p" / "openfast", "4.2.1")
    _fake_exe(clean_env / "p" / "turbsim", "4.2.1")
    monkeypatch.setenv("PATH", f"{clean_env / 'p'}:/usr/bin:/bin")
    assert find_openfast().version == "4.2.1"


def test_openfast_without_turbsim(clean_env, monkeypatch):
    monkeypatch.setenv("SPECDESIGN_OPENFAST", str(_fake_exe(clean_env / "of" / "openfast")))
    with pytest.raises(OpenFASTNotFound, match="no turbsim"):
        find_openfast()
    assert find_openfast(require_turbsim=False).turbsim is None


def test_deck_version_mismatch_names_both():
    inst = OpenFASTInstall(Path("/x/openfast"), Path("/x/turbsim"), "4.1.2")
    with pytest.raises(ValueError, match=r"deck.fst is written for OpenFAST v5\.0 .* found is v4\.1\.2"):
        check_deck_version(inst, "5.0", "deck.fst")
    check_deck_version(inst, "4.1", "deck.fst")  # patch versions share a format
    check_deck_version(inst, None)


def test_build_refuses_a_bad_source(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        build_openfast(tmp_path / "nope.tar.gz", cache=tmp_path / "c")
    (tmp_path / "src").mkdir()
    with pytest.raises(ValueError, match="no CMakeLists.txt"):
        build_openfast(tmp_path / "src", cache=tmp_path / "c")
    (tmp_path / "x.tar.gz").write_text("not a tarball")
    with pytest.raises(ValueError, match="not a tar archive"):
        build_openfast(tmp_path / "x.tar.gz", cache=tmp_path / "c")


def test_build_names_missing_tools(tmp_path, monkeypatch):
    src = tmp_path / "src"
    src.mkdir()
    (src / "CMakeLists.txt").write_text("")
    real = shutil.which
    monkeypatch.setattr(install.shutil, "which", lambda n: None if n in ("cmake", "gfortran") else real(n))
    with pytest.raises(RuntimeError, match=r"cmake \(Debian: cmake\).*gfortran \(Debian: gfortran\)"):
        build_openfast(src, cache=tmp_path / "c", version="5.0.0", progress=False)
    with pytest.raises(ValueError, match="pass version="):  # neither in the name nor a git checkout
        build_openfast(src, cache=tmp_path / "c", progress=False)


# A CMake project with the two targets of OpenFAST's tree, each "building" a fake executable
# where OpenFAST's build puts the real one: the whole path (extract, cmake, make, copy,
# manifest, second call from the cache) without a compiler.
_FAKE_CMAKE = """cmake_minimum_required(VERSION 3.10)
project(fakeopenfast NONE)
add_custom_target(openfast ALL COMMAND ${CMAKE_COMMAND} -E make_directory glue-codes/openfast
                  COMMAND ${CMAKE_COMMAND} -E copy ${CMAKE_SOURCE_DIR}/fake.sh glue-codes/openfast/openfast)
add_custom_target(turbsim ALL COMMAND ${CMAKE_COMMAND} -E make_directory modules/turbsim
                  COMMAND ${CMAKE_COMMAND} -E copy ${CMAKE_SOURCE_DIR}/fake.sh modules/turbsim/turbsim)
"""


@pytest.mark.skipif(shutil.which("cmake") is None or shutil.which("make") is None, reason="needs cmake and make")
def test_build_from_tarball_then_cached(tmp_path, monkeypatch, capfd):
    src = tmp_path / "openfast-v9.9.9"
    src.mkdir()
    (src / "CMakeLists.txt").write_text(_FAKE_CMAKE)
    _fake_exe(src / "fake.sh", "9.9.9")
    tar = tmp_path / "openfast-v9.9.9-src.tar.gz"  # the version comes from the name
    with tarfile.open(tar, "w:gz") as t:
        t.add(src, arcname=src.name)
    monkeypatch.setattr(install, "_missing_tools", lambda: [])  # no gfortran needed by the fake project
    cache = tmp_path / "cache"
    found = build_openfast(tar, cache=cache)
    digest = install._digest(tar)[:16]
    assert found.openfast == cache / digest / "bin" / "openfast" and found.version == "9.9.9"
    assert (cache / digest / "manifest.json").is_file() and "-DDOUBLE_PRECISION=ON" in (cache / digest / "cmake.log").read_text()
    assert "openfast build:" in capfd.readouterr().err  # progress shown

    def no_rebuild(*a, **k):
        raise AssertionError("a second call must not build")

    monkeypatch.setattr(install, "_build", no_rebuild)
    assert build_openfast(tar, cache=cache) == found
    # the CLI finds it in the cache (a subprocess: its own environment)
    env = dict(os.environ, SPECDESIGN_OPENFAST_CACHE=str(cache), PATH="/usr/bin:/bin")
    env.pop("SPECDESIGN_OPENFAST", None)
    r = subprocess.run([sys.executable, "-m", "specdesign", "openfast", "find"], capture_output=True, text=True,
                       env=env, cwd=Path(__file__).parents[1])
    assert r.returncode == 0, r.stderr
    assert "version 9.9.9" in r.stdout


def test_cli_build_without_source_is_a_user_error():
    r = subprocess.run([sys.executable, "-m", "specdesign", "openfast", "build"], capture_output=True, text=True,
                       cwd=Path(__file__).parents[1])
    assert r.returncode == 2 and "needs SOURCE" in r.stderr and "Traceback" not in r.stderr


def _blas(folder: Path) -> Path:
    """A folder that looks like a BLAS/LAPACK install to the loader's search (empty stand-in files)."""
    folder.mkdir(parents=True, exist_ok=True)
    for lib in ("libblas.so.3", "liblapack.so.3"):
        (folder / lib).write_bytes(b"")
    return folder


def test_serial_openblas_goes_first_on_the_library_path(tmp_path, monkeypatch):
    # Debian's libopenblas0-serial is found where its package puts it; the user's own path follows it
    debian = _blas(tmp_path / "openblas-serial")
    monkeypatch.setattr(install, "_debian_openblas_serial", lambda: debian)
    env = install.run_environment({"LD_LIBRARY_PATH": "/opt/x", "HOME": "/h"})
    assert env["LD_LIBRARY_PATH"].split(os.pathsep) == [str(debian), "/opt/x"]
    assert env["HOME"] == "/h"
    assert install.run_environment({})["LD_LIBRARY_PATH"] == str(debian)
    # no optimised BLAS installed: the environment is left as it is
    monkeypatch.setattr(install, "_debian_openblas_serial", lambda: None)
    assert "LD_LIBRARY_PATH" not in install.run_environment({"HOME": "/h"})


def test_the_users_blas_choice_wins(tmp_path, monkeypatch):
    debian = _blas(tmp_path / "openblas-serial")
    monkeypatch.setattr(install, "_debian_openblas_serial", lambda: debian)
    mine = _blas(tmp_path / "mkl")
    # an explicit folder, or "system" for the libraries the executable links
    assert install.blas_folder({"SPECDESIGN_OPENFAST_BLAS": str(mine)}) == mine.resolve()
    env = install.run_environment({"SPECDESIGN_OPENFAST_BLAS": "system", "LD_LIBRARY_PATH": "/opt/x"})
    assert env["LD_LIBRARY_PATH"] == "/opt/x"
    # a libblas.so.3 already on the user's LD_LIBRARY_PATH is theirs: nothing is put before it
    env = install.run_environment({"LD_LIBRARY_PATH": str(mine)})
    assert env["LD_LIBRARY_PATH"] == str(mine)
    with pytest.raises(ValueError, match="SPECDESIGN_OPENFAST_BLAS=.*libblas.so.3.*'system'"):
        install.blas_folder({"SPECDESIGN_OPENFAST_BLAS": str(tmp_path / "nothing-here")})


def test_debian_serial_openblas_folder_is_the_packages():
    # the folder libopenblas0-serial installs: /usr/lib/<arch>-linux-gnu/openblas-serial (Debian's
    # multiarch path), found only when both libraries are there
    expected = Path("/usr/lib") / f"{platform.machine()}-linux-gnu" / "openblas-serial"
    present = all((expected / lib).is_file() for lib in ("libblas.so.3", "liblapack.so.3"))
    assert install._debian_openblas_serial() == (expected if present else None)
