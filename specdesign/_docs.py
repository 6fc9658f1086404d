"""One docstring for a method several classes define alike (documented once, not copied)."""
from __future__ import annotations

from collections.abc import Callable


def docstring_of(source: type) -> Callable:
    """Decorator: the method takes the docstring of ``source``'s method of the same name.

    For a method that overrides a base class's (the MPC ``policy``) or mirrors another class's
    interface (``LinearTurbine.check_wind_speed`` and ``TurbineModel.check_wind_speed``): the text
    lives with ``source``, and ``help``, numpydoc and the API pages read the same words.

    Parameters
    ----------
    source : type
        The class whose method documents the decorated one.

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
        method.__doc__ = doc
        return method

    return decorate
