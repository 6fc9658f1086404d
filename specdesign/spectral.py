"""Spectral fatigue: moments, damage rates (narrow-band, Dirlik, Tovo-Benasciutti, ...), DEL,
and the damage sensitivity ΔD%(ω) of the seed paper's Eq. (7).

Conventions (the workbench's, as in the documentation's method page):

- ω in rad/s; PSDs one-sided per rad/s (∫₀^∞ S(ω) dω = variance), in load units² per rad/s.
- Spectral moments m_n = ∫ ω^n S(ω) dω by the trapezoid rule on the given (possibly
  non-uniform) grid; rates derived from them are in Hz (cycles or peaks per second).
- S-N curve range-based with S_ref = 1: N(S) = S^(-m), S the cycle **range**. The damage
  rate is then E[Σ S_i^m] per second (load units^m / s); any other intercept divides it by
  S_ref^m.
- DEL at 1 Hz: DEL = (damage_rate / n_eq_rate)^(1/m), a range in load units.
- Every function works on PSD stacks of shape (..., n): thousands of spectra are one call.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import gamma

from ._checks import as_omega, as_psd, as_real, positive_scalar, representable

__all__ = [
    "METHODS",
    "trapezoid_weights",
    "moments",
    "SpectralStats",
    "spectral_stats",
    "damage_rate",
    "del_spectral",
    "dirlik_range_pdf",
    "sensitivity",
    "predicted_change",
    "Change",
    "del_reduction",
    "exact_change",
]

# Every method is a closed form in these moments, so they are integrated once per spectrum.
_ORDERS = (0.0, 0.75, 1.0, 1.5, 2.0, 4.0)
# Below this bandwidth gap 1 - α2, Dirlik's coefficients are 0/0 and lose all digits; the
# narrow-band (Rayleigh) result is their limit and is what a single-line spectrum should give.
_NARROW = 1e-9


def trapezoid_weights(omega: ArrayLike) -> np.ndarray:
    """Trapezoid quadrature weights w_k (rad/s) on a possibly non-uniform grid.

    ∫ f dω ≈ Σ_k w_k f(ω_k): the weights every spectral moment of this module is built from.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Frequency grid in rad/s: 1-D, finite, strictly increasing, >= 0, at least 2 points.

    Returns
    -------
    ndarray, shape (n,)
        Weights w_k in rad/s; they sum to ω[-1] − ω[0].

    Raises
    ------
    TypeError
        If ``omega`` is complex or not numeric.
    ValueError
        If ``omega`` is not a 1-D grid of at least 2 finite, strictly increasing,
        non-negative frequencies.

    Examples
    --------
    >>> from specdesign.spectral import trapezoid_weights
    >>> trapezoid_weights([0.0, 1.0, 3.0])
    array([0.5, 1.5, 1. ])
    """
    w = as_omega(omega)
    d = np.diff(w)
    q = np.zeros_like(w)
    q[:-1] += 0.5 * d
    q[1:] += 0.5 * d
    return q


def _moment_matrix(w: np.ndarray, orders) -> np.ndarray:
    # Column j holds w_k ω_k^n_j, so moments of a stack are one matrix product psd @ A.
    q = trapezoid_weights(w)
    return np.stack([q * w**n for n in orders], axis=-1)


def moments(omega: ArrayLike, psd: ArrayLike, orders: ArrayLike = (0, 1, 2, 4)) -> np.ndarray:
    """Spectral moments m_n = ∫ ω^n S(ω) dω by the trapezoid rule on the given grid.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Strictly increasing, non-negative frequencies in rad/s (non-uniform is fine).
    psd : array_like, shape (..., n)
        One-sided PSD(s) per rad/s (∫₀^∞ S dω = variance), in load units² per rad/s;
        finite and >= 0. A stack of spectra is one call.
    orders : array_like of float, shape (k,)
        Moment orders n (real, finite, >= 0). Default (0, 1, 2, 4).

    Returns
    -------
    ndarray, shape (..., k)
        Moments m_n in load units² (rad/s)^n, one column per order; m_0 is the variance.

    Raises
    ------
    TypeError
        If ``omega``, ``psd`` or ``orders`` is complex or not numeric.
    ValueError
        If ``omega`` is not a valid grid (see :func:`trapezoid_weights`), ``psd`` does not
        have shape (..., n) or has NaN, inf or negative values, or an order is negative,
        not finite or ``orders`` is not 1-D.

    Examples
    --------
    White noise of unit level on [0, 2] rad/s, sampled at three points:

    >>> from specdesign.spectral import moments
    >>> moments([0.0, 1.0, 2.0], [1.0, 1.0, 1.0])
    array([2., 2., 3., 9.])
    >>> moments([0.0, 1.0, 2.0], [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]], orders=[0])
    array([[2.],
           [4.]])
    """
    w = as_omega(omega)
    s = as_psd(psd, w.size)
    o = np.atleast_1d(as_real(orders, "orders"))
    if o.ndim != 1 or not np.all(np.isfinite(o)) or np.any(o < 0):
        raise ValueError(f"orders must be a sequence of finite, non-negative moment orders, got {orders!r}")
    return s @ _moment_matrix(w, o)


@dataclass(frozen=True)
class SpectralStats:
    """Spectral moments of a PSD stack, integrated once, and the parameters derived from them.

    Built by :func:`spectral_stats`; every field and property has the stack shape (...).

    Parameters
    ----------
    m0 : ndarray
        Zeroth moment, the variance, load units².
    m075 : ndarray
        Moment of order 0.75, load units² (rad/s)^0.75.
    m1 : ndarray
        First moment, load units² rad/s.
    m15 : ndarray
        Moment of order 1.5, load units² (rad/s)^1.5.
    m2 : ndarray
        Second moment, load units² (rad/s)².
    m4 : ndarray
        Fourth moment, load units² (rad/s)⁴.

    See Also
    --------
    spectral_stats : Integrates these moments from a grid and a PSD stack.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.spectral import spectral_stats
    >>> omega = np.linspace(0.0, 5.0, 501)                        # rad/s
    >>> psd = 1.0 / ((1 - omega**2) ** 2 + (0.2 * omega) ** 2)    # one-sided, per rad/s
    >>> st = spectral_stats(omega, psd)
    >>> print(f"{st.m0:.4f} {st.nu0:.4f} {st.alpha2:.4f}")       # variance, Hz, -
    7.8512 0.1571 0.7834
    >>> print(f"{st.damage_rate(4):.1f}")                         # load units^4 / s
    1176.8
    """

    m0: np.ndarray
    m075: np.ndarray
    m1: np.ndarray
    m15: np.ndarray
    m2: np.ndarray
    m4: np.ndarray

    @classmethod
    def _from_array(cls, mom):
        return cls(*(mom[..., j] for j in range(len(_ORDERS))))

    def damage_rate(self, m: float, method: str = "dirlik") -> np.ndarray:
        """Damage per second for N = S^(-m) (S the range), from the stored moments.

        Same result as :func:`damage_rate` on the spectra these moments came from, without
        integrating them again.

        Parameters
        ----------
        m : float
            Wöhler exponent (> 0) of the range-based S-N curve N(S) = S^(-m) (S_ref = 1).
        method : str
            One of :data:`METHODS` (see :func:`damage_rate`). Default "dirlik".

        Returns
        -------
        ndarray, shape (...)
            E[Σ S_i^m] per second, load units^m / s; 0 for a spectrum without variance.

        Raises
        ------
        TypeError
            If ``m`` is complex or not a number.
        ValueError
            If ``m`` is not finite and > 0, ``method`` is unknown, or the method gives a
            damage <= 0 for a spectrum outside its range (see :func:`damage_rate`).
        OverflowError
            If a damage rate is outside float64's range (see :func:`damage_rate`).
        """
        mom = np.stack([self.m0, self.m075, self.m1, self.m15, self.m2, self.m4], axis=-1)
        return _damage_from_moments(mom, positive_scalar(m, "m"), method)

    @property
    def nu0(self) -> np.ndarray:
        """Mean up-crossing rate of the mean level, Hz: √(m2/m0)/(2π) (0 if m0 = 0)."""
        return _safe_div_sqrt(self.m2, self.m0) / (2 * np.pi)

    @property
    def nu_p(self) -> np.ndarray:
        """Peak (local maximum) rate, Hz: √(m4/m2)/(2π) (0 if m2 = 0)."""
        return _safe_div_sqrt(self.m4, self.m2) / (2 * np.pi)

    @property
    def alpha1(self) -> np.ndarray:
        """Bandwidth parameter α1 = m1/√(m0 m2), dimensionless (1 for a single line)."""
        return _safe_div(self.m1, np.sqrt(self.m0 * self.m2))

    @property
    def alpha2(self) -> np.ndarray:
        """Irregularity factor α2 = m2/√(m0 m4) = ν0/ν_p, dimensionless (1 for a single line)."""
        return _safe_div(self.m2, np.sqrt(self.m0 * self.m4))

    @property
    def alpha075(self) -> np.ndarray:
        """Bandwidth parameter α0.75 = m0.75/√(m0 m1.5), dimensionless (1 for a single line)."""
        return _safe_div(self.m075, np.sqrt(self.m0 * self.m15))


def _safe_div(a, b):
    a, b = np.asarray(a), np.asarray(b)
    ok = b != 0
    return np.where(ok, a / np.where(ok, b, 1.0), 0.0)


def _safe_div_sqrt(a, b):
    return np.sqrt(_safe_div(a, b))


def spectral_stats(omega: ArrayLike, psd: ArrayLike) -> SpectralStats:
    """Integrate the moments m0, m0.75, m1, m1.5, m2, m4 of a PSD stack once.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Frequency grid in rad/s (strictly increasing, >= 0).
    psd : array_like, shape (..., n)
        One-sided PSD(s) per rad/s, load units² per rad/s.

    Returns
    -------
    SpectralStats
        The six moments (shape (...)), the rates ν0, ν_p (Hz), the bandwidth parameters and
        :meth:`SpectralStats.damage_rate`.

    Raises
    ------
    TypeError
        If ``omega`` or ``psd`` is complex or not numeric.
    ValueError
        If ``omega`` is not a valid grid or ``psd`` does not match it or has NaN, inf or
        negative values.

    Examples
    --------
    >>> from specdesign.spectral import spectral_stats
    >>> st = spectral_stats([0.0, 1.0, 2.0], [1.0, 1.0, 1.0])
    >>> print(st.m0, st.m2, st.m4)
    2.0 3.0 9.0
    """
    return SpectralStats._from_array(moments(omega, psd, _ORDERS))


# --- damage rates from moments ---------------------------------------------------------
# Each takes the moment tuple (m0, m075, m1, m15, m2, m4) of equal-shape arrays and the
# exponent m, and returns E[Σ S^m] per second for N = S^(-m), S the range. They are written
# to accept complex moments so that the analytic sensitivity can use the complex step.
# Spectra with m0 = 0 or m2 = 0 (no variance, or nothing but a static offset) carry no
# cycles: their damage is set to zero by the caller.


def _nb(mo, m):
    m0, _, _, _, m2, _ = mo
    nu0 = np.sqrt(m2 / m0) / (2 * np.pi)
    # Rayleigh amplitudes with variance m0; range = 2 × amplitude.
    return nu0 * (2.0 * np.sqrt(2.0 * m0)) ** m * gamma(1.0 + m / 2.0)


def _dirlik_coefficients(mo):
    m0, _, m1, _, m2, m4 = mo
    xm = (m1 / m0) * np.sqrt(m2 / m4)
    g = m2 / np.sqrt(m0 * m4)
    g1 = 2.0 * (xm - g**2) / (1.0 + g**2)
    r = (g - xm - g1**2) / (1.0 - g - g1 + g1**2)
    g2 = (1.0 - g - g1 + g1**2) / (1.0 - r)
    g3 = 1.0 - g1 - g2
    q = 1.25 * (g - g3 - g2 * r) / g1
    return g1, g2, g3, r, q


def _abs(z):
    # |z| that stays complex-analytic for a small imaginary (complex-step) perturbation.
    return z * np.sign(np.real(z))


def _dirlik(mo, m):
    m0, _, _, _, m2, m4 = mo
    g1, g2, g3, r, q = _dirlik_coefficients(mo)
    nu_p = np.sqrt(m4 / m2) / (2 * np.pi)
    bracket = g1 * q**m * gamma(1.0 + m) + np.sqrt(2.0) ** m * gamma(1.0 + m / 2.0) * (g2 * _abs(r) ** m + g3)
    return nu_p * (2.0 * np.sqrt(m0)) ** m * bracket


def _tb(mo, m):
    m0, _, m1, _, m2, m4 = mo
    a1 = m1 / np.sqrt(m0 * m2)
    a2 = m2 / np.sqrt(m0 * m4)
    # Tovo-Benasciutti 2005 weight (FLife "method 2").
    b = (a1 - a2) * (1.112 * (1 + a1 * a2 - (a1 + a2)) * np.exp(2.11 * a2) + (a1 - a2)) / (a2 - 1) ** 2
    return _nb(mo, m) * (b + (1.0 - b) * a2 ** (m - 1.0))


def _alpha075(mo, m):
    m0, m075, _, m15, _, _ = mo
    return _nb(mo, m) * (m075 / np.sqrt(m0 * m15)) ** 2


def _zhao_baker(mo, m):
    m0, _, _, _, m2, m4 = mo
    a2 = m2 / np.sqrt(m0 * m4)
    a = 8.0 - 7.0 * a2
    b = np.where(np.real(a2) < 0.9, 1.1 + 0 * a2, 1.1 + 9.0 * (a2 - 0.9))
    w = (1.0 - a2) / (1.0 - np.sqrt(2.0 / np.pi) * gamma(1.0 + 1.0 / b) * a ** (-1.0 / b))
    nu_p = np.sqrt(m4 / m2) / (2 * np.pi)
    amp = w * a ** (-m / b) * gamma(1.0 + m / b) + (1.0 - w) * 2.0 ** (0.5 * m) * gamma(1.0 + 0.5 * m)
    # Method 1 of Zhao & Baker, on amplitudes; ranges add 2^m.
    return nu_p * 2.0**m * m0 ** (0.5 * m) * amp


_METHODS = {
    "narrowband": _nb,
    "dirlik": _dirlik,
    "tovo_benasciutti": _tb,
    "alpha075": _alpha075,
    "zhao_baker": _zhao_baker,
}
METHODS = tuple(_METHODS)


def _check_method(method):
    if method not in _METHODS:
        raise ValueError(f"method={method!r} is not known; choose one of {METHODS}")
    return _METHODS[method]


def _damage_parts(mom, m, method):
    """(d_n, s0) for a moment array (..., 6) in _ORDERS: damage rate = d_n · s0^(m/2).

    Every moment scales with S, and every method is homogeneous of degree m/2 in the moments,
    so the damage is evaluated on the moments divided by s0 = m0 (d_n: the damage of the
    spectrum scaled to unit variance, finite for any m ≤ 100) and the load scale comes back
    as s0^(m/2) only where the caller needs the damage itself; a DEL or a damage ratio never
    forms it and so never overflows. Degenerate spectra (m0 = 0 or m2 = 0) give d_n = 0, s0 = 1.
    """
    f = _check_method(method)
    re = np.real(mom)
    m0, m2 = re[..., 0], re[..., 4]
    alive = (m0 > 0) & (m2 > 0)
    s0 = np.where(alive, m0, 1.0)
    safe = np.where(alive[..., None], mom / s0[..., None], 1.0)
    mo = tuple(safe[..., j] for j in range(len(_ORDERS)))
    with np.errstate(all="ignore"):
        d = f(mo, m)
        if method in ("dirlik", "tovo_benasciutti", "zhao_baker"):
            # α2 → 1 (a single spectral line): their coefficients are 0/0 there; the
            # narrow-band result is the limit of all of them.
            a2 = np.real(mo[4]) / np.sqrt(np.real(mo[0]) * np.real(mo[5]))
            # (NaN only: an inf is an overflow at a huge m, which the narrow band must not hide)
            narrow = ((1.0 - a2) < _NARROW) | np.isnan(d)
            d = np.where(narrow, _nb(mo, m), d)
    # On unit-variance moments every method is finite up to m ≈ 170, where Dirlik's Γ(1+m)
    # overflows (its largest term ν_p 2^m q^m Γ(1+m) is < 1e188 ν_p at m = 100: q, the mean
    # range of its exponential part in units of 2√m0, is below 0.5 on every spectrum tried
    # and → 0 towards a single line)
    d_re = np.real(d)
    if np.any(alive & np.isinf(d_re)):
        raise OverflowError(f"m={m:g} is too large for float64: even the spectrum scaled to unit variance has a "
                            f"damage above 1.8e308 with method={method!r} (m <= 100 is supported by every method)")
    # what remains is a method used outside its range: Zhao-Baker's Rayleigh weight 1 - w turns
    # negative on very wide-band spectra (α2 ≲ 0.15) and its damage with it; a DEL of that is NaN
    bad = alive & ~(d_re > 0)
    if np.any(bad):
        a2 = np.real(mo[4]) / np.sqrt(np.real(mo[0]) * np.real(mo[5]))
        raise ValueError(f"method={method!r} gives a damage <= 0 (or NaN) at m={m:g} for a spectrum with "
                         f"α2 = {float(np.min(np.where(bad, a2, np.inf))):.3g}: the spectrum is outside the "
                         "method's range of validity; use method='dirlik'")
    return np.where(alive, d, 0.0), s0


def _damage_from_moments(mom, m, method):
    """Damage rate for a moment array (..., 6) in _ORDERS; handles degenerate spectra.

    Raises OverflowError where the damage itself is not representable in float64 (large
    or tiny loads at a large Wöhler exponent): its DEL still is (:func:`del_spectral`).
    """
    dn, s0 = _damage_parts(mom, m, method)
    with np.errstate(over="ignore", under="ignore"):
        d = dn * s0 ** (0.5 * m)
    return representable(d, np.real(dn) > 0, f"the damage rate at m={m:g} (load scale √m0 from "
                         f"{np.sqrt(np.min(s0)):.3g} to {np.sqrt(np.max(s0)):.3g})",
                         "compute the DEL (del_spectral) or a ratio (exact_change, sensitivity), "
                         "which never form it, or express the load in other units")


def _prepare(omega, psd, m):
    w = as_omega(omega)
    s = as_psd(psd, w.size)
    return w, s, positive_scalar(m, "m")


def damage_rate(omega: ArrayLike, psd: ArrayLike, m: float, method: str = "dirlik") -> np.ndarray:
    """Fatigue damage per second of a Gaussian load with one-sided PSD S(ω).

    Parameters
    ----------
    omega : array_like, shape (n,)
        Frequencies, rad/s (strictly increasing, >= 0).
    psd : array_like, shape (..., n)
        One-sided PSD(s) per rad/s, load units² s/rad (∫₀^∞ S dω = variance).
    m : float
        Wöhler exponent (> 0, any real) of the range-based S-N curve N = S^(-m) (S the cycle
        range, S_ref = 1; for N = (S_ref/S)^m divide the result by S_ref^m).
    method : str
        "narrowband", "dirlik" (default), "tovo_benasciutti" (TB 2005, FLife's "method 2"),
        "alpha075" (Benasciutti's α0.75 correction) or "zhao_baker" (method 1); the tuple
        :data:`METHODS` lists them.

    Returns
    -------
    ndarray, shape (...)
        E[Σ S_i^m] per second (load units^m / s), i.e. the Miner damage per second for
        S_ref = 1. Zero for an all-zero PSD; the narrow-band limit for a (near) single-line
        PSD.

    Raises
    ------
    OverflowError
        If a damage is outside float64's range: it scales as √m0^m, so N·m loads (√m0 ~ 1e7)
        overflow from m ≈ 40 and tiny ones underflow. An inf or 0 would be silently wrong
        in every ratio made of it; :func:`del_spectral`, :func:`sensitivity` and
        :func:`exact_change` work on the unit-variance spectrum and stay exact at any scale.
    ValueError
        If ``method`` gives a damage <= 0 for the spectrum (Zhao-Baker on very wide-band
        spectra at a large m), and for invalid arguments: an unknown ``method``, ``m`` not
        finite and > 0, an invalid grid, a PSD of the wrong shape or with NaN, inf or
        negative values.
    TypeError
        If an argument is complex or not numeric.

    See Also
    --------
    del_spectral : The damage equivalent load, finite at any load scale.
    SpectralStats.damage_rate : The same from moments integrated once.

    Examples
    --------
    A lightly damped mode at 1 rad/s (damping ratio 0.1):

    >>> import numpy as np
    >>> from specdesign.spectral import damage_rate
    >>> omega = np.linspace(0.0, 5.0, 501)                        # rad/s
    >>> psd = 1.0 / ((1 - omega**2) ** 2 + (0.2 * omega) ** 2)    # one-sided, per rad/s
    >>> print(f"{damage_rate(omega, psd, m=4):.1f}")              # load units^4 / s
    1176.8
    >>> print(f"{damage_rate(omega, psd, m=4, method='narrowband'):.1f}")
    1239.4

    A stack of spectra is one call; the damage scales as variance^(m/2):

    >>> d = damage_rate(omega, np.stack([psd, 4.0 * psd]), m=4)
    >>> d.shape
    (2,)
    >>> print(f"{d[1] / d[0]:.6f}")
    16.000000
    """
    w, s, m = _prepare(omega, psd, m)
    _check_method(method)
    return _damage_from_moments(s @ _moment_matrix(w, _ORDERS), m, method)


def del_spectral(omega: ArrayLike, psd: ArrayLike, m: float, method: str = "dirlik",
                 n_eq_rate: float = 1.0) -> np.ndarray:
    """Damage equivalent load (a range, load units) at ``n_eq_rate`` Hz (default 1 Hz).

    DEL = (damage_rate / n_eq_rate)^(1/m): the constant range that, cycled n_eq_rate times a
    second, does the damage of the spectrum.

    Computed as √m0 · (d₁ / n_eq_rate)^(1/m), d₁ the damage rate of the spectrum scaled to unit
    variance, so it is finite and exact (DEL(c²·S) = c·DEL(S)) for any m <= 100 and any load
    scale, where the damage rate itself would overflow. Beyond m ≈ 170 even d₁ leaves float64
    (Dirlik's Γ(1 + m)): OverflowError, never inf.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Frequencies, rad/s (strictly increasing, >= 0).
    psd : array_like, shape (..., n)
        One-sided PSD(s) per rad/s, load units² s/rad.
    m : float
        Wöhler exponent (> 0) of the range-based S-N curve N = S^(-m); the DEL does not
        depend on S_ref.
    method : str
        Damage method, one of :data:`METHODS` (see :func:`damage_rate`). Default "dirlik".
    n_eq_rate : float
        Equivalent cycle rate in Hz (> 0); default 1 Hz, the usual 1 Hz DEL.

    Returns
    -------
    ndarray, shape (...)
        DEL, a cycle **range** in load units (e.g. N·m for a moment in N·m). Zero for an
        all-zero PSD.

    Raises
    ------
    OverflowError
        If m is so large (≳ 170) that the damage of even the unit-variance spectrum leaves
        float64.
    ValueError
        For an unknown ``method``, ``m`` or ``n_eq_rate`` not finite and > 0, an invalid
        grid or PSD, or a method giving a damage <= 0 outside its range of validity.
    TypeError
        If an argument is complex or not numeric.

    See Also
    --------
    damage_rate : The damage per second the DEL is equivalent to.
    specdesign.fatigue.del_rainflow : The DEL of a time series.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.spectral import damage_rate, del_spectral
    >>> omega = np.linspace(0.0, 5.0, 501)                        # rad/s
    >>> psd = 1.0 / ((1 - omega**2) ** 2 + (0.2 * omega) ** 2)    # one-sided, per rad/s
    >>> print(f"{del_spectral(omega, psd, m=4):.4f}")             # load units, 1 Hz
    5.8570
    >>> print(f"{damage_rate(omega, psd, m=4) ** 0.25:.4f}")
    5.8570

    Homogeneous of degree 1 in the load, and finite where the damage rate overflows:

    >>> print(del_spectral(omega, 4.0 * psd, m=4) / del_spectral(omega, psd, m=4))
    2.0
    >>> print(f"{del_spectral(omega, 1e14 * psd, m=50):.4e}")     # √m0 ≈ 2.8e7
    2.4338e+08
    """
    rate = positive_scalar(n_eq_rate, "n_eq_rate")
    w, s, m = _prepare(omega, psd, m)
    dn, s0 = _damage_parts(s @ _moment_matrix(w, _ORDERS), m, method)
    # DEL is homogeneous of degree 1 in the load: √s0 carries the scale, never raised to m
    return np.sqrt(s0) * (dn / rate) ** (1.0 / m)


def dirlik_range_pdf(omega: ArrayLike, psd: ArrayLike, ranges: ArrayLike) -> np.ndarray:
    """Dirlik's probability density of cycle **ranges** (1/load unit).

    Parameters
    ----------
    omega : array_like, shape (n,)
        Frequency grid in rad/s (strictly increasing, >= 0).
    psd : array_like, shape (..., n)
        One-sided PSD(s) per rad/s, load units² per rad/s.
    ranges : array_like, shape (k,)
        Ranges S >= 0 (load units, peak to valley) at which to evaluate the density.

    Returns
    -------
    ndarray, shape (..., k)
        Density p(S) in 1/load unit, integrating to 1 over S in [0, ∞). Rayleigh (narrow-band) for a
        single-line spectrum; zeros for an all-zero one.

    Raises
    ------
    ValueError
        If ``ranges`` is not 1-D, finite and >= 0, or ``omega``/``psd`` are invalid.
    TypeError
        If an argument is complex or not numeric.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.spectral import dirlik_range_pdf
    >>> omega = np.linspace(0.0, 5.0, 501)                        # rad/s
    >>> psd = 1.0 / ((1 - omega**2) ** 2 + (0.2 * omega) ** 2)    # one-sided, per rad/s
    >>> print(np.round(dirlik_range_pdf(omega, psd, [0.0, 1.0, 5.0, 10.0]), 4))
    [0.1428 0.1488 0.0812 0.0482]
    >>> from scipy.integrate import trapezoid
    >>> s = np.linspace(0.0, 200.0, 20001)                        # load units
    >>> print(f"{trapezoid(dirlik_range_pdf(omega, psd, s), s):.5f}")
    1.00000
    """
    w = as_omega(omega)
    s = as_psd(psd, w.size)
    r = as_real(ranges, "ranges")
    if r.ndim != 1 or not np.all(np.isfinite(r)) or np.any(r < 0):
        raise ValueError("ranges must be a 1-D array of finite, non-negative cycle ranges (load units)")
    mom = s @ _moment_matrix(w, _ORDERS)
    alive = (mom[..., 0] > 0) & (mom[..., 4] > 0)
    mom = np.where(alive[..., None], mom, 1.0)
    mo = tuple(mom[..., j] for j in range(len(_ORDERS)))
    with np.errstate(all="ignore"):
        g1, g2, g3, rr, q = (c[..., None] for c in _dirlik_coefficients(mo))
        sd = np.sqrt(mo[0])[..., None]
        z = r / (2.0 * sd)
        p = (g1 / q * np.exp(-z / q) + g2 * z / rr**2 * np.exp(-(z**2) / (2 * rr**2)) + g3 * z * np.exp(-(z**2) / 2)) / (2 * sd)
        a2 = (mo[4] / np.sqrt(mo[0] * mo[5]))[..., None]
        rayleigh = z * np.exp(-(z**2) / 2) / (2 * sd)
        p = np.where(((1.0 - a2) < _NARROW) | ~np.isfinite(p), rayleigh, p)
    return np.where(alive[..., None], p, 0.0)


def sensitivity(omega: ArrayLike, psd: ArrayLike, m: float, reduction: float = 0.01, method: str = "dirlik",
                analytic: bool = False) -> np.ndarray:
    """Damage sensitivity ΔD%(ω) of the seed paper's Eq. (7), for every grid frequency.

    ΔD%(ω_k) = 100 · (D_0 − D_k)/D_0, where D_k is the damage of the PSD with its value at ω_k
    reduced by ``reduction`` (0.01 = the paper's 1 %). Moments are linear in S, so the N
    modified spectra are one moment update, m_n − reduction · w_k ω_k^n S_k (w_k the
    trapezoid weights), and the damage formula is evaluated once on all N moment sets.

    ΔD% is a ratio of damages, so it does not depend on the load scale or on S_ref; it is
    computed on each spectrum scaled to unit variance and stays finite for any m <= 100.
    It is defined per grid point, so it scales with the grid spacing: apply
    :func:`predicted_change` on the same grid.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Grid, rad/s (strictly increasing, >= 0).
    psd : array_like, shape (..., n)
        One-sided PSD(s) per rad/s, load units² per rad/s.
    m : float
        Wöhler exponent (> 0) of the range-based S-N curve.
    reduction : float
        Relative reduction of S at one frequency, in (0, 1] (dimensionless; 0.01 = 1 %);
        ignored with ``analytic``.
    method : str
        Damage method, one of :data:`METHODS` (see :func:`damage_rate`). Default "dirlik".
    analytic : bool
        If True, the limit reduction → 0 scaled to 1 %: 100 · 0.01 · S_k ∂D/∂S_k / D_0 from
        exact (complex-step) derivatives of the damage with respect to the moments.

    Returns
    -------
    ndarray, shape (..., n)
        ΔD% per grid point (percent of D_0 for a 1 % reduction at that point; positive =
        less damage). Zero for an all-zero PSD.

    Raises
    ------
    ValueError
        If ``reduction`` is not in (0, 1] (checked with ``analytic`` too), for an unknown
        ``method``, ``m`` not finite and > 0, an invalid grid or PSD, or a method giving a
        damage <= 0 outside its range of validity.
    TypeError
        If ``omega``, ``psd``, ``m`` or ``reduction`` is complex or not a real number (a
        bool, a string or None included).
    OverflowError
        If m is so large (≳ 170) that the damage of even the unit-variance spectrum leaves
        float64.

    See Also
    --------
    predicted_change : Eq. (10), the damage reduction this sensitivity predicts.
    exact_change : The exact change between two spectra.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.spectral import sensitivity
    >>> omega = np.linspace(0.0, 5.0, 501)                        # rad/s
    >>> psd = 1.0 / ((1 - omega**2) ** 2 + (0.2 * omega) ** 2)    # one-sided, per rad/s
    >>> dd = sensitivity(omega, psd, m=4)                         # % per 1 % cut, per point
    >>> print(f"{omega[np.argmax(dd)]:.2f} rad/s")
    0.99 rad/s

    D is homogeneous of degree m/2 in S, so the analytic ΔD% sums to m/2 (the finite 1 % cut
    to nearly that):

    >>> print(f"{sensitivity(omega, psd, m=4, analytic=True).sum():.6f}")
    2.000000
    >>> print(f"{dd.sum():.4f}")
    1.9998
    """
    w, s, m = _prepare(omega, psd, m)
    _check_method(method)
    red = positive_scalar(reduction, "reduction")
    if not red <= 1:
        raise ValueError(f"reduction={reduction!r} must be in (0, 1] (0.01 is a 1 % reduction of S at one frequency)")
    a = _moment_matrix(w, _ORDERS)  # (n, 6)
    # ΔD% is a ratio, invariant to the load scale: work on each spectrum scaled to unit
    # variance so that no damage overflows at a large m
    m0 = s @ a[:, 0]
    s = s / np.where(m0 > 0, m0, 1.0)[..., None]
    mom0 = s @ a  # (..., 6)
    d0 = _damage_from_moments(mom0, m, method)
    with np.errstate(divide="ignore", invalid="ignore"):
        if analytic:
            # Complex step: D(m + i h e_j) has imaginary part h ∂D/∂m_j with no cancellation.
            grads = []
            for j in range(len(_ORDERS)):
                h = 1e-30 * np.maximum(np.abs(mom0[..., j]), 1e-300)
                mc = mom0.astype(complex)
                mc[..., j] += 1j * h
                grads.append(np.imag(_damage_from_moments(mc, m, method)) / h)
            dlogd = np.stack(grads, axis=-1) / d0[..., None]  # (..., 6)
            out = 100.0 * 0.01 * s * (dlogd @ a.T)
        else:
            delta = red * s[..., :, None] * a  # (..., n, 6): Δm_n for each frequency k
            dk = _damage_from_moments(mom0[..., None, :] - delta, m, method)
            out = 100.0 * (d0[..., None] - dk) / d0[..., None]
    return np.where((d0 > 0)[..., None], out, 0.0)


def predicted_change(omega: ArrayLike, sensitivity: ArrayLike, t_mag2: ArrayLike, w_mag2: ArrayLike) -> np.ndarray:
    """Predicted damage reduction (%) of a specification, the seed paper's Eq. (10).

    ΔD_W = Σ_ω ΔD%(ω) · (|T(iω)|² − |W(iω)|²)/|T(iω)|² · 100, summed over the grid points
    exactly as written (ΔD% is defined per grid point, so no quadrature weights).

    Parameters
    ----------
    omega : array_like, shape (n,)
        Grid in rad/s on which ``sensitivity`` was computed.
    sensitivity : array_like, shape (..., n)
        ΔD%(ω) from :func:`sensitivity` (percent per 1 % reduction at each grid point).
    t_mag2 : array_like, shape (..., n)
        |T(iω)|² of the baseline transfer to the load (any unit, >= 0, real: pass
        ``abs(T)**2``, not T).
    w_mag2 : array_like, shape (..., n)
        |W(iω)|² of the specification, in the unit of ``t_mag2`` (>= 0).

    Returns
    -------
    ndarray, shape (...)
        Predicted reduction of damage in percent (positive = less damage). Grid points where
        |T|² = 0 carry no spectrum and contribute nothing.

    Raises
    ------
    ValueError
        If an array does not have shape (..., n) to match ``omega``, has NaN or inf, or a
        squared magnitude is negative; or if ``omega`` is not a valid grid.
    TypeError
        If an argument is complex (e.g. T instead of |T|²) or not numeric.

    See Also
    --------
    sensitivity : ΔD%(ω), Eq. (7).
    exact_change : The exact change, to check a prediction.
    del_reduction : The DEL reduction equivalent to a damage reduction.

    Examples
    --------
    A specification 10 % below the baseline at every frequency: to first order a 20 %
    damage reduction at m = 4 (the exact one, 1 − 0.9², is 19 %; see :func:`exact_change`):

    >>> import numpy as np
    >>> from specdesign.spectral import predicted_change, sensitivity
    >>> omega = np.linspace(0.0, 5.0, 501)                        # rad/s
    >>> psd = 1.0 / ((1 - omega**2) ** 2 + (0.2 * omega) ** 2)    # one-sided, per rad/s
    >>> dd = sensitivity(omega, psd, m=4, analytic=True)
    >>> t2 = np.ones_like(omega)                                  # |T|², baseline
    >>> print(f"{predicted_change(omega, dd, t2, 0.9 * t2):.4f} %")
    20.0000 %
    """
    w = as_omega(omega)
    dd, t2, w2 = (as_real(v, n) for v, n in ((sensitivity, "sensitivity"), (t_mag2, "t_mag2"), (w_mag2, "w_mag2")))
    for name, v in (("sensitivity", dd), ("t_mag2", t2), ("w_mag2", w2)):
        if v.ndim == 0 or v.shape[-1] != w.size:
            raise ValueError(f"{name} must have shape (..., {w.size}) to match omega, got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name} contains NaN or inf")
    if np.any(t2 < 0) or np.any(w2 < 0):
        raise ValueError("t_mag2 and w_mag2 are squared magnitudes |T|², |W|² and must be >= 0")
    ok = t2 > 0
    ds = np.where(ok, (t2 - w2) / np.where(ok, t2, 1.0) * 100.0, 0.0)
    return np.sum(dd * ds, axis=-1)


@dataclass(frozen=True)
class Change:
    """Exact change between two spectra (percent; positive = reduction), from :func:`exact_change`.

    ``damage_before`` and ``damage_after`` (damage rates, load units^m / s) are formed only
    when read: the reductions are exact at any load scale, the damages may not fit in float64
    (OverflowError, see :func:`damage_rate`).

    Parameters
    ----------
    damage_reduction : ndarray, shape (...)
        100 (1 − D_after/D_before), percent.
    del_reduction : ndarray, shape (...)
        100 (1 − DEL_after/DEL_before), percent.
    _parts : tuple
        Internal: unit-variance damage rates and variances of both spectra, and m, from which
        the damages are formed when read. Not part of the public interface.

    See Also
    --------
    exact_change : Builds it.
    """

    damage_reduction: np.ndarray
    del_reduction: np.ndarray
    # (unit-variance damage rates n0, n1; variances s0, s1; m) of before and after
    _parts: tuple = field(repr=False, compare=False)

    @property
    def damage_before(self) -> np.ndarray:
        """Damage rate of ``psd_before``, load units^m / s (S_ref = 1); OverflowError outside float64."""
        n0, s0, _, _, m = self._parts
        return _scaled_damage(n0, s0, m)

    @property
    def damage_after(self) -> np.ndarray:
        """Damage rate of ``psd_after``, load units^m / s (S_ref = 1); OverflowError outside float64."""
        _, _, n1, s1, m = self._parts
        return _scaled_damage(n1, s1, m)


def _scaled_damage(dn, s0, m):
    with np.errstate(over="ignore", under="ignore"):
        d = dn * s0 ** (0.5 * m)
    return representable(d, dn > 0, f"the damage rate at m={m:g}", "use the reductions, which are exact at any scale")


def del_reduction(damage_reduction: ArrayLike, m: float) -> np.ndarray:
    """DEL reduction (%) equivalent to a damage reduction (%) at Wöhler exponent ``m``.

    100·(1 − (1 − ΔD/100)^(1/m)). A damage reduction of 100 % or more (possible for the
    first-order Eq. 10 estimate, never for an exact one) means no damage left: 100 %.

    Parameters
    ----------
    damage_reduction : array_like
        Damage reduction ΔD in percent (positive = less damage; negative = an increase).
    m : float
        Wöhler exponent (> 0).

    Returns
    -------
    ndarray
        DEL reduction in percent, same shape as ``damage_reduction``.

    Raises
    ------
    TypeError
        If ``damage_reduction`` or ``m`` is complex or not numeric.
    ValueError
        If ``m`` is not finite and > 0.

    Examples
    --------
    >>> from specdesign.spectral import del_reduction
    >>> print(f"{del_reduction(19.0, m=2):.6f}")    # 0.81 of the damage: 0.9 of the DEL
    10.000000
    >>> print(del_reduction([100.0, 120.0], m=4))   # no damage left
    [100. 100.]
    """
    ratio = np.clip(1.0 - as_real(damage_reduction, "damage_reduction") / 100.0, 0.0, None)
    return 100.0 * (1.0 - ratio ** (1.0 / positive_scalar(m, "m")))


def exact_change(omega: ArrayLike, psd_before: ArrayLike, psd_after: ArrayLike, m: float,
                 method: str = "dirlik") -> Change:
    """Exact damage and DEL reduction (%) from ``psd_before`` to ``psd_after``.

    damage_reduction = 100 (1 − D_after/D_before); del_reduction = 100 (1 − (D_after/D_before)^(1/m)),
    with D the damage rate of ``method`` (see :func:`damage_rate`). Both come from the log of
    the damage ratio of the unit-variance spectra and the variance ratio, so they are exact at
    any load scale and for m <= 100.

    Parameters
    ----------
    omega : array_like, shape (n,)
        Frequency grid in rad/s (strictly increasing, >= 0).
    psd_before : array_like, shape (..., n)
        One-sided PSD(s) per rad/s of the baseline, load units² per rad/s; not all-zero.
    psd_after : array_like, shape (..., n)
        One-sided PSD(s) per rad/s of the new design, same unit (broadcast against
        ``psd_before``).
    m : float
        Wöhler exponent (> 0) of the range-based S-N curve.
    method : str
        Damage method, one of :data:`METHODS`. Default "dirlik".

    Returns
    -------
    Change
        ``damage_reduction`` and ``del_reduction`` (percent, shape (...)); ``damage_before``
        and ``damage_after`` (load units^m / s) when read.

    Raises
    ------
    ValueError
        If ``psd_before`` has zero damage (an all-zero spectrum), for an unknown ``method``,
        ``m`` not finite and > 0, invalid grid or PSDs, or a method giving a damage <= 0
        outside its range of validity.
    TypeError
        If an argument is complex or not numeric.
    OverflowError
        If m is so large (≳ 170) that the damage of even a unit-variance spectrum leaves
        float64.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.spectral import exact_change
    >>> omega = np.linspace(0.0, 5.0, 501)                        # rad/s
    >>> psd = 1.0 / ((1 - omega**2) ** 2 + (0.2 * omega) ** 2)    # one-sided, per rad/s
    >>> c = exact_change(omega, psd, 0.9 * psd, m=4)
    >>> print(f"{c.damage_reduction:.4f} % damage, {c.del_reduction:.4f} % DEL")
    19.0000 % damage, 5.1317 % DEL
    >>> print(f"{c.damage_before:.1f} -> {c.damage_after:.1f}")   # load units^4 / s
    1176.8 -> 953.2
    """
    w = as_omega(omega)
    before = as_psd(psd_before, w.size, "psd_before")
    after = as_psd(psd_after, w.size, "psd_after")
    m = positive_scalar(m, "m")
    a = _moment_matrix(w, _ORDERS)
    (n0, s0), (n1, s1) = (_damage_parts(x @ a, m, method) for x in (before, after))
    if np.any(n0 <= 0):
        raise ValueError("psd_before has zero damage (all-zero spectrum); a relative change is undefined")
    # ln(D_after/D_before) from the unit-variance damages and the variance ratio: no damage is
    # formed, so no overflow at a large m; the DEL ratio is exp(ln(ratio)/m), taken directly
    # (not back from the rounded damage reduction) so a near-total reduction keeps its digits
    with np.errstate(divide="ignore"):
        log_ratio = np.where(n1 > 0, np.log(np.where(n1 > 0, n1, 1.0) / n0) + 0.5 * m * np.log(s1 / s0), -np.inf)
    with np.errstate(over="ignore"):
        damage = -100.0 * np.expm1(log_ratio)
    return Change(damage, -100.0 * np.expm1(log_ratio / m), (n0, s0, n1, s1, m))
