"""Wind spectra and synthesis against independent integrals, Monte Carlo and Welch."""
import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import integrate, signal

from specdesign import wind

R = 120.97
U = 19.0
A_COH = 12 * 0.12 / (8.1 * 42.0)  # low-frequency decay rate of the IEC coherence, 1/m


def _disc_pairs(n, seed):
    """n random pairs of uniform points on the rotor disc, their distances (m)."""
    rng = np.random.default_rng(seed)
    r = R * np.sqrt(rng.random((2, n)))
    th = 2 * np.pi * rng.random((2, n))
    x, y = r * np.cos(th), r * np.sin(th)
    return np.hypot(x[0] - x[1], y[0] - y[1])


def test_kaimal_variance_is_iec_sigma():
    # ∫ Kaimal dω = σ² analytically (the spectrum integrates to σ² over 0..∞)
    for cls, iref in wind.TURBULENCE_CLASSES.items():
        val, _ = integrate.quad(lambda w: wind.kaimal_spectrum(np.array([0.0, w]), U, cls)[1], 0, np.inf, limit=200)
        assert_allclose(val, (iref * (0.75 * U + 5.6)) ** 2, rtol=1e-6)


def test_kaimal_is_per_rad_s():
    # per-Hz Kaimal written out independently, divided by 2π
    f = np.array([0.0, 0.01, 0.1, 1.0])
    sigma = 0.14 * (0.75 * U + 5.6)
    L = 340.2
    s_hz = 4 * sigma**2 * L / U / (1 + 6 * f * L / U) ** (5 / 3)
    assert_allclose(wind.kaimal_spectrum(2 * np.pi * f, U), s_hz / (2 * np.pi), rtol=1e-12)


def test_distance_density_moments(monkeypatch):
    # Small a = 12·0.12/L: γ(0) = E[exp(−a r)] = 1 − a E[r] + a² E[r²]/2 − O(a³), with the disc's
    # E[r] = 128R/(45π) and E[r²] = R²; checks p_R and the quadrature together.
    a = 1e-3 / R
    monkeypatch.setattr(wind, "COHERENCE_LENGTH", 12 * 0.12 / a)
    g0 = wind.disc_coherence(np.array([0.0, 1.0]), U, R)[0]
    assert_allclose((1 - g0) / a, 128 * R / (45 * np.pi) - a * R**2 / 2, rtol=1e-5)


def test_low_frequency_limit_matches_monte_carlo():
    # f → 0: γ → E[exp(−a r)] over pairs of disc points, estimated by Monte Carlo
    d = _disc_pairs(400_000, 1)
    mc = np.exp(-A_COH * d)
    g = wind.disc_coherence(np.array([0.0, 1e-4]), U, R)
    se = mc.std() / np.sqrt(mc.size)
    assert abs(g[0] - mc.mean()) < 5 * se
    assert abs(g[1] - g[0]) < 1e-6  # continuous at 0
    assert 0 < g[0] < 1


def test_high_frequency_limit():
    # f → ∞ only short distances matter: p_R(r) ≈ 2r/R², so γ ≈ 2/(k R)², k = 12√((f/U)² + (0.12/L)²)
    omega = np.array([40.0, 80.0])
    f = omega / (2 * np.pi)
    k = 12 * np.sqrt((f / U) ** 2 + (0.12 / wind.COHERENCE_LENGTH) ** 2)
    assert_allclose(wind.disc_coherence(omega, U, R), 2 / (k * R) ** 2, rtol=1e-2)


def test_disc_average_matches_brute_force_double_sum():
    # pairs of points on a Cartesian grid covering the disc, every pair summed
    h = 6.0
    g = np.arange(-R + h / 2, R, h)
    X, Y = np.meshgrid(g, g)
    inside = X**2 + Y**2 <= R**2
    px, py = X[inside], Y[inside]
    d = np.hypot(px[:, None] - px[None, :], py[:, None] - py[None, :])
    omega = np.array([0.0, 0.05, 0.2, 0.6])
    brute = []
    for w in omega:
        f = w / (2 * np.pi)
        brute.append(np.mean(np.exp(-12 * np.sqrt((f * d / U) ** 2 + (0.12 * d / wind.COHERENCE_LENGTH) ** 2))))
    assert_allclose(wind.disc_coherence(omega, U, R), brute, rtol=2e-2, atol=2e-3)


