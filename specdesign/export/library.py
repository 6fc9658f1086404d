"""The compiled Bladed-interface library: :func:`discon_library` builds ``discon.c`` once per source.

The C source ships in the package (``specdesign/export/discon.c``); the system C compiler
builds it (``cc -O2 -shared -fPIC``, the C standard library and libm only: nothing of Python at
run time) into a cache folder keyed by the digest of the source and the compile command, so
one library serves every design and a second call is instant.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["SOURCE", "CompilerNotFoundError", "default_cache", "discon_library"]

#: The C source of the library.
SOURCE = Path(__file__).with_name("discon.c")
_FLAGS = ("-O2", "-shared", "-fPIC", "-std=c99", "-D_DEFAULT_SOURCE")
_NAME = "libspecdesign_discon"


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
    cc = compiler or os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    path = shutil.which(cc) if cc else None
    if path is None:
        raise CompilerNotFoundError(
            f"no C compiler{' ' + repr(cc) if cc else ''} found to build the exported controller: install one "
            "(Debian/Ubuntu: apt-get install gcc; conda: conda install c-compiler) or name it with compiler= or CC")
    src = SOURCE.read_bytes()
    digest = hashlib.sha256(src + "\0".join(("cc",) + _FLAGS).encode()).hexdigest()[:16]
    folder = Path(cache) if cache is not None else default_cache()
    lib = folder / digest / (_NAME + _suffix())
    if lib.is_file():
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    # built under a temporary name and renamed: a parallel build or a reader never sees half a file
    fd, tmp = tempfile.mkstemp(suffix=_suffix(), dir=lib.parent)
    os.close(fd)
    try:
        run = subprocess.run([path, *_FLAGS, "-o", tmp, str(SOURCE), "-lm"], capture_output=True, text=True, check=False)
        if run.returncode != 0:
            raise RuntimeError(f"{cc} failed to build {SOURCE} (exit {run.returncode}): {run.stderr.strip()[-2000:]}")
        os.replace(tmp, lib)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return lib
