"""BLAS threading for the design loop's many small linear-algebra calls.

The design steps (the Youla certificate and its plant-case checks, the element fit, the
multi-model H∞ step) make thousands of BLAS calls on matrices of a few dozen rows. A
multi-threaded OpenBLAS spends more time waking and synchronising its threads than computing
on them, the more so on a shared 2-core machine: one thread measured 10× faster for the element
fit and 1.3× for :func:`specdesign.feasibility.specification_for_target` at load 2. The limit
is process-wide while the context is open (threadpoolctl), so it is used around whole design
steps, never inside a library call a user might run in parallel.
"""
from __future__ import annotations

import functools
from contextlib import AbstractContextManager

from threadpoolctl import ThreadpoolController

__all__ = ["on_one_blas_thread", "one_blas_thread"]


@functools.lru_cache(maxsize=1)
def _controller():
    """threadpoolctl's controller, built once: it scans the loaded libraries (milliseconds)."""
    return ThreadpoolController()


def one_blas_thread() -> AbstractContextManager:
    """A context in which BLAS runs on one thread (threadpoolctl).

    Returns
    -------
    contextlib.AbstractContextManager
        threadpoolctl's limit of BLAS to one thread; results are the same as with more
        threads up to the round-off of BLAS's own summation order.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign._blas import one_blas_thread
    >>> with one_blas_thread():
    ...     x = np.linalg.solve(np.eye(3), np.ones(3))
    >>> x.tolist()
    [1.0, 1.0, 1.0]
    """
    return _controller().limit(limits=1, user_api="blas")


def on_one_blas_thread(fn):
    """Decorate ``fn`` to run inside :func:`one_blas_thread`.

    Parameters
    ----------
    fn : callable
        A whole design step.

    Returns
    -------
    callable
        ``fn`` with the same signature and docstring.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign._blas import on_one_blas_thread
    >>> det = on_one_blas_thread(np.linalg.det)
    >>> float(det(np.eye(2)))
    1.0
    """
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with one_blas_thread():
            return fn(*args, **kwargs)

    return wrapper
