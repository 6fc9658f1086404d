"""Online (streaming) rainflow counting and Palmgren-Miner damage: the accumulated damage D(k).

:class:`StreamingDamage` consumes a load history in chunks of any size (one sample per control
step, or a block at a time) and keeps the Palmgren-Miner damage of the cycles closed so far.
It runs the same ASTM E1049 three-point counter as :func:`specdesign.fatigue.rainflow`, one
turning point at a time, so after the whole record

    ``StreamingDamage(sn).update(x)`` … ``.total()`` == ``miner_damage(*rainflow(x)[ranges, counts], sn)``

for every chunking of ``x`` (to round-off of the summation order).

Residue convention (stated once, used everywhere here):

- :attr:`StreamingDamage.damage` is D(k), the damage of the cycles **closed** by the samples
  seen so far: the full cycles (count 1) and the half cycles that ASTM E1049's start-point
  rule closes on the fly (the cycle that contains the record's first turning point, count
  0.5, as :func:`specdesign.fatigue.rainflow` with ``residue="half"``). It never decreases. The
  last sample is not yet a turning point: whether it is one depends on the next sample.
- :meth:`StreamingDamage.total` is the damage if the record ended at the last sample: D(k)
  plus the residue (the turning points still on the stack and the last sample) counted as half
  cycles (count 0.5), exactly ``residue="half"`` of :func:`specdesign.fatigue.rainflow`. It
  does not change the counter's state. The residue of a stationary signal holds a few tens of
  turning points, so ``total() − damage`` stays bounded while D(k) grows with time.

S-N curves are range-based, N(S) = (S_ref/S)^m with S the cycle **range**
(:class:`specdesign.fatigue.SNCurve`, bilinear curves included).
"""
from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from ._checks import as_signal
from .fatigue import SNCurve

__all__ = ["StreamingDamage", "accumulated_damage"]

# integer state: [start, top, samples seen]; float state: [last distinct sample, last slope, damage]
_START, _TOP, _SEEN = 0, 1, 2
_XC, _DLAST, _DAMAGE = 0, 1, 2


@njit(cache=True)
def _cycle_damage(rng, count, m, s_ref, knee_range, knee_cycles, m2):
    """count / N(rng) on the range-based curve (bilinear below ``knee_range`` when it is > 0)."""
    if knee_range > 0.0 and rng < knee_range:
        return count / knee_cycles * (rng / knee_range) ** m2
    return count * (rng / s_ref) ** m


@njit(cache=True)
def _push(c, stack, ist, fst, sn):
    """Count the turning point ``c`` on the stack (ASTM E1049 three-point rule, start-point
    half cycles) and add the closed cycles' damage."""
    m, s_ref, knee_range, knee_cycles, m2 = sn[0], sn[1], sn[2], sn[3], sn[4]
    start, top = ist[_START], ist[_TOP]
    d = fst[_DAMAGE]
    while top - start >= 2:
        a = stack[top - 2]
        b = stack[top - 1]
        if abs(c - b) < abs(b - a):
            break
        if top - start == 2:  # the cycle holds the first turning point: half, and it leaves
            d += _cycle_damage(abs(a - b), 0.5, m, s_ref, knee_range, knee_cycles, m2)
            start += 1
        else:
            d += _cycle_damage(abs(a - b), 1.0, m, s_ref, knee_range, knee_cycles, m2)
            top -= 2
    stack[top] = c
    ist[_START], ist[_TOP] = start, top + 1
    fst[_DAMAGE] = d


@njit(cache=True)
def _feed(x, stack, ist, fst, sn, trace):
    """Consume the samples ``x``; ``trace[i]`` gets D after sample i (closed cycles only)."""
    for i in range(x.size):
        xn = x[i]
        seen = ist[_SEEN]
        ist[_SEEN] = seen + 1
        if seen == 0:  # the first sample is always a turning point
            _push(xn, stack, ist, fst, sn)
            fst[_XC] = xn
        elif seen == 1:
            fst[_DLAST] = xn - fst[_XC]
            fst[_XC] = xn
        elif xn != fst[_XC]:  # plateaus collapse to one point
            d_next = xn - fst[_XC]
            if fst[_DLAST] * d_next < 0:  # the previous distinct sample was a reversal
                _push(fst[_XC], stack, ist, fst, sn)
            fst[_XC] = xn
            fst[_DLAST] = d_next
        trace[i] = fst[_DAMAGE]


@njit(cache=True)
def _residue_total(stack, ist, fst, sn):
    """D plus the residue as half cycles, the last sample closing the record (state untouched)."""
    if ist[_SEEN] < 3:  # at most one reversal: no cycle (as the batch counter)
        return fst[_DAMAGE]
    st = stack.copy()
    ist2 = ist.copy()
    fst2 = fst.copy()
    _push(fst[_XC], st, ist2, fst2, sn)
    d = fst2[_DAMAGE]
    for j in range(ist2[_START], ist2[_TOP] - 1):
        d += _cycle_damage(abs(st[j] - st[j + 1]), 0.5, sn[0], sn[1], sn[2], sn[3], sn[4])
    return d