def test_rotor_effective_variance_below_point_variance():
    omega = np.linspace(0, 20, 20001)
    for u in (11.0, 19.0, 25.0):
        s_rot = wind.rotor_effective_spectrum(omega, u, R)
        s_pt = wind.kaimal_spectrum(omega, u)
        assert np.all(s_rot <= s_pt)
        assert np.trapezoid(s_rot, omega) < 0.8 * np.trapezoid(s_pt, omega)


def test_bad_inputs_name_the_argument():
    with pytest.raises(ValueError, match="turbulence_class"):
        wind.kaimal_spectrum([0.0, 1.0], U, "D")
    with pytest.raises(ValueError, match="mean_speed"):
        wind.rotor_effective_spectrum([0.0, 1.0], -3, R)
    with pytest.raises(ValueError, match="omega"):
        wind.kaimal_spectrum([1.0, 0.5], U)
    with pytest.raises(TypeError, match="seeds"):
        wind.gaussian_series(lambda w: w, 10, 0.1, seeds=1.5)
    with pytest.raises(ValueError, match="duration"):
        wind.gaussian_series(lambda w: w, -10, 0.1, seeds=1)


def _spectrum(w):
    return wind.rotor_effective_spectrum(np.concatenate([[0.0], w]), U, R)[1:]


def test_gaussian_series_reproducible_per_seed():
    batch = wind.gaussian_series(_spectrum, 200, 0.25, seeds=[1, 3, 5])
    alone = wind.gaussian_series(_spectrum, 200, 0.25, seeds=3)
    assert batch.shape == (3, 800) and alone.shape == (1, 800)
    assert_allclose(batch[1], alone[0], rtol=0, atol=0)
    assert not np.allclose(batch[0], batch[1])


def test_gaussian_series_variance_equals_discrete_integral():
    duration, dt = 600.0, 0.2
    n = int(duration / dt)
    x = wind.gaussian_series(_spectrum, duration, dt, seeds=[0, 1], random_amplitude=False)
    dw = 2 * np.pi / duration
    wk = dw * np.arange(1, (n - 1) // 2 + 1)
    assert_allclose(x.var(axis=1), np.sum(_spectrum(wk)) * dw, rtol=1e-10)
    # the rectangle sum over the harmonics is ∫ S from Δω/2 (no mean term) to Nyquist
    omega = np.linspace(dw / 2, np.pi / dt, 40001)
    assert_allclose(np.sum(_spectrum(wk)) * dw, np.trapezoid(_spectrum(omega), omega), rtol=1e-2)


def test_gaussian_series_welch_matches_target():
    duration, dt = 1200.0, 0.25
    x = wind.gaussian_series(_spectrum, duration, dt, seeds=range(16))
    f, pxx = signal.welch(x, fs=1 / dt, nperseg=1200, axis=-1)  # one-sided per Hz
    s_est = pxx.mean(axis=0) / (2 * np.pi)  # per rad/s
    w = 2 * np.pi * f
    band = (w > 0.05) & (w < 3.0)
    ratio = s_est[band] / _spectrum(w[band])
    # 16 seeds × ~7 segments: each ratio has ~±10 % scatter, their mean much less
    assert abs(np.mean(ratio) - 1) < 0.05
    assert np.all(np.abs(ratio - 1) < 0.5)
    # ensemble variance vs ∫S
    var_target = np.trapezoid(_spectrum(np.linspace(1e-3, 4 * np.pi, 40001)), np.linspace(1e-3, 4 * np.pi, 40001))
    assert abs(x.var(axis=1).mean() / var_target - 1) < 0.1


def test_gaussian_series_accepts_tabulated_spectrum():
    omega = np.linspace(0, 20, 4001)
    table = wind.rotor_effective_spectrum(omega, U, R)
    a = wind.gaussian_series((omega, table), 300, 0.1, seeds=7)
    b = wind.gaussian_series(_spectrum, 300, 0.1, seeds=7)
    assert_allclose(a, b, rtol=0, atol=1e-2 * np.abs(b).max())
