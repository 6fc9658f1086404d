"""Rotor-effective wind: IEC 61400-1 Kaimal spectra, rotor-disc coherence, turbulent series.

All spectra are one-sided and per rad/s (∫₀^∞ S(ω) dω = variance, (m/s)²); ω in rad/s.

- :func:`kaimal_spectrum`: longitudinal Kaimal spectrum of the normal turbulence model (NTM),
  σ = I_ref(0.75 U + 5.6), length scale L = 8.1 Λ with Λ = 42 m (hub height above 60 m).
- :func:`rotor_effective_spectrum`: Kaimal times the rotor-disc average of the IEC exponential
  coherence, γ(f) = ∫₀^{2R} exp(−12 √((f r/U)² + (0.12 r/L_c)²)) p_R(r) dr, with p_R the
  density of the distance between two random points of the disc and L_c = 8.1·42 m.
- :func:`gaussian_series`: Gaussian time series with a given one-sided PSD, reproducible per seed.
- :func:`wind_series`: the rotor-effective wind records the simulator runs on, one per
  (mean wind speed, seed), seeded by :func:`seed_for`.
"""
from __future__ import annotations

import functools
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ._checks import as_omega, positive_scalar

__all__ = ["TURBULENCE_CLASSES", "kaimal_spectrum", "disc_coherence", "rotor_effective_spectrum", "gaussian_series", "seed_for",
           "wind_series", "RECORD_LENGTH", "LOWEST_OMEGA", "record_window"]

#: IEC 61400-1 ed. 3/4 reference turbulence intensities I_ref by turbulence class.
TURBULENCE_CLASSES = {"A+": 0.18, "A": 0.16, "B": 0.14, "C": 0.12}
#: Turbulence scale parameter Λ (m) for hub heights above 60 m.
LAMBDA_1 = 42.0
#: Kaimal integral length scale of the longitudinal component (m) and coherence scale L_c (m).
KAIMAL_LENGTH = 8.1 * LAMBDA_1
COHERENCE_LENGTH = 8.1 * LAMBDA_1

# Gauss-Legendre nodes on the distance variable; the coherence decays over r ~ U/(12 f), so
# the nodes are placed in s = sqrt(r/2R), which clusters them near r = 0 where the
# integrand lives at high frequency.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(160)


def _sigma(mean_speed, turbulence_class):
    if turbulence_class not in TURBULENCE_CLASSES:
        raise ValueError(f"turbulence_class={turbulence_class!r} must be one of {sorted(TURBULENCE_CLASSES)}")
    return TURBULENCE_CLASSES[turbulence_class] * (0.75 * mean_speed + 5.6)


def kaimal_spectrum(omega: ArrayLike, mean_speed: float, turbulence_class: str = "B") -> np.ndarray:
    """One-sided Kaimal spectrum of the longitudinal wind at a point, ((m/s)² per rad/s).

    S(ω) = S_f(ω/2π)/(2π), S_f(f) = 4σ²(L/U)/(1 + 6fL/U)^{5/3} (per Hz), σ = I_ref(0.75U + 5.6)
    (IEC NTM), L = 8.1·42 m.

    Parameters
    ----------
    omega : array_like
        Frequency grid (rad/s, ≥ 0, strictly increasing).
    mean_speed : float
        Hub-height mean wind speed U (m/s).
    turbulence_class : str, optional
        IEC turbulence class: "A+", "A", "B" or "C".

    Returns
    -------
    numpy.ndarray
        S(ω) on ``omega`` ((m/s)² per rad/s).

    Raises
    ------
    ValueError
        For an invalid grid, a non-positive ``mean_speed`` or an unknown class.

    Examples
    --------
    >>> import numpy as np
    >>> kaimal_spectrum(np.array([0.0, 1.0]), 19.0).shape
    (2,)
    """
    w = as_omega(omega, "omega")
    u = positive_scalar(mean_speed, "mean_speed")
    sigma = _sigma(u, turbulence_class)
    f = w / (2 * np.pi)
    s_f = 4 * sigma**2 * (KAIMAL_LENGTH / u) / (1 + 6 * f * KAIMAL_LENGTH / u) ** (5 / 3)
    return s_f / (2 * np.pi)


