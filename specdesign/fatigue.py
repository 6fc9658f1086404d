"""Time-domain fatigue: ASTM E1049 rainflow counting, S-N curves, Palmgren-Miner, DEL.

Conventions (the documentation's method page): S-N curves are range-based, N(S) = (S_ref/S)^m with S the
cycle **range** (peak to valley, not the amplitude); half cycles count 0.5; the damage
equivalent load uses the 1 Hz convention, DEL = (Σ n_i S_i^m / N_eq)^(1/m) with
N_eq = duration · n_eq_rate (n_eq_rate = 1 Hz by default). Loads keep the units of the
signal (N·m in, N·m out).

The rainflow counter is a compiled (numba) three-point ASTM E1049 counter on the turning
points. It reproduces, cycle for cycle and in the same order, the cycles of
``rainflow.extract_cycles`` (the reference pure-Python implementation), with one deliberate
exception: a constant signal gives no cycles here, whereas ``rainflow`` emits one zero-range
half cycle (which carries no damage anyway).
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from ._checks import as_real, as_signal, positive_scalar, representable

__all__ = [
    "TOWER_M",
    "BLADE_M",
    "Cycles",
    "rainflow",
    "SNCurve",
    "miner_damage",
    "goodman_ranges",
    "del_rainflow",
    "VarianceDamageFit",
    "fit_variance_damage",
    "economic_cost",
]

#: Wöhler (S-N) exponent of the welded-steel tower, N = (S_ref/S)^m with S the cycle range: the
#: seed paper's m = 4, the default of every tower-load DEL and damage in the workbench.
TOWER_M = 4.0
#: Wöhler exponent of the glass-fibre composite blade root: the usual m = 10.
BLADE_M = 10.0


@dataclass(frozen=True)
class Cycles:
    """Rainflow cycles of one signal, as returned by :func:`rainflow`.

    ``len(cycles)`` is the number of entries (full and half cycles alike); :attr:`total`
    counts half cycles 0.5.

    Parameters
    ----------
    ranges : ndarray, shape (k,)
        Cycle ranges (peak-to-valley, not amplitudes), in the units of the signal.
    means : ndarray, shape (k,)
        Cycle means, in the units of the signal.
    counts : ndarray, shape (k,)
        1.0 for full cycles, 0.5 for half cycles of the residue.

    See Also
    --------
    rainflow : Counts them.
    miner_damage : Their damage on an S-N curve.
    """

    ranges: np.ndarray
    means: np.ndarray
    counts: np.ndarray

    def __len__(self) -> int:
        return int(self.ranges.size)

    @property
    def total(self) -> float:
        """Number of cycles, half cycles counted 0.5."""
        return float(self.counts.sum())


@njit(cache=True)
def _reversals(x, out):
    """Turning points of x into out; returns how many.

    Mirrors ``rainflow.reversals``: the first and last samples are always kept, plateaus
    collapse to one point, and a point is a reversal when the sign of the slope changes.
    """
    n = x.size
    if n == 0:
        return 0
    out[0] = x[0]
    if n == 1:
        return 1
    k = 1
    xc = x[1]
    d_last = xc - x[0]
    for i in range(2, n):
        xn = x[i]
        if xn == xc:
            continue
        d_next = xn - xc
        # Branch-free write: the slope sign of noisy signals is unpredictable, so always
        # store and advance only on a reversal.
        out[k] = xc
        k += d_last * d_next < 0
        xc = xn
        d_last = d_next
    if n > 2:
        out[k] = x[n - 1]
        k += 1
    return k


#: turning points found per block before they are counted (fits in L1 with the samples)
_BLOCK = 4096


@njit(cache=True)
def _count_signal(x, half_rule, ranges, means, counts):
    """ASTM E1049 three-point counting of the turning points of x; returns the number of cycles.

    One pass: a block of turning points is extracted branch-free (as :func:`_reversals`) into
    a small buffer that stays in cache, then counted on a stack whose two top values are kept
    in registers (``a``, ``b``), so a candidate point costs one comparison when it closes no
    cycle (about two thirds of the points of noise). The stack starts at index 2 so that
    reading the two entries under a popped pair never leaves the buffer; entries below
    ``start`` are never used. With ``half_rule`` False (periodic records rotated to start at
    their maximum) a range that contains the start point is counted as a full cycle, which
    closes the residue. Cycles are written to ``ranges``, ``means``, ``counts`` (length ≥ the
    number of turning points) in counting order.
    """
    n = x.size
    if n < 3:  # at most one turning point (ASTM, and rainflow.reversals): no cycle
        return 0
    stack = np.empty(n + 3)
    buf = np.empty(_BLOCK + 1)
    start = 2
    top = 2
    nc = 0
    a = 0.0
    b = 0.0
    xc = x[1]
    d_last = xc - x[0]
    i = 2
    buf[0] = x[0]
    k = 1
    while True:
        while i < n and k < _BLOCK:
            xn = x[i]
            i += 1
            if xn == xc:  # plateaus collapse to one point
                continue
            d_next = xn - xc
            # branch-free: the slope sign of noise is unpredictable, so always store and
            # advance only on a reversal
            buf[k] = xc
            k += d_last * d_next < 0
            xc = xn
            d_last = d_next
        last = i >= n
        if last:  # the last sample is always a turning point
            buf[k] = x[n - 1]
            k += 1
        for j in range(k):
            c = buf[j]
            # the stack [..., a, b] plus the candidate c: |c - b| >= |b - a| closes (a, b)
            while top - start >= 2 and abs(c - b) >= abs(b - a):
                ranges[nc] = abs(a - b)
                means[nc] = 0.5 * (a + b)
                if top - start == 2 and half_rule:
                    counts[nc] = 0.5
                    start += 1
                else:
                    counts[nc] = 1.0
                    top -= 2
                    a = stack[top - 2]
                    b = stack[top - 1]
                nc += 1
            stack[top] = c
            top += 1
            a = b
            b = c
        k = 0
        if last:
            break
    while top - start > 1:
        x1 = stack[start]
        x2 = stack[start + 1]
        ranges[nc] = abs(x1 - x2)
        means[nc] = 0.5 * (x1 + x2)
        counts[nc] = 0.5
        nc += 1
        start += 1
    return nc


@njit(cache=True)
def _rotate_periodic(x):
    """Turning points of x rotated to start at the (first) maximum and closed on it."""
    tp = np.empty(x.size + 1)
    n_tp = _reversals(x, tp)
    k = 0
    for i in range(1, n_tp):
        if tp[i] > tp[k]:
            k = i
    rot = np.empty(n_tp + 1)
    j = 0
    for i in range(k, n_tp):
        rot[j] = tp[i]
        j += 1
    for i in range(0, k + 1):
        rot[j] = tp[i]
        j += 1
    return rot[:j]


def _cycles(x, half_rule):
    """Count x (a checked, contiguous float64 signal) into three arrays.

    The output buffer is allocated by numpy (which asks the kernel for huge pages on large
    arrays), in one block: the page faults of three separate arrays from numba's allocator
    cost up to a third of the counting. Each output row stays contiguous. Cycles of a
    signal with few of them are copied out of the n-long buffer so it is not kept alive.
    """
    n = x.size
    buf = np.empty((3, n))  # one block: fewer, larger pages to fault in than three arrays
    nc = _count_signal(x, half_rule, buf[0], buf[1], buf[2])
    out = buf[0, :nc], buf[1, :nc], buf[2, :nc]
    return tuple(o.copy() for o in out) if 4 * nc < n else out


def rainflow(x: ArrayLike, residue: str = "half") -> Cycles:
    """Rainflow-count a time series (ASTM E1049 three-point method, exact, no binning).

    Parameters
    ----------
    x : array_like, shape (n,)
        The load or stress history (any unit; ranges and means come out in the same unit).
    residue : {"half", "periodic"}
        "half" (default): the residue left after counting is counted as half cycles (0.5),
        exactly as ``rainflow.extract_cycles``. "periodic": the record is treated as one
        period of a periodic signal: it is rotated to start (and end) at its maximum, which
        closes the residue into full cycles (the unbiased choice for periodic records).

    Returns
    -------
    Cycles
        ``ranges`` (peak to valley), ``means`` and ``counts`` (1.0 or 0.5), in counting order.
        A constant signal gives no cycles.

    Raises
    ------
    ValueError
        If ``residue`` is not "half" or "periodic", or ``x`` is not 1-D, has fewer than 2
        samples or contains NaN or inf.
    TypeError
        If ``x`` is complex or not numeric.

    See Also
    --------
    del_rainflow : The damage equivalent load of the counted cycles.

    Examples
    --------
    >>> from specdesign.fatigue import rainflow
    >>> c = rainflow([0.0, 3.0, 1.0, 4.0, 0.0])
    >>> c.ranges, c.counts
    (array([2., 4., 4.]), array([1. , 0.5, 0.5]))
    >>> c.total
    2.0

    One period of a periodic record: the two half cycles of the residue close into one.

    >>> c = rainflow([0.0, 3.0, 1.0, 4.0, 0.0], residue="periodic")
    >>> c.ranges, c.counts
    (array([2., 4.]), array([1., 1.]))
    """
    if residue not in ("half", "periodic"):
        raise ValueError(f"residue={residue!r} must be 'half' or 'periodic'")
    a = as_signal(x, "x")
    if a.size == 2:
        # rainflow.extract_cycles finds a single reversal in two samples: no cycle.
        empty = np.empty(0)
        return Cycles(empty, empty.copy(), empty.copy())
    # the junction between the last and first sample of a periodic record may not be a
    # reversal: its rotated turning points are counted again from scratch
    r, mu, c = _cycles(_rotate_periodic(a), False) if residue == "periodic" else _cycles(a, True)
    if r.size == 1 and r[0] == 0.0 and a.max() == a.min():
        # A constant signal: rainflow.extract_cycles reports one zero-range half cycle.
        r, mu, c = r[:0], mu[:0], c[:0]
    return Cycles(r, mu, c)


@dataclass(frozen=True)
class SNCurve:
    """Range-based S-N (Wöhler) curve N(S) = (S_ref/S)^m, optionally bilinear.

    S is the cycle **range**. With ``knee_cycles`` set, the curve continues below the knee
    range S_knee = S_ref · knee_cycles^(-1/m) with slope ``m2``:
    N(S) = knee_cycles · (S_knee/S)^m2 for S < S_knee.

    Parameters
    ----------
    m : float
        Wöhler exponent (> 0), e.g. 4 for steel, 10 for glass fibre.
    s_ref : float
        Range that fails in one cycle (the intercept), in load units. Default 1.
    knee_cycles : float or None
        Cycle count at the knee (e.g. 1e7), None for a single slope.
    m2 : float or None
        Exponent below the knee (> 0, required with ``knee_cycles``); use a large value for an
        endurance limit.

    Raises
    ------
    ValueError
        If ``m``, ``s_ref``, ``knee_cycles`` or ``m2`` is not finite and > 0, or only one of
        ``knee_cycles`` and ``m2`` is given.
    TypeError
        If one of them is complex or not a number.

    See Also
    --------
    miner_damage : Palmgren-Miner damage of cycles on this curve.

    Examples
    --------
    >>> from specdesign.fatigue import SNCurve
    >>> sn = SNCurve(m=4, s_ref=100.0)               # fails in 1 cycle at a range of 100
    >>> sn.cycles_to_failure([10.0, 50.0, 0.0])
    array([10000.,    16.,    inf])

    Bilinear, with slope 5 below the knee at 1e6 cycles:

    >>> sn = SNCurve(m=3, s_ref=1000.0, knee_cycles=1e6, m2=5.0)
    >>> print(f"{sn.knee_range:.6g}")
    10
    >>> print(", ".join(f"{n:.6g}" for n in sn.cycles_to_failure([20.0, 5.0])))
    125000, 3.2e+07
    """

    m: float
    s_ref: float = 1.0
    knee_cycles: float | None = None
    m2: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "m", positive_scalar(self.m, "m"))
        object.__setattr__(self, "s_ref", positive_scalar(self.s_ref, "s_ref"))
        if (self.knee_cycles is None) != (self.m2 is None):
            raise ValueError("knee_cycles and m2 go together: give both for a bilinear curve or neither")
        if self.knee_cycles is not None:
            object.__setattr__(self, "knee_cycles", positive_scalar(self.knee_cycles, "knee_cycles"))
            object.__setattr__(self, "m2", positive_scalar(self.m2, "m2"))

    @property
    def knee_range(self) -> float | None:
        """Range at the knee (load units), or None for a single-slope curve."""
        if self.knee_cycles is None:
            return None
        return self.s_ref * self.knee_cycles ** (-1.0 / self.m)

    def cycles_to_failure(self, ranges: ArrayLike) -> np.ndarray:
        """N(S) for ranges S (load units); a zero range never fails (inf).

        At a large exponent N itself may leave float64's range (inf above ~1.8e308 cycles,
        0 below ~1e-308): :func:`miner_damage` and :func:`del_rainflow` never form it.

        Parameters
        ----------
        ranges : array_like
            Cycle ranges S (peak to valley, load units), >= 0. Not validated beyond being
            real: a negative or NaN range gives a meaningless N.

        Returns
        -------
        ndarray
            Cycles to failure N(S) (dimensionless), same shape as ``ranges``.

        Raises
        ------
        TypeError
            If ``ranges`` is complex or not numeric.
        """
        s = as_real(ranges, "ranges")
        with np.errstate(divide="ignore"):
            n = (self.s_ref / s) ** self.m
            if self.knee_cycles is not None:
                sk = self.knee_range
                n = np.where(s < sk, self.knee_cycles * (sk / s) ** self.m2, n)
        return n


def miner_damage(ranges: ArrayLike, counts: ArrayLike, sn: SNCurve) -> float:
    """Palmgren-Miner damage Σ n_i / N(S_i) (dimensionless) for cycle ranges S_i (load units).

    Computed as Σ n_i (S_i/S_ref)^m (N itself is never formed), piecewise for a bilinear
    curve.

    Parameters
    ----------
    ranges : array_like, shape (k,)
        Cycle ranges S_i (peak to valley, not amplitudes), load units; finite, >= 0.
    counts : array_like, shape (k,)
        Cycle counts n_i (1 for full cycles, 0.5 for half cycles); finite, >= 0.
    sn : SNCurve
        Range-based S-N curve, in the load units of ``ranges``.

    Returns
    -------
    float
        The damage D (dimensionless; failure at D = 1) of the cycles, not a rate: divide by
        the record's duration (s) for a damage per second.

    Raises
    ------
    TypeError
        If ``sn`` is not an :class:`SNCurve`, or ``ranges``/``counts`` are complex or not
        numeric.
    ValueError
        If ``ranges`` and ``counts`` are not 1-D of the same length, or have NaN, inf or
        negative values.
    OverflowError
        If the damage is outside float64's range (above ~1.8e308, or a nonzero damage below
        ~2.2e-308: ranges far from S_ref at a large exponent) instead of returning inf or 0;
        the DEL (:func:`del_rainflow`) is computed scaled and stays finite.

    Examples
    --------
    >>> from specdesign.fatigue import SNCurve, miner_damage, rainflow
    >>> sn = SNCurve(m=3, s_ref=10.0)
    >>> print(f"{miner_damage([2.0, 4.0], [1.0, 0.5], sn):.6f}")   # 0.2³ + 0.5 · 0.4³
    0.040000
    >>> c = rainflow([0.0, 3.0, 1.0, 4.0, 0.0])
    >>> print(f"{miner_damage(c.ranges, c.counts, sn):.6f}")
    0.072000
    """
    if not isinstance(sn, SNCurve):
        raise TypeError(f"sn must be an SNCurve, got {type(sn).__name__}")
    s = as_real(ranges, "ranges")
    n = as_real(counts, "counts")
    if s.shape != n.shape or s.ndim != 1:
        raise ValueError(f"ranges and counts must be 1-D of the same length, got {s.shape} and {n.shape}")
    if not (np.all(np.isfinite(s)) and np.all(s >= 0)):
        raise ValueError("ranges must be finite and >= 0 (cycle ranges, peak to valley)")
    if not (np.all(np.isfinite(n)) and np.all(n >= 0)):
        raise ValueError("counts must be finite and >= 0")
    # n/N written as n (S/S_ref)^m: N itself leaves float64's range first (1/N of a
    # subnormal N is inexact); the sum overflows only if the damage does (every term >= 0)
    with np.errstate(over="ignore", under="ignore"):
        d = n * (s / sn.s_ref) ** sn.m
        if sn.knee_cycles is not None:
            sk = sn.knee_range
            d = np.where(s < sk, n / sn.knee_cycles * (s / sk) ** sn.m2, d)
        d = float(np.sum(d))
    representable(d, bool(np.any((n > 0) & (s > 0))), f"the Miner damage (m={sn.m:g}, s_ref={sn.s_ref:g})",
                  "compute the DEL (del_rainflow) instead, or choose s_ref in the load's range")
    return d


def goodman_ranges(ranges: ArrayLike, means: ArrayLike, ultimate: float) -> np.ndarray:
    """Goodman mean correction: equivalent zero-mean ranges S/(1 - |mean|/ultimate).

    Tensile and compressive means are both treated as harmful (|mean|), the usual
    conservative choice for bending moments.

    Parameters
    ----------
    ranges : array_like
        Cycle ranges S (peak to valley), load units.
    means : array_like
        Cycle means, load units; same shape as ``ranges``.
    ultimate : float
        Ultimate load (> 0) in the units of the signal.

    Returns
    -------
    ndarray
        Equivalent zero-mean ranges, load units, same shape as ``ranges``.

    Raises
    ------
    ValueError
        If ``ranges`` and ``means`` differ in shape, ``ultimate`` is not finite and > 0, or
        a cycle's |mean| reaches the ultimate load (a static failure).
    TypeError
        If an argument is complex or not numeric.

    Examples
    --------
    >>> from specdesign.fatigue import goodman_ranges
    >>> goodman_ranges([10.0, 10.0], [0.0, -50.0], ultimate=100.0)
    array([10., 20.])
    """
    su = positive_scalar(ultimate, "ultimate")
    s = as_real(ranges, "ranges")
    mu = np.abs(as_real(means, "means"))
    if s.shape != mu.shape:
        raise ValueError(f"ranges and means must have the same shape, got {s.shape} and {mu.shape}")
    if np.any(mu >= su):
        raise ValueError(f"ultimate={su!r} must exceed every |cycle mean| (max {mu.max()!r}); a mean at the ultimate load is a static failure")
    return s / (1.0 - mu / su)


def del_rainflow(x: ArrayLike, m: float, duration: float, n_eq_rate: float = 1.0, *, ultimate: float | None = None,
                 residue: str = "half") -> float:
    """Damage equivalent load of a time series, DEL = (Σ n_i S_i^m / N_eq)^(1/m).

    Parameters
    ----------
    x : array_like, shape (n,)
        Load history (e.g. N·m); the DEL is a **range** in the same unit.
    m : float
        Wöhler exponent (> 0).
    duration : float
        Length of the record in seconds.
    n_eq_rate : float
        Equivalent cycle rate in Hz (default 1 Hz): N_eq = duration · n_eq_rate.
    ultimate : float or None
        Ultimate load for the Goodman mean correction (:func:`goodman_ranges`); None: no correction.
    residue : {"half", "periodic"}
        Residue handling of :func:`rainflow`.

    Returns
    -------
    float
        The DEL, a cycle **range** in the unit of ``x``: the constant range that, cycled
        n_eq_rate times a second for ``duration`` seconds, does the damage of the record.
        0.0 for a constant signal. It does not depend on the S-N curve's S_ref.

    Raises
    ------
    ValueError
        If ``m``, ``duration``, ``n_eq_rate`` or ``ultimate`` is not finite and > 0, a
        cycle's |mean| reaches ``ultimate``, ``residue`` is unknown, or ``x`` is not a 1-D
        finite series of at least 2 samples.
    TypeError
        If an argument is complex or not numeric.

    See Also
    --------
    specdesign.spectral.del_spectral : The DEL from a PSD.

    Examples
    --------
    A sine of amplitude 10 and period 10 s over 600 s: 60 cycles of range 20, so
    DEL = 20 · (60/600)^(1/4) at m = 4:

    >>> import numpy as np
    >>> from specdesign.fatigue import del_rainflow
    >>> t = np.arange(0.0, 600.0, 0.05)                          # s
    >>> x = 10.0 * np.sin(2 * np.pi * t / 10.0)                  # e.g. MN·m
    >>> print(f"{del_rainflow(x, m=4, duration=600.0, residue='periodic'):.4f}")
    11.2468
    >>> print(f"{20.0 * 0.1 ** 0.25:.4f}")
    11.2468
    >>> print(f"{del_rainflow(x, m=4, duration=600.0):.4f}")     # residue as half cycles
    11.2261
    >>> print(f"{del_rainflow(x + 50.0, 4, 600.0, ultimate=500.0):.4f}")   # Goodman
    12.4734
    """
    m = positive_scalar(m, "m")
    n_eq = positive_scalar(duration, "duration") * positive_scalar(n_eq_rate, "n_eq_rate")
    c = rainflow(x, residue=residue)
    s = c.ranges if ultimate is None else goodman_ranges(c.ranges, c.means, ultimate)
    top = float(np.max(s)) if s.size else 0.0
    if top == 0.0:
        return 0.0
    # DEL is homogeneous of degree 1 in the load: ranges relative to the largest never overflow
    # (the largest term is 0.5 or 1), and those that underflow carry < 1e-308 of the sum
    with np.errstate(under="ignore"):
        return top * float((np.sum(c.counts * (s / top) ** m) / n_eq) ** (1.0 / m))


def _log_sum_pow(ranges, counts, m) -> float:
    """ln Σ n_i S_i^m (ranges S_i > 0 somewhere), scaled by the largest range so that no S^m is formed."""
    top = float(np.max(ranges))
    with np.errstate(under="ignore"):
        return m * np.log(top) + float(np.log(np.sum(counts * (ranges / top) ** m)))


@dataclass(frozen=True)
class VarianceDamageFit:
    """Power-law surrogate ln(L_ult^m · D) = a · ln(Var) + b (natural logarithms).

    D is the Miner damage of a record for N = (L_ult/S)^m (S the range), Var its variance.
    Built by :func:`fit_variance_damage`.

    Parameters
    ----------
    a : float
        Slope of ln(L_ult^m · D) against ln(Var) (dimensionless; m/2 for Gaussian records of
        one spectral shape).
    b : float
        Intercept: ln(L_ult^m · D) = ln Σ n_i S_i^m (S in load units) at Var = 1 load unit²,
        for records of the fitted duration.
    m : float
        Wöhler exponent of the fit.
    ultimate : float
        L_ult, the S_ref of the range-based S-N curve, load units.
    residual_std : float
        Standard deviation of the residuals of the log fit (dimensionless).

    See Also
    --------
    fit_variance_damage : Fits it.
    """

    a: float
    b: float
    m: float
    ultimate: float
    residual_std: float

    def predict(self, variance: ArrayLike) -> np.ndarray:
        """Damage D predicted for variance(s) in load units squared: e^b Var^a / L_ult^m.

        Evaluated in logarithms (L_ult^m alone overflows for L_ult = 1e8 N·m at m = 40).

        Parameters
        ----------
        variance : array_like
            Variance(s) of the load, load units², finite and > 0.

        Returns
        -------
        ndarray
            Miner damage D (dimensionless) of a record of the fitted duration, same shape as
            ``variance``.

        Raises
        ------
        ValueError
            If a variance is not finite and > 0.
        TypeError
            If ``variance`` is complex or not numeric.
        OverflowError
            If D itself is outside float64's range.
        """
        v = as_real(variance, "variance")
        if np.any(~np.isfinite(v)) or np.any(v <= 0):
            raise ValueError("variance must be finite and > 0 (load units squared)")
        with np.errstate(over="ignore", under="ignore"):
            d = np.exp(self.b + self.a * np.log(v) - self.m * np.log(self.ultimate))
        return representable(d, True, f"the predicted damage (m={self.m:g})",
                             "predict at a variance nearer the fitted ones, or choose ultimate in the load's range")


def fit_variance_damage(records: Iterable[ArrayLike], m: float, *, ultimate: float = 1.0) -> VarianceDamageFit:
    """Fit ln(L_ult^m · D) = a ln(Var) + b over a set of load histories (least squares).

    D is the Miner damage of each whole record (rainflow, half cycles 0.5) for the range-based
    curve N = (L_ult/S)^m; the fit is done in logarithms, so it holds at any load scale.

    Parameters
    ----------
    records : iterable of array_like
        Load histories (load units), 1-D, at least 3 samples each (or a 2-D array, one
        record per row); at least two with different variances, none constant. Use records
        of equal duration: D is a damage per record, not per second.
    m : float
        Wöhler exponent (> 0); fit one surrogate per exponent.
    ultimate : float
        Ultimate load L_ult (load units), the S_ref of the range-based S-N curve; default 1.

    Returns
    -------
    VarianceDamageFit
        With ``a``, ``b``, the residual standard deviation of the log fit and ``predict``.

    Raises
    ------
    ValueError
        If ``m`` or ``ultimate`` is not finite and > 0, fewer than two records are given, a
        record is not 1-D and finite with at least 3 samples, a record is constant, or all
        records have the same variance.
    TypeError
        If an argument is complex or not numeric.

    Examples
    --------
    Gaussian white noise at three levels: D ∝ Var^(m/2), so a ≈ 2 at m = 4.

    >>> import numpy as np
    >>> from specdesign.fatigue import fit_variance_damage
    >>> rng = np.random.default_rng(0)
    >>> records = [s * rng.standard_normal(2000) for s in (1.0, 2.0, 4.0)]
    >>> fit = fit_variance_damage(records, m=4)
    >>> print(f"a = {fit.a:.2f}")
    a = 2.00
    """
    m = positive_scalar(m, "m")
    su = positive_scalar(ultimate, "ultimate")
    recs = [as_signal(r, f"records[{i}]", min_samples=3) for i, r in enumerate(records)]
    if len(recs) < 2:
        raise ValueError(f"records needs at least 2 load histories to fit a and b, got {len(recs)}")
    var = np.array([np.var(r) for r in recs])
    cycles = [rainflow(r) for r in recs]
    if np.any(var <= 0) or any(c.ranges.size == 0 or np.max(c.ranges) == 0 for c in cycles):
        raise ValueError("records must not contain constant signals (zero variance, zero damage)")
    lx = np.log(var)
    if np.ptp(lx) == 0:
        raise ValueError("records all have the same variance; a and b are not identifiable")
    # ln(L_ult^m D) = ln Σ n S^m (the damage at S_ref = 1), in logarithms: neither L_ult^m nor
    # S^m is formed, so the fit holds for any load scale and m <= 100
    ly = np.array([_log_sum_pow(c.ranges, c.counts, m) for c in cycles])
    a, b = np.polyfit(lx, ly, 1)
    res = ly - (a * lx + b)
    dof = max(len(recs) - 2, 1)
    return VarianceDamageFit(float(a), float(b), m, su, float(np.sqrt(np.sum(res**2) / dof)))


def economic_cost(damages: ArrayLike, weights: ArrayLike) -> np.ndarray:
    """Economic fatigue cost J = Σ_i π_i D_i over the last axis.

    Parameters
    ----------
    damages : array_like, shape (..., n_components)
        Dimensionless Miner damages D_i (or damage rates, per second), finite and >= 0.
    weights : array_like, shape (n_components,)
        Costs π_i, currency per unit damage, finite and >= 0.

    Returns
    -------
    ndarray, shape (...)
        J in currency (or currency per second for damage rates).

    Raises
    ------
    ValueError
        If ``weights`` is not 1-D, ``damages`` does not end in n_components, or either has
        NaN, inf or negative values.
    TypeError
        If an argument is complex or not numeric.

    Examples
    --------
    >>> from specdesign.fatigue import economic_cost
    >>> economic_cost([[0.1, 0.2], [0.3, 0.0]], weights=[2.0, 1.0])
    array([0.4, 0.6])
    """
    d = as_real(damages, "damages")
    w = as_real(weights, "weights")
    if w.ndim != 1:
        raise ValueError(f"weights must be 1-D (one cost per component), got shape {w.shape}")
    if d.ndim == 0 or d.shape[-1] != w.size:
        raise ValueError(f"damages must have shape (..., {w.size}) to match weights, got {d.shape}")
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError("weights must be finite and >= 0 (economic cost per unit damage)")
    if not np.all(np.isfinite(d)) or np.any(d < 0):
        raise ValueError("damages must be finite and >= 0")
    return d @ w
