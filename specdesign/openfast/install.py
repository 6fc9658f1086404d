"""OpenFAST and TurbSim executables: found (environment variable, PATH, build cache) or built
from a source tarball or folder into a cache outside the checkout.

A plain ``pip install`` of the workbench never compiles Fortran: building is an explicit
command, ``python -m specdesign openfast build SOURCE`` (:func:`build_openfast`), and a user
who has OpenFAST already points the workbench to it with ``SPECDESIGN_OPENFAST`` (an
executable, or a folder holding ``openfast`` and ``turbsim``) or puts it on ``PATH``.

Cache layout (default ``~/.cache/specdesign/openfast``, or ``SPECDESIGN_OPENFAST_CACHE``)::

    <cache>/<digest16>/          16 hex digits of the source's SHA-256
        <source folder>/         the tarball, extracted (a source folder is built in place)
        build/                   cmake's build folder (kept: a rebuild is incremental)
        cmake.log, make.log      the build's output
        bin/openfast, bin/turbsim
        manifest.json            version, source, digest, cmake options (written last)
    <cache>/<digest16>.lock      held while building (two calls never build at once)

BLAS: OpenFAST and TurbSim link ``libblas.so.3``/``liblapack.so.3`` dynamically, and on Debian
those are the reference (unoptimised) BLAS unless an optimised one is installed. OpenFAST's
linearisation spends nearly all its time in one LU solve of its glue system (LAPACK
``dgetrf``/``dgetrs``, then ``dgemm``), and its time steps in small ``dtrsm``/``dgemm`` calls, so
every process of the workbench is run with Debian's *serial* OpenBLAS when it is installed
(``libopenblas0-serial``, :func:`blas_folder`): its folder goes first on ``LD_LIBRARY_PATH``
(:func:`run_environment`); nothing is rebuilt. Serial, not threaded: campaigns run one OpenFAST
process per core. ``SPECDESIGN_OPENFAST_BLAS`` overrides the choice: a folder holding another
``libblas.so.3``/``liblapack.so.3``, or ``system`` for the libraries the executable links; a
``libblas.so.3`` already on the user's ``LD_LIBRARY_PATH`` is left to win.
"""
from __future__ import annotations

import ctypes.util
import fcntl
import hashlib
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tarfile
import time
from dataclasses import dataclass
from pathlib import Path

__all__ = ["OpenFASTInstall", "OpenFASTNotFound", "find_openfast", "build_openfast", "openfast_version",
           "check_deck_version", "default_cache", "CMAKE_OPTIONS", "BUILD_TARGETS", "blas_folder", "run_environment"]

#: cmake options of :func:`build_openfast`: an optimised, double-precision build without tests
CMAKE_OPTIONS = ("-DCMAKE_BUILD_TYPE=Release", "-DDOUBLE_PRECISION=ON", "-DBUILD_TESTING=OFF")
#: the only targets built (the glue code and the wind-field generator)
BUILD_TARGETS = ("openfast", "turbsim")
_ENV_EXE = "SPECDESIGN_OPENFAST"
_ENV_CACHE = "SPECDESIGN_OPENFAST_CACHE"
_ENV_BLAS = "SPECDESIGN_OPENFAST_BLAS"
_BLAS_LIBS = ("libblas.so.3", "liblapack.so.3")
_BUILD_HINT = ("build one with `python -m specdesign openfast build SOURCE` (SOURCE: an OpenFAST source tarball "
               "or folder, e.g. openfast-v5.0.0-src.tar.gz; needs gfortran, cmake and LAPACK) or point "
               f"{_ENV_EXE} to an openfast executable or to a folder holding openfast and turbsim")


class OpenFASTNotFound(FileNotFoundError):
    """No OpenFAST (or TurbSim) executable was found; the message says how to build or point to one."""


