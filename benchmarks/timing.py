"""The best-of-n wall-clock timing every bench_*.py script uses (imported as a neighbour:
the scripts run from this folder, ``python benchmarks/bench_x.py`` or ``benchmarks/run.py``)."""
from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any


def timed(fn: Callable[[], Any], n: int = 3) -> tuple[float, Any]:
    """The shortest of ``n`` wall-clock times of ``fn()`` (s) and its last result.

    The shortest, not the mean: it is the least disturbed by the other processes of the machine.
    """
    times, out = [], None
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def best_of(fn: Callable[[], Any], n: int = 3) -> float:
    """The shortest of ``n`` wall-clock times of ``fn()``, s (:func:`timed` without the result)."""
    return timed(fn, n)[0]
