"""Deprecation helpers of loopshaping (private module: its names are public within it).

:func:`renamed_keywords` lets a function accept the old name of a renamed keyword argument
with a :class:`DeprecationWarning` naming the new one; :func:`renamed_attribute` is the
read-only property that keeps an old attribute name of a class working, with the same
warning. Both warn with ``stacklevel=2``, at the caller.
"""
from __future__ import annotations

import functools
import warnings

__all__ = ["renamed_attribute", "renamed_keywords"]


def renamed_keywords(**old_to_new: str):
    """Decorator: accept the keyword ``old`` for ``new`` with a DeprecationWarning.

    Parameters
    ----------
    **old_to_new : str
        Old keyword name → new keyword name.

    Returns
    -------
    callable
        The decorator. Giving both the old and the new name is a TypeError.
    """

    def decorate(fn):
        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            for old, new in old_to_new.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(f"{fn.__qualname__}() got both {old!r} (deprecated) and {new!r}; give {new!r}")
                    warnings.warn(f"{fn.__qualname__}(): the keyword {old!r} is deprecated, use {new!r}",
                                  DeprecationWarning, stacklevel=2)
                    kwargs[new] = kwargs.pop(old)
            return fn(*args, **kwargs)

        return wrapper

    return decorate


def renamed_attribute(old: str, new: str) -> property:
    """A read-only property ``old`` returning attribute ``new`` with a DeprecationWarning.

    Parameters
    ----------
    old : str
        The deprecated attribute name.
    new : str
        The attribute it is an alias of.

    Returns
    -------
    property
        To assign in a class body: ``omegas = renamed_attribute("omegas", "omega")``.
    """

    def getter(self):
        warnings.warn(f"{type(self).__name__}.{old} is deprecated, use {type(self).__name__}.{new}",
                      DeprecationWarning, stacklevel=2)
        return getattr(self, new)

    return property(getter, doc=f"Deprecated alias of ``{new}``.")