@dataclass(frozen=True)
class OpenFASTInstall:
    """An OpenFAST glue-code executable, the TurbSim beside it and the version they report.

    Parameters
    ----------
    openfast : pathlib.Path
        The ``openfast`` executable.
    turbsim : pathlib.Path or None
        The ``turbsim`` executable (None when only OpenFAST was found: full-field winds then
        cannot be generated).
    version : str
        The version OpenFAST prints, e.g. ``"5.0.0"``.
    """

    openfast: Path
    turbsim: Path | None
    version: str

    @property
    def version_tuple(self) -> tuple:
        """(major, minor, patch) integers of :attr:`version`."""
        return tuple(int(x) for x in self.version.split(".")[:3])


def default_cache() -> Path:
    """The build cache: ``$SPECDESIGN_OPENFAST_CACHE`` or ``~/.cache/specdesign/openfast``.

    Returns
    -------
    pathlib.Path
        The folder (not created).
    """
    env = os.environ.get(_ENV_CACHE)
    return Path(env).expanduser() if env else Path.home() / ".cache" / "specdesign" / "openfast"


def _debian_openblas_serial() -> Path | None:
    """Debian's serial OpenBLAS folder (package ``libopenblas0-serial``) for this machine's architecture, if installed."""
    folder = Path("/usr/lib") / f"{platform.machine()}-linux-gnu" / "openblas-serial"
    return folder if all((folder / lib).is_file() for lib in _BLAS_LIBS) else None


def blas_folder(environ=None) -> Path | None:
    """The folder of the ``libblas.so.3``/``liblapack.so.3`` OpenFAST and TurbSim are run with.

    ``$SPECDESIGN_OPENFAST_BLAS`` when set (a folder, or ``system``: None), else None when the
    user's ``LD_LIBRARY_PATH`` already holds a ``libblas.so.3`` (theirs wins), else Debian's
    serial OpenBLAS (``/usr/lib/<arch>-linux-gnu/openblas-serial``, package
    ``libopenblas0-serial``) when installed, else None.

    Parameters
    ----------
    environ : mapping, optional
        The environment read (default ``os.environ``).

    Returns
    -------
    pathlib.Path or None
        The folder put first on ``LD_LIBRARY_PATH``; None: the libraries the executable links.

    Raises
    ------
    ValueError
        ``SPECDESIGN_OPENFAST_BLAS`` names something that is neither ``system`` nor a folder
        holding ``libblas.so.3`` or ``liblapack.so.3``.
    """
    environ = os.environ if environ is None else environ
    chosen = environ.get(_ENV_BLAS)
    if chosen is not None:
        if chosen.strip().lower() in ("", "system"):
            return None
        folder = Path(chosen).expanduser()
        if not any((folder / lib).is_file() for lib in _BLAS_LIBS):
            raise ValueError(f"{_ENV_BLAS}={chosen!r} must be a folder holding libblas.so.3 and/or liblapack.so.3 "
                             "(e.g. /usr/lib/x86_64-linux-gnu/openblas-serial), or 'system' for the libraries "
                             "the executables link")
        return folder.resolve()
    user = [Path(p) for p in environ.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p]
    if any((p / "libblas.so.3").is_file() for p in user):
        return None
    return _debian_openblas_serial()


def run_environment(environ=None) -> dict:
    """The environment of an OpenFAST or TurbSim process: ``environ`` with :func:`blas_folder` first on ``LD_LIBRARY_PATH``.

    Parameters
    ----------
    environ : mapping, optional
        The base environment (default ``os.environ``); not modified.

    Returns
    -------
    dict
        A new environment.
    """
    env = dict(os.environ if environ is None else environ)
    folder = blas_folder(env)
    if folder is not None:
        env["LD_LIBRARY_PATH"] = os.pathsep.join([str(folder), *(p for p in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p)])
    return env