def disc_coherence(omega: ArrayLike, mean_speed: float, rotor_radius: float) -> np.ndarray:
    """Rotor-disc average γ(ω) of the IEC exponential coherence (dimensionless, ≤ 1).

    γ = ∫₀^{2R} exp(−12 √((f r/U)² + (0.12 r/L_c)²)) p_R(r) dr, f = ω/2π, with
    p_R(r) = (4r/(πR²))[acos(r/2R) − (r/2R)√(1 − (r/2R)²)] the distance density of two
    uniform points on the disc of radius R. Gauss-Legendre quadrature in s = √(r/2R).

    Parameters
    ----------
    omega : array_like
        Frequency grid (rad/s, ≥ 0, strictly increasing).
    mean_speed : float
        Mean wind speed U (m/s).
    rotor_radius : float
        Rotor radius R (m).

    Returns
    -------
    numpy.ndarray
        γ(ω) on ``omega`` (-).

    Raises
    ------
    ValueError
        For an invalid grid or a non-positive ``mean_speed`` or ``rotor_radius``.

    Notes
    -----
    The last 32 results (by grid, speed and radius) are kept and returned as copies, bit for
    bit the computed ones; ``disc_coherence.cache_clear()`` forgets them (a benchmark timing
    cold calls).

    Examples
    --------
    >>> import numpy as np
    >>> g = disc_coherence(np.array([0.0, 0.1, 1.0]), 19.0, 120.0)
    >>> bool(g[0] <= 1.0 and g[0] > g[1] > g[2] > 0.0)
    True
    """
    w = as_omega(omega, "omega")
    u = positive_scalar(mean_speed, "mean_speed")
    radius = positive_scalar(rotor_radius, "rotor_radius")
    # a campaign asks again for the same grid, speed and radius (each controller's linear
    # prediction at a speed): the (n_ω × 160) exponentials are the cost, so keep the last few
    return _coherence(w.tobytes(), u, radius).copy()


@functools.lru_cache(maxsize=32)
def _coherence(omega_bytes, u, radius):
    w = np.frombuffer(omega_bytes, dtype=float)
    s = 0.5 * (_GL_X + 1.0)  # nodes on (0, 1)
    r = 2 * radius * s**2
    dr_ds = 4 * radius * s
    x = r / (2 * radius)
    p_r = 4 * r / (np.pi * radius**2) * (np.arccos(x) - x * np.sqrt(1 - x**2))
    weights = 0.5 * _GL_W * p_r * dr_ds  # (n_nodes,)
    f = w[:, None] / (2 * np.pi)
    # exp(−12 √((f r/U)² + (0.12 r/L_c)²)) operation by operation in one buffer: the same
    # roundings as the plain expression, without its five temporaries of n_ω × 160
    coh = f * r
    coh /= u
    np.square(coh, out=coh)
    coh += (0.12 * r / COHERENCE_LENGTH) ** 2
    np.sqrt(coh, out=coh)
    coh *= -12
    np.exp(coh, out=coh)
    out = coh @ weights
    out.flags.writeable = False
    return out


disc_coherence.cache_clear = _coherence.cache_clear


def rotor_effective_spectrum(omega: ArrayLike, mean_speed: float, rotor_radius: float,
                             turbulence_class: str = "B") -> np.ndarray:
    """One-sided PSD of the rotor-effective wind speed ((m/s)² per rad/s): Kaimal × γ(ω).

    See :func:`kaimal_spectrum` and :func:`disc_coherence`.

    Parameters
    ----------
    omega : array_like
        Frequency grid (rad/s, ≥ 0, strictly increasing).
    mean_speed : float
        Mean wind speed (m/s).
    rotor_radius : float
        Rotor radius (m).
    turbulence_class : str, optional
        IEC turbulence class: "A+", "A", "B" or "C".

    Returns
    -------
    numpy.ndarray
        The PSD on ``omega`` ((m/s)² per rad/s).

    Raises
    ------
    ValueError
        For an invalid grid, non-positive speed or radius, or an unknown class.

    Examples
    --------
    >>> import numpy as np
    >>> s = rotor_effective_spectrum(np.linspace(0.0, 3.0, 31), 19.0, 120.97)
    >>> bool(s[0] > s[-1] > 0)
    True
    """
    return kaimal_spectrum(omega, mean_speed, turbulence_class) * disc_coherence(omega, mean_speed, rotor_radius)


def _seeds(seeds):
    if isinstance(seeds, (int, np.integer)):
        return [int(seeds)]
    try:
        out = [int(s) for s in seeds]
    except TypeError:
        raise TypeError(f"seeds must be an int or a sequence of ints, got {type(seeds).__name__}") from None
    if not out:
        raise ValueError("seeds is empty; pass at least one integer seed")
    if any(s < 0 for s in out) or any(s != v for s, v in zip(out, seeds)):
        raise ValueError(f"seeds must be non-negative integers, got {list(seeds)!r}")
    return out


