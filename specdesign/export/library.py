"""The compiled Bladed-interface libraries: :func:`discon_library` builds ``discon.c`` once per
source, :func:`forward_library` builds ``forward.c`` (the library forwarding each call to Python).

The C sources ship in the package (``specdesign/export/discon.c``, ``forward.c``); the system C
compiler builds each (``cc -O2 -shared -fPIC``, the C standard library and libm only: nothing of
Python at run time) into a cache folder keyed by the digest of the sources and the compile
command, so one library serves every design and a second call is instant. ``forward.c``
includes ``discon.c`` (its parameter-file reader, torque law and limits), so its digest covers both.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["SOURCE", "FORWARD_SOURCE", "CompilerNotFoundError", "default_cache", "discon_library", "forward_library"]

#: The C source of the library.
SOURCE = Path(__file__).with_name("discon.c")
#: The C source of the forwarding library (it includes :data:`SOURCE`; POSIX sockets).
FORWARD_SOURCE = Path(__file__).with_name("forward.c")
_FLAGS = ("-O2", "-shared", "-fPIC", "-std=c99", "-D_DEFAULT_SOURCE")
_NAME = "libspecdesign_discon"
_FORWARD_NAME = "libspecdesign_forward"


class CompilerNotFoundError(RuntimeError):
    """No C compiler to build the exported controller (install one, or name it with ``CC``)."""


def default_cache() -> Path:
    """The cache folder of compiled libraries: ``$XDG_CACHE_HOME/specdesign/discon`` (``~/.cache`` by default).

    Returns
    -------
    pathlib.Path
        The folder (not created here).
    """
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "specdesign" / "discon"


def _suffix() -> str:
    return ".dll" if sys.platform == "win32" else ".dylib" if sys.platform == "darwin" else ".so"


def discon_library(*, cache: str | Path | None = None, compiler: str | None = None) -> Path:
    """The compiled DISCON library, built from :data:`SOURCE` on the first call.

    Parameters
    ----------
    cache : str or pathlib.Path, optional
        Cache folder (default :func:`default_cache`); the library goes into a sub-folder named
        by the first 16 hex digits of the SHA-256 of the source and the compile command.
    compiler : str, optional
        The C compiler (default: ``$CC``, else ``cc``, else ``gcc`` on PATH).

    Returns
    -------
    pathlib.Path
        The shared library, exporting ``DISCON``.

    Raises
    ------
    CompilerNotFoundError
        If no C compiler is found.
    RuntimeError
        If the compiler fails (its message is quoted).
    """
    return _build(SOURCE, (SOURCE,), _NAME, cache, compiler)


def forward_library(*, cache: str | Path | None = None, compiler: str | None = None) -> Path:
    """The compiled forwarding library, built from :data:`FORWARD_SOURCE` on the first call.

    Its ``DISCON`` sends each call's swap array to a Python process over a local socket and
    writes back the commands it answers (:mod:`specdesign.export.forward`). POSIX only (AF_UNIX
    sockets).

    Parameters
    ----------
    cache : str or pathlib.Path, optional
        Cache folder (default :func:`default_cache`); the library goes into a sub-folder named
        by the first 16 hex digits of the SHA-256 of both sources and the compile command.
    compiler : str, optional
        The C compiler (default: ``$CC``, else ``cc``, else ``gcc`` on PATH).

    Returns
    -------
    pathlib.Path
        The shared library, exporting ``DISCON``.

    Raises
    ------
    CompilerNotFoundError
        If no C compiler is found.
    RuntimeError
        If the compiler fails (its message is quoted), e.g. on a system without POSIX sockets.
    """
    return _build(FORWARD_SOURCE, (FORWARD_SOURCE, SOURCE), _FORWARD_NAME, cache, compiler)


def _build(source: Path, digested: tuple, name: str, cache, compiler) -> Path:
    """``source`` compiled into the cache, keyed by the digest of the ``digested`` sources and the flags."""
    cc = compiler or os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    path = shutil.which(cc) if cc else None
    if path is None:
        raise CompilerNotFoundError(
            f"no C compiler{' ' + repr(cc) if cc else ''} found to build the exported controller: install one "
            "(Debian/Ubuntu: apt-get install gcc; conda: conda install c-compiler) or name it with compiler= or CC")
    # discon.c alone is digested as before this module built two libraries: its cache key is unchanged
    src = b"".join(p.read_bytes() for p in digested)
    digest = hashlib.sha256(src + "\0".join(("cc",) + _FLAGS).encode()).hexdigest()[:16]
    folder = Path(cache) if cache is not None else default_cache()
    lib = folder / digest / (name + _suffix())
    if lib.is_file():
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    # built under a temporary name and renamed: a parallel build or a reader never sees half a file
    fd, tmp = tempfile.mkstemp(suffix=_suffix(), dir=lib.parent)
    os.close(fd)
    try:
        run = subprocess.run([path, *_FLAGS, "-o", tmp, str(source), "-lm"], capture_output=True, text=True, check=False)
        if run.returncode != 0:
            raise RuntimeError(f"{cc} failed to build {source} (exit {run.returncode}): {run.stderr.strip()[-2000:]}")
        os.replace(tmp, lib)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return lib