def openfast_version(executable: str | os.PathLike, timeout: float = 60.0) -> str:
    """The version an OpenFAST (or TurbSim) executable reports with ``-v``.

    Parameters
    ----------
    executable : str or os.PathLike
        The executable.
    timeout : float, default 60.0
        Seconds to wait for it (s).

    Returns
    -------
    str
        ``"major.minor.patch"``, e.g. ``"5.0.0"``.

    Raises
    ------
    OpenFASTNotFound
        The file does not exist or cannot be executed.
    RuntimeError
        It ran but printed no version.
    """
    exe = Path(executable)
    if not exe.is_file() or not os.access(exe, os.X_OK):
        raise OpenFASTNotFound(f"{exe} is not an executable file; {_BUILD_HINT}")
    try:
        r = subprocess.run([str(exe), "-v"], capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise OpenFASTNotFound(f"{exe} could not be run to read its version ({e}); {_BUILD_HINT}") from None
    text = r.stdout + r.stderr
    # OpenFAST prints e.g. "OpenFAST-v5.0.0" (or "v5.0.0-dirty" from a git build)
    found = re.search(r"v(\d+)\.(\d+)\.(\d+)", text)
    if found is None:
        tail = " ".join(text.split())[-300:]
        hint = (" (built from a source without git information: rebuild with cmake -DGIT_DESCRIBE=vX.Y.Z, as "
                "`python -m specdesign openfast build` does)") if "HEAD-HASH-NOTFOUND" in text else ""
        raise RuntimeError(f"{exe} -v printed no version 'vX.Y.Z'{hint} (it printed: {tail!r})")
    return ".".join(found.groups())


def _from_folder(folder: Path):
    """The openfast and turbsim executables in a folder or its bin/ (None where absent)."""
    out = []
    for name in ("openfast", "turbsim"):
        hit = None
        for d in (folder, folder / "bin"):
            for n in (name, "TurbSim" if name == "turbsim" else name, name + ".exe"):
                if (d / n).is_file():
                    hit = d / n
                    break
            if hit:
                break
        out.append(hit)
    return out


def find_openfast(require_turbsim: bool = True) -> OpenFASTInstall:
    """Find OpenFAST and TurbSim: ``$SPECDESIGN_OPENFAST``, then ``PATH``, then the build cache.

    ``SPECDESIGN_OPENFAST`` names the ``openfast`` executable (TurbSim is looked for beside it,
    then on PATH) or a folder holding both (or a ``bin/`` holding both). On PATH the names are
    ``openfast`` and ``turbsim`` (or ``TurbSim``). The build cache is :func:`default_cache`;
    of several builds there, the newest.

    Parameters
    ----------
    require_turbsim : bool, default True
        Fail when OpenFAST is found without a TurbSim.

    Returns
    -------
    OpenFASTInstall
        The executables and the version OpenFAST reports.

    Raises
    ------
    OpenFASTNotFound
        None found (or an environment variable naming a missing file); the message says how
        to build one or point to one.

    Examples
    --------
    >>> install = find_openfast()  # doctest: +SKIP
    >>> install.version  # doctest: +SKIP
    '5.0.0'
    """
    env = os.environ.get(_ENV_EXE)
    if env:
        p = Path(env).expanduser()
        if p.is_dir():
            exe, ts = _from_folder(p)
            if exe is None:
                raise OpenFASTNotFound(f"{_ENV_EXE}={env}: the folder holds no openfast executable (nor its bin/); "
                                       f"{_BUILD_HINT}")
        elif p.is_file():
            exe, ts = p, _from_folder(p.parent)[1]
        else:
            raise OpenFASTNotFound(f"{_ENV_EXE}={env} does not exist; {_BUILD_HINT}")
        ts = ts or _which_turbsim()
        return _install(exe, ts, require_turbsim, f"{_ENV_EXE}={env}")
    on_path = shutil.which("openfast")
    if on_path:
        return _install(Path(on_path), _which_turbsim(), require_turbsim, "PATH")
    builds = sorted(default_cache().glob("*/manifest.json"), key=lambda p: p.stat().st_mtime, reverse=True)
    for manifest in builds:
        exe, ts = _from_folder(manifest.parent / "bin")
        if exe is not None:
            return _install(exe, ts, require_turbsim, f"the build cache {manifest.parent}")
    raise OpenFASTNotFound(f"no OpenFAST found (not in {_ENV_EXE}, not on PATH, no build in {default_cache()}); "
                           f"{_BUILD_HINT}")


def _which_turbsim():
    hit = shutil.which("turbsim") or shutil.which("TurbSim")
    return Path(hit) if hit else None


def _install(exe: Path, ts, require_turbsim: bool, where: str) -> OpenFASTInstall:
    if ts is None and require_turbsim:
        raise OpenFASTNotFound(f"OpenFAST found at {exe} ({where}) but no turbsim beside it nor on PATH; put turbsim "
                               f"beside openfast, or {_BUILD_HINT}")
    return OpenFASTInstall(openfast=exe.resolve(), turbsim=None if ts is None else Path(ts).resolve(),
                           version=openfast_version(exe))


def check_deck_version(install: OpenFASTInstall, deck_version: str | None, deck: str | os.PathLike = "the deck"):
    """Refuse a deck written for another OpenFAST format than the executable's.

    Input formats change between minor versions (v5.0 added SeaState's ``WvCrntMod``, for
    one), so major and minor must agree.

    Parameters
    ----------
    install : OpenFASTInstall
        The executables.
    deck_version : str or None
        The OpenFAST version the deck's files are written for (``"5.0"``, ``"5.0.0"``); None:
        unknown, not checked.
    deck : str or os.PathLike
        The deck's name, for the message.

    Raises
    ------
    ValueError
        Major or minor versions differ (the message names both).
    """
    if deck_version is None:
        return
    want = tuple(int(x) for x in str(deck_version).split(".")[:2])
    if want != install.version_tuple[:2]:
        raise ValueError(f"{deck} is written for OpenFAST v{deck_version} but the OpenFAST found is v{install.version} "
                         f"({install.openfast}): use a v{'.'.join(map(str, want))} executable ({_ENV_EXE}) or a "
                         f"deck converted to v{install.version} (openfast-io reads and writes decks)")


def _digest(source: Path) -> str:
    """SHA-256 of a tarball's bytes, or of a source folder's relative paths and file contents
    (its .git and build folders left out)."""
    h = hashlib.sha256()
    if source.is_file():
        with open(source, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        return h.hexdigest()
    skip = {".git", "build"}
    for root, dirs, files in os.walk(source):
        dirs[:] = sorted(d for d in dirs if d not in skip)
        for name in sorted(files):
            p = Path(root) / name
            h.update(str(p.relative_to(source)).encode() + b"\0")
            with open(p, "rb") as f:
                h.update(f.read())
    return h.hexdigest()


def _missing_tools() -> list:
    """The build prerequisites absent from this machine, each with its Debian package."""
    missing = []
    if shutil.which("cmake") is None:
        missing.append("cmake (Debian: cmake)")
    if shutil.which(os.environ.get("FC", "gfortran")) is None:
        missing.append("a Fortran compiler, gfortran (Debian: gfortran)")
    if shutil.which("make") is None:
        missing.append("make (Debian: make)")
    if ctypes.util.find_library("lapack") is None or ctypes.util.find_library("blas") is None:
        missing.append("LAPACK and BLAS (Debian: liblapack-dev libblas-dev)")
    return missing


def _manifest(folder: Path):
    """The manifest of a finished build in ``folder``, or None."""
    m = folder / "manifest.json"
    if not m.is_file():
        return None
    data = json.loads(m.read_text())
    exe, ts = _from_folder(folder / "bin")
    return data if exe is not None and ts is not None else None


def build_openfast(source: str | os.PathLike, cache: str | os.PathLike | None = None, *, version: str | None = None,
                   jobs: int | None = None, progress: bool = True) -> OpenFASTInstall:
    """Build ``openfast`` and ``turbsim`` from a source tarball or folder, cached by the source's digest.

    cmake with :data:`CMAKE_OPTIONS` (Release, double precision, no tests), then only the
    :data:`BUILD_TARGETS`; the executables are copied to ``<cache>/<digest16>/bin`` and a
    ``manifest.json`` is written last. A second call with the same source returns at once
    (after hashing the source); an interrupted build resumes where ``make`` stopped. A lock
    file makes a concurrent call wait for the first one's build. Takes 11-34 minutes on 2 cores.

    Parameters
    ----------
    source : str or os.PathLike
        An OpenFAST source tarball (``.tar.gz``, ``.tgz``, ``.tar``) or source folder (the one
        holding its top ``CMakeLists.txt``).
    cache : str or os.PathLike, optional
        Cache folder; default :func:`default_cache`.
    version : str, optional
        The source's version (``"5.0.0"``), compiled into the executables (cmake
        ``-DGIT_DESCRIBE``) so that they report it: a tarball has no git history to take it
        from. Default: read from the source's name (``openfast-v5.0.0-src.tar.gz``); a git
        checkout without it in its name uses ``git describe``.
    jobs : int, optional
        Parallel compile jobs; default the number of CPUs.
    progress : bool, default True
        Print make's ``[ nn%]`` lines to stderr as it goes.

    Returns
    -------
    OpenFASTInstall
        The built executables and their version.

    Raises
    ------
    FileNotFoundError
        ``source`` does not exist.
    ValueError
        ``source`` is neither a tarball nor a folder with a ``CMakeLists.txt``, or its
        version is neither given nor in its name (nor a git checkout).
    RuntimeError
        gfortran, cmake, make or LAPACK/BLAS missing (naming the Debian packages), or cmake or
        make failed (the tail of its log and the log's path).

    Examples
    --------
    >>> build_openfast("openfast-v5.0.0-src.tar.gz")  # doctest: +SKIP
    OpenFASTInstall(openfast=PosixPath('/root/.cache/specdesign/openfast/947a4938a595bfcb/bin/openfast'), ...)
    """
    source = Path(source).expanduser().resolve()
    if not source.exists():
        raise FileNotFoundError(f"source={str(source)!r} does not exist: give an OpenFAST source tarball or folder")
    is_tar = source.is_file()
    if is_tar and not tarfile.is_tarfile(source):
        raise ValueError(f"source={str(source)!r} is not a tar archive: give an OpenFAST source tarball or folder")
    if not is_tar and not (source / "CMakeLists.txt").is_file():
        raise ValueError(f"source={str(source)!r} has no CMakeLists.txt: give the OpenFAST source's top folder")
    if version is None:
        named = re.search(r"v?(\d+\.\d+\.\d+)", source.name)
        if named is None and not (source.is_dir() and (source / ".git").exists()):
            raise ValueError(f"source={str(source)!r}: its version is not in its name; pass version='X.Y.Z' "
                             "(--source-version on the command line)")
        version = named.group(1) if named else None
    elif not re.fullmatch(r"\d+\.\d+\.\d+", str(version)):
        raise ValueError(f"version={version!r} must be 'major.minor.patch', e.g. '5.0.0'")
    cache = Path(cache).expanduser() if cache is not None else default_cache()
    digest = _digest(source)[:16]
    folder = cache / digest
    if _manifest(folder) is None:
        cache.mkdir(parents=True, exist_ok=True)
        with open(cache / f"{digest}.lock", "w") as lock:
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                print(f"openfast build: another process is building {folder}; waiting for it", file=sys.stderr)
                fcntl.flock(lock, fcntl.LOCK_EX)
            if _manifest(folder) is None:  # the other process may have finished it
                _build(source, is_tar, folder, version, jobs or os.cpu_count() or 1, progress)
    exe, ts = _from_folder(folder / "bin")
    return OpenFASTInstall(openfast=exe, turbsim=ts, version=json.loads((folder / "manifest.json").read_text())["version"])


def _build(source: Path, is_tar: bool, folder: Path, version, jobs: int, progress: bool) -> None:
    missing = _missing_tools()
    if missing:
        raise RuntimeError("building OpenFAST needs " + ", ".join(missing) + "; install them (Debian: apt-get install "
                           "gfortran cmake make liblapack-dev libblas-dev) or point SPECDESIGN_OPENFAST to an "
                           "existing OpenFAST")
    folder.mkdir(parents=True, exist_ok=True)
    src = source
    if is_tar:
        src = _source_folder(folder)
        if src is None:
            _say(progress, f"openfast build: extracting {source.name} into {folder}")
            with tarfile.open(source) as tar:
                tar.extractall(folder, filter="data")
            src = _source_folder(folder)
            if src is None:
                raise ValueError(f"source={str(source)!r}: the tarball holds no folder with a CMakeLists.txt")
    build = folder / "build"
    t0 = time.monotonic()
    options = list(CMAKE_OPTIONS) + ([f"-DGIT_DESCRIBE=v{version}"] if version else [])
    # configure when new, or when the version compiled in differs (an adopted build folder):
    # a reconfigure recompiles only the version module and relinks
    cached = (build / "CMakeCache.txt").read_text(errors="replace") if (build / "CMakeCache.txt").is_file() else ""
    if not (build / "Makefile").is_file() or (version and f"GIT_DESCRIBE:UNINITIALIZED=v{version}" not in cached):
        _say(progress, f"openfast build: cmake {' '.join(options)} (log: {folder / 'cmake.log'})")
        _run(["cmake", "-S", str(src), "-B", str(build), *options], folder / "cmake.log", False)
    _say(progress, f"openfast build: make {' '.join(BUILD_TARGETS)} with {jobs} jobs; 11-34 min on 2 cores "
                   f"(log: {folder / 'make.log'})")
    _run(["cmake", "--build", str(build), "--target", *BUILD_TARGETS, "--", f"-j{jobs}"], folder / "make.log",
         progress)
    built = {"openfast": build / "glue-codes" / "openfast" / "openfast",
             "turbsim": build / "modules" / "turbsim" / "turbsim"}
    bin_ = folder / "bin"
    bin_.mkdir(exist_ok=True)
    for name, path in built.items():
        if not path.is_file():
            raise RuntimeError(f"the build finished but {path} is missing (log: {folder / 'make.log'})")
        shutil.copy2(path, bin_ / name)
    version = openfast_version(bin_ / "openfast")
    manifest = {"version": version, "source": str(source), "digest16": folder.name,
                "cmake_options": options, "targets": list(BUILD_TARGETS),
                "build_seconds": round(time.monotonic() - t0, 1), "built": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
    (folder / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")
    _say(progress, f"openfast build: OpenFAST v{version} in {bin_}")


def _source_folder(folder: Path):
    """The extracted source's top folder (the one with CMakeLists.txt) under a cache entry, or None."""
    for d in sorted(folder.iterdir()):
        if d.is_dir() and d.name not in ("build", "bin") and (d / "CMakeLists.txt").is_file():
            return d
    return None


def _say(progress: bool, text: str) -> None:
    if progress:
        print(text, file=sys.stderr, flush=True)


def _run(cmd, log: Path, progress: bool) -> None:
    """Run a build step with its output in ``log`` (appended); make's percent lines echoed when asked."""
    pct = re.compile(r"^\[\s*(\d+)%\]")
    last = None
    with open(log, "a") as f:
        f.write(f"$ {' '.join(cmd)}\n")
        f.flush()
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                stdin=subprocess.DEVNULL)
        for line in proc.stdout:
            f.write(line)
            m = pct.match(line)
            if progress and m and m.group(1) != last:
                last = m.group(1)
                print(f"openfast build: {last:>3}%", file=sys.stderr, flush=True)
        rc = proc.wait()
        f.write(f"rc={rc}\n")
    if rc != 0:
        tail = log.read_text(errors="replace").splitlines()[-25:]
        hint = ""
        if any("LAPACK" in t or "BLAS" in t for t in tail):
            hint = " (LAPACK/BLAS not found: Debian apt-get install liblapack-dev libblas-dev)"
        raise RuntimeError(f"{cmd[0]} {cmd[1]} failed with exit code {rc}{hint}; the end of {log}:\n" + "\n".join(tail))
