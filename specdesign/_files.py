"""File writes a concurrent reader never sees half done (the campaign stores, the exports)."""
from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path


def atomic_write(path: str | os.PathLike, write: Callable[[Path], object]) -> None:
    """Write ``path`` through ``write(tmp)``, then rename ``tmp`` over it.

    The file is there whole or not at all, and a reader that has the old one open or mapped (a
    running OpenFAST with a controller library loaded) keeps the old one whole.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    write : callable
        ``write(tmp)`` writes the content to the path ``tmp``: ``.<name>.<pid>.tmp`` beside
        ``path`` (removed if ``write`` fails).
    """
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
