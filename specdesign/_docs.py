"""One docstring for a method several classes define alike (documented once, not copied)."""
from __future__ import annotations

import textwrap
from collections.abc import Callable


def docstring_of(source: type, note: str | None = None) -> Callable:
    """Decorator: the method takes the docstring of ``source``'s method of the same name.

    For a method that overrides a base class's (the MPC ``policy``) or mirrors another class's
    interface (``LinearTurbine.check_wind_speed`` and ``TurbineModel.check_wind_speed``): the text
    lives with ``source``, and ``help``, numpydoc and the API pages read the same words.

    Parameters
    ----------
    source : type
        The class whose method documents the decorated one.
    note : str, optional
        What the decorated method does besides (one paragraph): set after the summary line as
        ``source``'s own extended summary would be, the parameters staying ``source``'s.

    Returns
    -------
    callable
        The decorator. It raises AttributeError when ``source`` has no documented method of that
        name (at import, so a renamed method cannot leave a stale reference).
    """
    def decorate(method):
        doc = getattr(getattr(source, method.__name__, None), "__doc__", None)
        if not doc:
            raise AttributeError(f"{source.__name__}.{method.__name__} has no docstring to give "
                                 f"{method.__qualname__}")
        if note:
            summary, _, rest = doc.partition("\n")  # the rest starts with the blank line after the summary
            lines = [line for line in rest.splitlines() if line.strip()]
            indent = min((len(line) - len(line.lstrip(" ")) for line in lines), default=0)
            text = "\n".join(" " * indent + line for line in textwrap.wrap(note, 92))
            doc = f"{summary}\n\n{text}\n{rest}"
        method.__doc__ = doc
        return method

    return decorate