def gaussian_series(spectrum_or_callable: Callable | tuple, duration: float, dt: float, seeds: int | Sequence[int], *,
               random_amplitude: bool = True) -> np.ndarray:
    """Zero-mean Gaussian series with a one-sided PSD, shape (n_seeds, n_samples).

    Harmonics sit at ω_k = 2πk/(n·dt), k = 1 … ⌊(n−1)/2⌋ (no mean, no Nyquist term), each with
    complex Gaussian coefficient of variance 2S(ω_k)Δω, so E[PSD] is S on that grid and the
    expected variance Σ S(ω_k)Δω. ``random_amplitude=False`` fixes the amplitudes at
    √(2SΔω) with random phases only: then the variance of every row equals that sum exactly.
    The series is periodic with period n·dt; variance below Δω/2 = π/duration is not
    represented (for a 600 s record at 19 m/s that is ~10 % of the rotor-effective variance,
    as in any FFT synthesis). Add the mean wind speed yourself.

    Parameters
    ----------
    spectrum_or_callable : callable or tuple
        A callable ``S(omega)`` (omega in rad/s → PSD per rad/s), or a pair ``(omega, psd)``
        interpolated linearly (zero outside the grid).
    duration : float
        Length of the series (s); n = round(duration/dt) samples at t = k·dt.
    dt : float
        Sample spacing (s).
    seeds : int or sequence of int
        Non-negative seeds, one row each; each row depends on its own seed only, so seed 3
        gives the same series alone or in a batch.
    random_amplitude : bool, optional
        Random Gaussian amplitudes (default) or fixed amplitudes with random phases.

    Returns
    -------
    numpy.ndarray
        The series (units of √(PSD·rad/s), m/s for a wind PSD), shape (n_seeds, n).

    Raises
    ------
    ValueError
        For fewer than 4 samples, no or negative seeds, or a PSD that is not finite and
        non-negative.
    TypeError
        For seeds that are not integers or a spectrum of the wrong kind.

    Examples
    --------
    >>> gaussian_series(lambda w: 1.0 / (1.0 + w**2), 60.0, 0.1, [1, 2]).shape
    (2, 600)
    """
    duration = positive_scalar(duration, "duration")
    dt = positive_scalar(dt, "dt")
    n = int(round(duration / dt))
    if n < 4:
        raise ValueError(f"duration/dt = {duration}/{dt} gives {n} samples; need at least 4")
    seed_list = _seeds(seeds)
    k = np.arange(1, (n - 1) // 2 + 1)
    d_omega = 2 * np.pi / (n * dt)
    omega_k = k * d_omega
    if callable(spectrum_or_callable):
        psd = np.asarray(spectrum_or_callable(omega_k), dtype=float)
    else:
        try:
            grid, values = spectrum_or_callable
        except (TypeError, ValueError):
            raise TypeError("spectrum_or_callable must be a callable S(omega) or a pair (omega, psd)") from None
        grid = as_omega(grid, "spectrum_or_callable[0]")
        values = np.asarray(values, dtype=float)
        if values.shape != grid.shape:
            raise ValueError(f"spectrum_or_callable: psd shape {values.shape} does not match omega shape {grid.shape}")
        psd = np.interp(omega_k, grid, values, left=0.0, right=0.0)
    if psd.shape != omega_k.shape or not np.all(np.isfinite(psd)) or np.any(psd < 0):
        raise ValueError("spectrum_or_callable must return a finite, non-negative PSD of the same shape as omega")
    amp = np.sqrt(psd * d_omega)  # per real/imaginary part: E|X|² = 2 S Δω
    spec = np.zeros((len(seed_list), n // 2 + 1), dtype=complex)
    for row, seed in enumerate(seed_list):
        rng = np.random.default_rng(seed)
        if random_amplitude:
            z = rng.standard_normal(k.size) + 1j * rng.standard_normal(k.size)
        else:
            z = np.sqrt(2.0) * np.exp(2j * np.pi * rng.random(k.size))
        spec[row, k] = z * amp
    # irfft(Y)[t] = (1/n)[Y0 + 2 Σ Re(Y_k e^{2πikt/n}) ...], so Y_k = n X_k / 2 gives Σ Re(X_k e^{iω_k t}).
    return np.fft.irfft(spec * (n / 2), n=n, axis=-1)


def seed_for(wind_speed: float, seed: int) -> int:
    """Integer seed of the wind series for (wind speed, seed): ``seed·1000 + round(10·v)``.

    Every (v, seed) pair gets its own series (v < 100 m/s), and two controllers run with the
    same seed see exactly the same wind: the paired comparison of the validation.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed v (m/s).
    seed : int
        The run's seed.

    Returns
    -------
    int
        The seed of :func:`gaussian_series` for that record.

    Examples
    --------
    >>> seed_for(19.0, 3)
    3190
    """
    return int(seed) * 1000 + int(round(10.0 * float(wind_speed)))


def wind_series(rotor_radius: float, wind_speeds: Sequence[float], seeds: Sequence[int], duration: float, dt: float,
                turbulence_class: str = "B") -> np.ndarray:
    """Rotor-effective wind records: the mean plus turbulence, one per (wind speed, seed).

    Each record is its mean speed plus :func:`gaussian_series` of :func:`rotor_effective_spectrum`
    at that speed, seeded by :func:`seed_for`, so a record depends on (v, seed) only.

    Parameters
    ----------
    rotor_radius : float
        Rotor radius (m) of the rotor-disc coherence.
    wind_speeds : sequence of float
        Mean wind speeds (m/s), W of them.
    seeds : sequence of int
        Seeds, S of them.
    duration : float
        Length of each record (s).
    dt : float
        Sample spacing (s).
    turbulence_class : str, optional
        IEC turbulence class: "A+", "A", "B" or "C".

    Returns
    -------
    numpy.ndarray
        Wind speed (m/s), shape (W, S, round(duration/dt)).

    Examples
    --------
    >>> wind_series(120.0, [19.0], [1, 2], 60.0, 0.1).shape
    (1, 2, 600)
    """
    out = []
    for v in wind_speeds:
        def spec(om, v=v):
            return rotor_effective_spectrum(om, v, rotor_radius, turbulence_class=turbulence_class)

        s = gaussian_series(spec, duration, dt, [seed_for(v, s) for s in seeds])
        out.append(v + np.asarray(s, dtype=float))
    return np.stack(out)


#: Length of the records a spectral DEL counts cycles over, s (IEC 61400-1's 10-minute records, the
#: simulations' 600 s): see :func:`record_window`.
RECORD_LENGTH = 600.0
#: Lowest frequency of :func:`default_omega`, rad/s: a tenth of the fundamental 2π/600 s of a
#: 10-minute record. Below it :func:`record_window` leaves < 0.3 % of the spectrum (falling as
#: ω²), so halving it or doubling the grid density moves the promise by < 0.01 pp at 15 and
#: 19 m/s on the IEA 15 MW (tests/test_spectral_band.py). The former 0.01 rad/s cut the band at
#: the record's fundamental and left 1-2 pp of promise to where the grid happened to stop.
LOWEST_OMEGA = 0.001


def record_window(omega: ArrayLike, record_length: float = RECORD_LENGTH) -> np.ndarray:
    """Share of a stationary process's PSD at ω that is variance about the mean of one record.

    A record of length T sees a component of frequency ω partly as a shift of its mean: the
    expected variance about the record's own mean is ∫ S(ω)·(1 − sinc²(ωT/2)) dω, sinc x =
    sin x / x. Slow wind (periods beyond T) moves the 10-minute mean, which the Weibull
    distribution of mean speeds carries, not the cycles a rainflow count of the record finds.
    For a spectrum flat below ~2π/T the window takes out the same variance as the FFT
    synthesis of a T-long series (:func:`specdesign.wind.gaussian_series`: nothing below π/T), and it
    is smooth, so the spectral figures converge as the grid's lowest frequency goes to 0.

    Parameters
    ----------
    omega : array_like
        Frequencies, rad/s (≥ 0).
    record_length : float
        Record length T, s (> 0).

    Returns
    -------
    numpy.ndarray
        1 − sinc²(ωT/2), in [0, 1): ≈ (ωT)²/12 for ωT ≪ 1, → 1 above a few 2π/T.

    Examples
    --------
    >>> from specdesign.wind import record_window
    >>> [round(float(x), 3) for x in record_window([0.001, 0.005, 0.1])]   # rad/s, 600 s records
    [0.03, 0.558, 0.999]
    """
    t = positive_scalar(record_length, "record_length")
    w = np.asarray(omega, dtype=float)
    return 1.0 - np.sinc(w * t / (2 * np.pi)) ** 2  # numpy's sinc is sin(πx)/(πx)