def _sn_vector(sn: SNCurve) -> np.ndarray:
    if not isinstance(sn, SNCurve):
        raise TypeError(f"sn must be a specdesign.fatigue.SNCurve, got {type(sn).__name__}")
    if sn.knee_cycles is None:
        return np.array([sn.m, sn.s_ref, 0.0, 1.0, 1.0])
    return np.array([sn.m, sn.s_ref, sn.knee_range, sn.knee_cycles, sn.m2])


class StreamingDamage:
    """Online rainflow + Palmgren-Miner damage of one load history, fed in chunks.

    See the module docstring for the residue convention: :attr:`damage` counts the closed
    cycles, :meth:`total` adds the residue as half cycles (the batch result of
    :func:`specdesign.fatigue.rainflow` + :func:`specdesign.fatigue.miner_damage`).

    Parameters
    ----------
    sn : specdesign.fatigue.SNCurve
        Range-based S-N curve N(S) = (S_ref/S)^m (S the cycle range), in the load's units.

    Raises
    ------
    TypeError
        If ``sn`` is not an :class:`~specdesign.fatigue.SNCurve`.

    Examples
    --------
    >>> from specdesign.fatigue import SNCurve, miner_damage, rainflow
    >>> x = [0.0, 3.0, 1.0, 4.0, 0.0, 2.0, 1.0]
    >>> sd = StreamingDamage(SNCurve(m=3, s_ref=10.0))
    >>> d = sd.update(x[:3]); d = sd.update(x[3:])
    >>> print(f"{sd.damage:.6f} {sd.total():.6f}")
    0.040000 0.076500
    >>> c = rainflow(x)
    >>> print(f"{miner_damage(c.ranges, c.counts, SNCurve(m=3, s_ref=10.0)):.6f}")
    0.076500
    """

    def __init__(self, sn: SNCurve):
        self.sn = sn
        self._sn = _sn_vector(sn)
        self._stack = np.empty(64)
        self._ist = np.zeros(3, dtype=np.int64)
        self._fst = np.zeros(3)

    def update(self, samples: ArrayLike) -> np.ndarray:
        """Consume the next samples of the load history.

        Parameters
        ----------
        samples : array_like
            The next samples (load units), a scalar or a 1-D array (may be empty); finite.

        Returns
        -------
        numpy.ndarray
            D(k) after each of the samples (dimensionless damage of the closed cycles), shape
            (len(samples),).

        Raises
        ------
        ValueError
            If ``samples`` is not 1-D or has NaN or inf.
        TypeError
            If ``samples`` is complex or not numeric.
        """
        x = np.atleast_1d(np.asarray(samples))
        if x.size == 0:
            return np.empty(0)
        x = as_signal(x, "samples", min_samples=1)
        start, top = int(self._ist[_START]), int(self._ist[_TOP])
        if start > self._stack.size // 2:  # drop the entries that left the stack's bottom
            self._stack[: top - start] = self._stack[start:top]
            self._ist[_START], self._ist[_TOP] = 0, top - start
            top -= start
        need = top + x.size + 2
        if need > self._stack.size:
            grown = np.empty(max(need, 2 * self._stack.size))
            grown[:top] = self._stack[:top]
            self._stack = grown
        trace = np.empty(x.size)
        _feed(x, self._stack, self._ist, self._fst, self._sn, trace)
        return trace

    @property
    def damage(self) -> float:
        """D(k): Palmgren-Miner damage of the cycles closed so far (dimensionless)."""
        return float(self._fst[_DAMAGE])

    @property
    def samples_seen(self) -> int:
        """Number of samples consumed."""
        return int(self._ist[_SEEN])

    def total(self) -> float:
        """Damage if the record ended now: :attr:`damage` plus the residue as half cycles.

        Returns
        -------
        float
            Dimensionless damage, equal to the batch rainflow (``residue="half"``) + Miner
            damage of everything consumed so far.
        """
        return float(_residue_total(self._stack, self._ist, self._fst, self._sn))

    @property
    def residue(self) -> np.ndarray:
        """Turning points still open (load units), oldest first, followed by the last sample."""
        start, top = int(self._ist[_START]), int(self._ist[_TOP])
        tail = [self._fst[_XC]] if self._ist[_SEEN] >= 2 else []
        return np.concatenate([self._stack[start:top], tail])


def accumulated_damage(x: ArrayLike, sn: SNCurve) -> np.ndarray:
    """D(k) of a whole record: the damage of the cycles closed by each sample (online counting).

    Parameters
    ----------
    x : array_like, shape (n,)
        Load history (load units), finite.
    sn : specdesign.fatigue.SNCurve
        Range-based S-N curve (S the cycle range).

    Returns
    -------
    numpy.ndarray
        (n,) nondecreasing damage (dimensionless); its last value plus the residue's half
        cycles is the batch rainflow + Miner damage (see :class:`StreamingDamage`).

    Raises
    ------
    ValueError
        If ``x`` is not 1-D or has NaN or inf.
    TypeError
        If ``sn`` is not an SNCurve, or ``x`` is complex or not numeric.

    Examples
    --------
    >>> from specdesign.fatigue import SNCurve
    >>> accumulated_damage([0.0, 3.0, 1.0, 4.0, 0.0], SNCurve(m=3, s_ref=10.0))
    array([0.   , 0.   , 0.   , 0.   , 0.008])
    """
    return StreamingDamage(sn).update(x)
