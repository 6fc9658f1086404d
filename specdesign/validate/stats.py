"""Statistics of a validation: Weibull weights of the operating points, Welch spectra per
rad/s, pooling over seeds and paired-seed relative changes with jackknife or bootstrap
standard errors.

Per wind speed, seeds are pooled the way fatigue adds up: DEL over S seeds of equal length
is (mean_s DEL_s^m)^{1/m} (the DEL of the concatenated damage), SDs are pooled as
√(mean_s var_s), the power is the plain mean. A *relative change* designed vs baseline is
100·(X_designed/X_baseline − 1) %; a *reduction* is minus that. Both controllers see the same
seeds (paired), and standard errors come from the jackknife over paired seeds (delete one
seed from both controllers), or a seeded paired bootstrap.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .._checks import positive_scalar
from ..fatigue import BLADE_M, TOWER_M
from .metrics import INDICATORS

__all__ = ["WEIBULL_K", "WEIBULL_A", "weibull_weights", "welch_psd", "pool", "resampled_se", "PairedChange",
           "paired_change", "seeds_from"]

#: Weibull shape of the paper's wind climate (Table 2's mean).
WEIBULL_K = 2.2
#: Weibull scale of the paper's wind climate (m/s).
WEIBULL_A = 11.29


def weibull_weights(wind_speeds, k: float = WEIBULL_K, scale: float = WEIBULL_A) -> np.ndarray:
    """Compute the weights of the operating points: Weibull pdf at each wind speed, normalised to sum 1.

    f(v) = (k/A)(v/A)^{k−1} exp(−(v/A)^k), w_i = f(v_i)/Σ f(v_j). With the defaults this
    reproduces the means printed in the paper's Table 2 from its per-speed values.

    Parameters
    ----------
    wind_speeds : array_like
        Mean wind speeds of the operating points (m/s), positive, one-dimensional.
    k : float, default WEIBULL_K
        Weibull shape (dimensionless).
    scale : float, default WEIBULL_A
        Weibull scale A (m/s).

    Returns
    -------
    numpy.ndarray
        (W,) weights summing to 1.

    Raises
    ------
    ValueError
        A wind speed that is not positive and finite, or a non-positive ``k`` or ``scale``.

    Examples
    --------
    >>> float(weibull_weights([15.0, 19.0, 25.0]).sum())
    1.0
    """
    v = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    if v.ndim != 1 or v.size == 0 or np.any(~np.isfinite(v)) or np.any(v <= 0):
        raise ValueError(f"wind_speeds must be positive mean wind speeds in m/s, got {wind_speeds!r}")
    k = positive_scalar(k, "k")
    a = positive_scalar(scale, "scale")
    f = (k / a) * (v / a) ** (k - 1) * np.exp(-((v / a) ** k))
    return f / f.sum()


def welch_psd(x, dt: float, nperseg: int | None = None, axis: int = -1) -> tuple[np.ndarray, np.ndarray]:
    """One-sided Welch PSD per rad/s of ``x`` sampled every ``dt`` s.

    scipy's ``welch`` with ``fs = 1/dt`` returns f (Hz) and P(f) per Hz, one-sided. With
    ω = 2πf the density per rad/s is S(ω) = P(f)/(2π), so that ∫ S dω = ∫ P df = variance.

    Parameters
    ----------
    x : array_like
        Signal(s), time along ``axis`` (SI unit of the signal).
    dt : float
        Sample spacing (s).
    nperseg : int, optional
        Samples per segment. Default: the power of 2 closest to 1/6 of the record (≈ 100 s
        for 600 s), at least 16; Hann window, 50 % overlap, mean removed per segment.
    axis : int, default -1
        Time axis of ``x``.

    Returns
    -------
    omega : numpy.ndarray
        Frequencies (rad/s), from 0.
    psd : numpy.ndarray
        PSD (signal unit² per rad/s), shaped like ``x`` with ``axis`` replaced by frequency.

    Raises
    ------
    ValueError
        ``dt`` is not a positive number, ``nperseg`` not a positive integer, or ``x`` empty.

    Notes
    -----
    Equal to ``scipy.signal.welch`` with its defaults (to round-off), computed for all segments
    of all signals at once.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.random.default_rng(0).standard_normal(6000)
    >>> w, p = welch_psd(x, 0.1)
    >>> bool(abs(np.trapezoid(p, w) - x.var()) < 0.05)
    True
    """
    from scipy.signal import get_window

    x = np.moveaxis(np.asarray(x, dtype=float), axis, -1)
    dt = positive_scalar(dt, "dt")
    n = x.shape[-1]
    if nperseg is None:
        nperseg = int(2 ** max(4, round(math.log2(max(n / 6, 16)))))
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or nperseg < 1:
        raise ValueError(f"nperseg must be a positive whole number of samples (or None), got {nperseg!r}")
    if n < 1:
        raise ValueError(f"x must have at least one sample along axis={axis}, got shape {x.shape}")
    nperseg = min(int(nperseg), n)
    # scipy.signal.welch's defaults (periodic Hann, hop nperseg - nperseg // 2, segment mean
    # removed, density scaling, interior bins doubled), but every segment of every signal in one
    # rfft: scipy's ShortTimeFFT detrends and transforms them one slice at a time in Python
    hop = nperseg - nperseg // 2
    win = get_window("hann", nperseg)
    seg = sliding_window_view(x, nperseg, axis=-1)[..., : (n - nperseg // 2) // hop * hop : hop, :]
    spec = np.fft.rfft((seg - seg.mean(axis=-1, keepdims=True)) * win, axis=-1)
    p = (spec.real ** 2 + spec.imag ** 2).mean(axis=-2) * (dt / (win * win).sum())
    p[..., 1:-1 if nperseg % 2 == 0 else None] *= 2.0
    f = np.fft.rfftfreq(nperseg, dt)
    return 2.0 * np.pi * f, np.moveaxis(p, -1, axis) / (2.0 * np.pi)


def pool(indicator: str, x: np.ndarray, m: float, axis: int = -1) -> np.ndarray:
    """Pool an indicator over seeds the way it adds up.

    Parameters
    ----------
    indicator : str
        One of :data:`~specdesign.validate.metrics.INDICATORS`.
    x : numpy.ndarray
        Per-seed values (the indicator's unit), seeds along ``axis``.
    m : float
        Wöhler exponent (used for ``tower_del``).
    axis : int, default -1
        Seed axis.

    Returns
    -------
    numpy.ndarray
        ``tower_del``: (mean DEL^m)^{1/m} (the DEL of the summed damage), ``blade_del``
        the same with m = :data:`~specdesign.fatigue.BLADE_M`; ``mean_power``, ``pitch_travel``
        (per hour) and ``rate_limit_time`` (a fraction): the mean; a standard deviation: √(mean
        of the variances).

    Examples
    --------
    >>> import numpy as np
    >>> round(float(pool("pitch_sd", np.array([3.0, 4.0]), 4.0) ** 2), 9)  # mean of the variances
    12.5
    """
    if indicator == "tower_del":
        return np.mean(x**m, axis=axis) ** (1.0 / m)
    if indicator == "blade_del":  # its own S-N slope, whatever the campaign's tower m
        return np.mean(x**BLADE_M, axis=axis) ** (1.0 / BLADE_M)
    if indicator in ("mean_power", "pitch_travel", "rate_limit_time"):  # rates and fractions: the mean
        return np.mean(x, axis=axis)
    return np.sqrt(np.mean(x**2, axis=axis))


def resampled_se(theta: Callable[[np.ndarray], np.ndarray], n_seeds: int, n_speeds: int, method: str,
                 n_boot: int = 2000, seed: int = 0) -> np.ndarray:
    """Standard error over paired seeds of a statistic of the seeds.

    Parameters
    ----------
    theta : callable
        ``theta(seed_indices) → (W,)``: the statistic of the seeds selected by an index array
        (the same seeds for every controller: paired).
    n_seeds : int
        Number of seeds S.
    n_speeds : int
        Number of wind speeds W (the length of ``theta``'s result).
    method : {"jackknife", "bootstrap"}
        Jackknife: θ_(i) from all seeds but i, SE = √((S−1)/S Σ(θ_(i) − θ̄)²). Bootstrap:
        ``n_boot`` resamples of the seed indices, SE = SD of the replicates.
    n_boot : int, default 2000
        Bootstrap replicates.
    seed : int, default 0
        Seed of ``np.random.default_rng`` for the bootstrap.

    Returns
    -------
    numpy.ndarray
        (W,) standard errors (the statistic's unit); NaN with fewer than 2 seeds.

    Raises
    ------
    ValueError
        An unknown ``method``.
    """
    S, W = n_seeds, n_speeds
    if method not in ("jackknife", "bootstrap"):
        raise ValueError(f"method={method!r} must be 'jackknife' or 'bootstrap'")
    if S < 2:
        return np.full(W, np.nan)
    if method == "jackknife":
        keep = np.arange(S)
        reps = np.stack([theta(np.delete(keep, i)) for i in range(S)], axis=-1)
        return np.sqrt((S - 1) / S * np.sum((reps - reps.mean(axis=-1, keepdims=True)) ** 2, axis=-1))
    rng = np.random.default_rng(seed)
    reps = np.stack([theta(i) for i in rng.integers(0, S, size=(int(n_boot), S))], axis=-1)
    return reps.std(axis=-1, ddof=1)


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class PairedChange:
    """Relative change (%) designed vs baseline per wind speed, with its standard error.

    Parameters
    ----------
    indicator : str
        The indicator compared (:data:`~specdesign.validate.metrics.INDICATORS`).
    wind_speeds : numpy.ndarray
        (W,) wind speeds (m/s), or 0..W−1 when none were given.
    change : numpy.ndarray
        (W,) 100·(X_des/X_base − 1) of the seed-pooled indicator (%).
    se : numpy.ndarray
        (W,) standard error over paired seeds (percentage points).
    method : str
        "jackknife" or "bootstrap".
    n_seeds : int
        Number of paired seeds S.

    See Also
    --------
    paired_change : Computes it.
    """

    indicator: str
    wind_speeds: np.ndarray
    change: np.ndarray
    se: np.ndarray
    method: str
    n_seeds: int


def paired_change(designed, baseline, indicator: str = "tower_del", *, m: float = TOWER_M, wind_speeds=None,
                  method: str = "jackknife", n_boot: int = 2000, seed: int = 0) -> PairedChange:
    """Paired-seed relative change of an indicator, with jackknife (default) or bootstrap SE.

    Seeds are pooled by :func:`pool` (DEL by damage, SDs by variance).

    Parameters
    ----------
    designed, baseline : array_like
        (W, S) per-run values on the same seeds (seed j of both saw the same wind), in the
        indicator's unit; a 1-D array is one wind speed.
    indicator : str, default "tower_del"
        One of :data:`~specdesign.validate.metrics.INDICATORS`.
    m : float, default 4.0
        Wöhler exponent (for the DEL).
    wind_speeds : array_like, optional
        (W,) wind speeds (m/s) to label the result; default 0..W−1.
    method, n_boot, seed
        The standard error's method ("jackknife" by default), bootstrap replicates and seed, as
        :func:`resampled_se` takes them.

    Returns
    -------
    PairedChange
        The change (%) and its SE (pp) per wind speed.

    Raises
    ------
    ValueError
        Shapes that differ, an unknown ``indicator`` or ``method``.

    Examples
    --------
    >>> r = paired_change([[9.0, 11.0]], [[10.0, 12.0]], "mean_power")
    >>> round(float(r.change[0]), 3)
    -9.091
    """
    a = np.atleast_2d(np.asarray(designed, dtype=float))
    b = np.atleast_2d(np.asarray(baseline, dtype=float))
    if a.shape != b.shape:
        raise ValueError(f"designed {a.shape} and baseline {b.shape} must have the same (W, S) shape: paired seeds")
    if indicator not in INDICATORS:
        raise ValueError(f"indicator={indicator!r} must be one of {INDICATORS}")
    W, S = a.shape
    vs = np.arange(W, dtype=float) if wind_speeds is None else np.asarray(wind_speeds, dtype=float)

    def theta(ia, ib):
        return 100.0 * (pool(indicator, ia, m) / pool(indicator, ib, m) - 1.0)

    est = theta(a, b)
    se = resampled_se(lambda idx: theta(a[:, idx], b[:, idx]), S, W, method, n_boot, seed)
    return PairedChange(indicator=indicator, wind_speeds=vs, change=est, se=se, method=method, n_seeds=S)


def seeds_from(seeds) -> np.ndarray:
    """The seeds of a campaign, in a campaign file and in :func:`run_campaign` alike.

    Parameters
    ----------
    seeds : int or sequence of int
        An integer n means the n seeds 0, 1, …, n − 1; a sequence lists distinct integer seeds.

    Returns
    -------
    numpy.ndarray
        (S,) int64 seeds.

    Raises
    ------
    ValueError
        An integer below 1, an empty sequence, a non-integer or repeated seed.

    Examples
    --------
    >>> seeds_from(3).tolist(), seeds_from([7, 2]).tolist()
    ([0, 1, 2], [7, 2])
    """
    if isinstance(seeds, (int, np.integer)) and not isinstance(seeds, bool):
        if seeds < 1:
            raise ValueError(f"seeds={seeds!r}: an integer n means the seeds 0..n−1 and must be ≥ 1")
        return np.arange(int(seeds), dtype=np.int64)
    items = list(np.atleast_1d(np.asarray(seeds, dtype=object)))
    if not items or not all(isinstance(s, (int, np.integer)) and not isinstance(s, bool) for s in items):
        raise ValueError(f"seeds must be an integer n (the seeds 0..n−1) or a non-empty list of integers, got {seeds!r}")
    out = np.asarray(items, dtype=np.int64)
    if len(set(out.tolist())) != out.size:
        raise ValueError(f"seeds must be distinct, got {out.tolist()}")
    return out
